#!/usr/bin/env python3
"""A closed-loop controller, tick by tick: the needle is driven by the force
it feels. An admittance law advances the tip so that the needle force follows
a ramp (force_rate N/s); the loop stops at the tick the skin gives way, then
holds the tip there for a few ticks to show the force dropping.

    PYTHONPATH=build/apps/python python3 apps/python/examples/closed_loop_press.py

Start from here for a haptic device, a learning loop or a controller: one
Simulator.tick(depth_mm, velocity_mm_per_s) per haptic step (1 ms).
"""
import argparse
import sys
import time

import puncture


def press_until_skin_breaks(scene, force_rate_N_per_s=2.0, gain_mm_per_N_s=40.0, max_speed_mm_per_s=20.0,
                            max_ticks=60000):
    """Returns (the tick of the skin's break, the ticks run, wall seconds in tick())."""
    sim = puncture.Simulator(scene)
    dt = sim.time_step_s
    depth, force, wall = -0.5, 0.0, 0.0  # start 0.5 mm above the skin
    for i in range(max_ticks):
        target = force_rate_N_per_s * i * dt
        speed = min(max_speed_mm_per_s, max(0.0, gain_mm_per_N_s * (target - force)))  # admittance: push until F = target
        depth += speed * dt
        start = time.perf_counter()
        tick = sim.tick(depth, velocity_mm_per_s=speed)
        wall += time.perf_counter() - start
        force = tick.force_N
        if any(e.layer_name == "skin" for e in tick.events):
            return tick, sim, i + 1, wall
    raise RuntimeError(f"the skin did not break within {max_ticks} ticks")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(puncture.default_scene_path()))
    parser.add_argument("--force-rate", type=float, default=2.0, help="N/s of the force ramp the controller follows")
    args = parser.parse_args(argv)
    scene = puncture.Scene.load(args.scene)
    broke, sim, ticks, wall = press_until_skin_breaks(scene, args.force_rate)
    event = [e for e in broke.events if e.layer_name == "skin"][0]
    print(f"skin broke at tick {ticks} (t = {broke.time_s:.3f} s): depth {event.depth_mm:.2f} mm, "
          f"needle force {event.total_force_N:.3f} N")
    after = [sim.tick(broke.depth_mm, velocity_mm_per_s=0.0).force_N for _ in range(20)]
    print(f"holding the tip there: force {after[0]:.3f} N -> {after[-1]:.3f} N after 20 ticks")
    print(f"mean time per tick() from Python: {wall / ticks * 1e6:.1f} us (haptic budget 1000 us)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
