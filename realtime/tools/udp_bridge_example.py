#!/usr/bin/env python3
"""A minimal bridge for puncture-app's UDP device (protocol: apps/README.md).

It sends POSE messages at about 1 kHz and reads the FORCE replies. Here the
"device" is a scripted up-and-down motion on the needle axis; for a real
haptic device replace read_device_pose() with the SDK's pose query (e.g.
OpenHaptics hdGetDoublev(HD_CURRENT_POSITION), Force Dimension
dhdGetPosition, Haply Inverse3) mapped into the scene frame (m, skin at z = 0,
needle axis = q * (0, 0, -1)), and render_force() with the SDK's force
command (hdSetDoublev(HD_CURRENT_FORCE), dhdSetForce, ...).

Usage: udp_bridge_example.py [--host 127.0.0.1] [--port 47011] [--seconds 5]
                             [--depth-mm 12] [--speed-mm-s 10]
Start the app first:  puncture-app --device udp
"""
import argparse
import math
import socket
import struct
import time

MAGIC = 0x50434E50          # the bytes "PNCP"
VERSION = 1
POSE, FORCE = 1, 2
POSE_FORMAT = "<IHHIId3d4d3dII"     # 112 bytes, little-endian
FORCE_FORMAT = "<IHHIIIId3ddd"      # 72 bytes
VELOCITY_VALID = 1 << 0


def read_device_pose(t, depth_m, speed_m_s):
    """Tip position (m), orientation quaternion (w, x, y, z) and velocity (m/s) at time t."""
    start_height = 0.002
    travel = start_height + depth_m
    period = 2.0 * travel / speed_m_s
    phase = (t % period) / period                     # down for half a period, up for the other half
    if phase < 0.5:
        z, vz = start_height - speed_m_s * phase * period, -speed_m_s
    else:
        z, vz = start_height - travel + speed_m_s * (phase - 0.5) * period, speed_m_s
    return (0.0, 0.0, z), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, vz)


def render_force(force_n, flags):
    """Send the force to the device (here: nothing)."""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=47011)
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--depth-mm", type=float, default=12.0)
    ap.add_argument("--speed-mm-s", type=float, default=10.0)
    a = ap.parse_args()
    assert struct.calcsize(POSE_FORMAT) == 112 and struct.calcsize(FORCE_FORMAT) == 72

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setblocking(False)
    app = (a.host, a.port)
    start = time.monotonic()
    sequence, replies, peak, last_report = 0, 0, 0.0, 0.0
    while (now := time.monotonic() - start) < a.seconds:
        pos, quat, vel = read_device_pose(now, a.depth_mm * 1e-3, a.speed_mm_s * 1e-3)
        sequence = (sequence + 1) & 0xFFFFFFFF
        sock.sendto(struct.pack(POSE_FORMAT, MAGIC, VERSION, POSE, sequence, VELOCITY_VALID, now,
                                *pos, *quat, *vel, 0, 0), app)
        while True:
            try:
                data = sock.recv(256)
            except BlockingIOError:
                break
            if len(data) != 72:
                continue
            (magic, version, kind, tick, echo, flags, states, model_t, fx, fy, fz,
             tissue_force, depth) = struct.unpack(FORCE_FORMAT, data)
            if magic != MAGIC or version != VERSION or kind != FORCE:
                continue
            replies += 1
            peak = max(peak, tissue_force)
            render_force((fx, fy, fz), flags)
            if now - last_report >= 0.5:
                last_report = now
                layers = " ".join("upP"[(states >> (2 * k)) & 3] for k in range(3))
                print(f"t {now:6.3f} s  depth {depth * 1e3:6.2f} mm  force to device {fz:+.3f} N  "
                      f"tissue {tissue_force:.3f} N  layers {layers}  flags {flags:#x}", flush=True)
        time.sleep(max(0.0, start + sequence * 1e-3 - time.monotonic()))
    print(f"sent {sequence} poses, received {replies} forces, peak tissue force {peak:.3f} N")
    return 0 if replies > 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
