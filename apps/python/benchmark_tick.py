#!/usr/bin/env python3
"""What Simulator.tick costs from Python beyond the C++ tick itself.

The same haptic ticks as the scene's scripted run (depth, velocity and time of
every tick taken from Simulator.run()) are called from a Python loop, on fresh
tissue each repeat. The C++ tick's own cost is the wall time run() measures
around every PunctureSimulator::tick (RunResult.tick_wall_time_s, a run of the
same ticks in the same repeat); the overhead is the Python loop's time per
call less that. Median over the repeats. A haptic loop at 1 kHz has 1000 us
per tick. Speed is never asserted in a test; this prints (and with --write
stores) the table.

    PYTHONPATH=build/apps/python python3 apps/python/benchmark_tick.py --write results/python_api/README.md
"""
import argparse
import datetime
import os
import pathlib
import platform
import statistics
import sys
import time

import numpy as np

import puncture


INTRO = """What a haptic loop written in Python pays per tick beyond the model's own tick (issue 51's goal:
under 2 us, against the 1000 us of a 1 kHz haptic step). Made by `apps/python/benchmark_tick.py`: the
scene's scripted ticks (depth, velocity, time of every tick of `Simulator.run()`) are called from a Python
loop on fresh tissue; the C++ tick's cost is the wall time `run()` measures around every C++ tick of the
same ticks in the same repeat (`RunResult.tick_wall_time_s`, two clock reads included); the overhead is the
loop's time per call less that: argument conversion, the `Tick` object (a copy of the tick's result, its
per-layer results and events), the loop itself. Keyword arguments and reading an attribute of the `Tick`
cost more than positional arguments. On a shared machine under load (the load average is in the machine
line) single repeats scatter; the median is the figure. Speed is never asserted in a test."""


def machine():
    model = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return f"{platform.node()}, {model}, {os.cpu_count()} cores, load {load:.2f}; Python {platform.python_version()}, NumPy {np.__version__}"


def loop_seconds(scene, call, depth, velocity, times):
    """Wall time of one Python loop of tick calls over the run's ticks (fresh tissue)."""
    sim = puncture.Simulator(scene)
    tick = sim.tick
    start = time.perf_counter()
    call(tick, depth, velocity, times)
    return time.perf_counter() - start


def all_arguments(tick, depth, velocity, times):
    for d, v, t in zip(depth, velocity, times):
        tick(d, v, t)


def depth_only(tick, depth, velocity, times):
    for d in depth:
        tick(d)


def keywords_and_force(tick, depth, velocity, times):
    for d, v in zip(depth, velocity):
        tick(d, velocity_mm_per_s=v).force_N


def empty_loop(tick, depth, velocity, times):
    f = float
    for d, v, t in zip(depth, velocity, times):
        f(d)


VARIANTS = [
    ("tick(depth_mm, velocity_mm_per_s, time_s)", all_arguments),
    ("tick(depth_mm) (time and velocity by default)", depth_only),
    ("tick(depth_mm, velocity_mm_per_s=v).force_N", keywords_and_force),
]


def measure(scene, repeats):
    """{variant: [overhead us per call]}, C++ tick us per call per repeat, ticks, baseline loop us."""
    reference = puncture.Simulator(scene).run()
    depth, velocity, times = (reference[k].tolist() for k in ("depth_mm", "velocity_mm_per_s", "time_s"))
    n = len(depth)
    overhead = {name: [] for name, _ in VARIANTS}
    cxx, baseline = [], []
    for _ in range(repeats):
        cxx_s = float(np.sum(puncture.Simulator(scene).run().tick_wall_time_s))
        cxx.append(cxx_s / n * 1e6)
        for name, call in VARIANTS:
            overhead[name].append((loop_seconds(scene, call, depth, velocity, times) - cxx_s) / n * 1e6)
        baseline.append(loop_seconds(scene, empty_loop, depth, velocity, times) / n * 1e6)
    return overhead, cxx, n, baseline


def table(scene_name, overhead, cxx, n, baseline, repeats):
    lines = [f"Scene `{scene_name}`: {n} ticks per loop, median of {repeats} repeats.", "",
             "| call from Python | C++ tick (us per call) | Python overhead beyond it (us per call) | min .. max over repeats |",
             "|---|---|---|---|"]
    for name, values in overhead.items():
        lines.append(f"| `{name}` | {statistics.median(cxx):.2f} | **{statistics.median(values):.2f}** | "
                     f"{min(values):.2f} .. {max(values):.2f} |")
    lines.append(f"| the bare Python loop (`float(d)` per tick, for scale) | - | {statistics.median(baseline):.2f} | "
                 f"{min(baseline):.2f} .. {max(baseline):.2f} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(puncture.default_scene_path()))
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--write", help="also write the table as this markdown page")
    args = parser.parse_args(argv)
    scene = puncture.Scene.load(args.scene)
    overhead, cxx, n, baseline = measure(scene, args.repeats)
    command = "PYTHONPATH=build/apps/python python3 apps/python/benchmark_tick.py " + " ".join(argv or sys.argv[1:])
    head = (f"Command: `{command.strip()}`  \nMachine: {machine()}  \n"
            f"Module: puncture {puncture.__version__} ({puncture.git_revision})  \n"
            f"Date (UTC): {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M}")
    body = table(scene.name, overhead, cxx, n, baseline, args.repeats)
    print(head + "\n\n" + body)
    if args.write:
        page = pathlib.Path(args.write)
        page.parent.mkdir(parents=True, exist_ok=True)
        page.write_text("# Simulator.tick from Python: the cost beyond the C++ tick\n\n" + INTRO + "\n\n" + head +
                        "\n\n" + body + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
