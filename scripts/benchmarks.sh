#!/usr/bin/env bash
# Haptic-tick benchmarks: builds the Google Benchmark programs (Release, -j2)
# if needed, runs them with 5 repetitions (medians), keeps the raw JSON and
# writes results/benchmarks/tick_benchmarks.md (one table per benchmark
# family: median time per tick in us, ratio to the default configuration,
# and a header naming the command, machine, date and git revision).
#
# Usage: scripts/benchmarks.sh [extra Google Benchmark flags, e.g.
#        --benchmark_filter=BM_tick_phase]
#        scripts/benchmarks.sh --report-only   (rewrite the markdown from the
#        JSON files and run_info.json of the last run)
# Env:   PUNCTURE_BENCH_BUILD_DIR  build directory (default ./build-bench)
#        PUNCTURE_BENCH_OUT        output directory (default results/benchmarks)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BENCH_BUILD_DIR:-$root/build-bench}"
out="${PUNCTURE_BENCH_OUT:-$root/results/benchmarks}"
report_only=0
if [[ "${1:-}" == "--report-only" ]]; then
  # Rewrite the markdown from the JSON and run_info.json of an earlier run.
  report_only=1
  shift
fi

if (( ! report_only )); then
  if [[ ! -f "$build/CMakeCache.txt" ]]; then
    # No Python module: its libraries would be compiled position-independent.
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DPUNCTURE_WITH_FEM=OFF -DPUNCTURE_WITH_VTK=OFF \
      -DPUNCTURE_BUILD_TESTS=ON -DPUNCTURE_BUILD_BENCHMARKS=ON -DPUNCTURE_WITH_PYTHON=OFF
  fi
  build_type="$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$build/CMakeCache.txt")"
  if [[ "$build_type" != "Release" ]]; then
    echo "benchmarks.sh: $build is configured as '$build_type'; timings need a Release build" >&2
    exit 1
  fi
  cmake --build "$build" -j2 --target bench_tick bench_effects

  mkdir -p "$out"
  revision="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  if [[ -n "$(git -C "$root" status --porcelain -- core tests/benchmarks scenes 2>/dev/null)" ]]; then
    revision="$revision (+ uncommitted changes in core/, tests/benchmarks/ or scenes/)"
  fi
  started_utc="$(date -u '+%Y-%m-%d %H:%M UTC')"
  load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
  common=(--benchmark_repetitions=5 --benchmark_report_aggregates_only=true
          --benchmark_out_format=json)
  for bench in bench_tick bench_effects; do
    echo "== $bench"
    "$build/tests/benchmarks/$bench" "${common[@]}" --benchmark_out="$out/$bench.json" "$@"
  done
  load_after="$(cut -d' ' -f1-3 /proc/loadavg)"
  python3 - "$out/run_info.json" "scripts/benchmarks.sh${*:+ $*}" "$revision" "$started_utc" \
    "$load_before" "$load_after" <<'PY'
import json, sys
path, command, revision, started, load_before, load_after = sys.argv[1:7]
with open(path, "w") as f:
    json.dump({"command": command, "revision": revision, "started_utc": started,
               "load_average_before": load_before, "load_average_after": load_after}, f, indent=1)
PY
fi

python3 - "$out" <<'PY'
"""Turns the Google Benchmark JSON files into results/benchmarks/tick_benchmarks.md."""
import datetime
import functools
import json
import os
import re
import socket
import sys

out_dir = sys.argv[1]
with open(os.path.join(out_dir, "run_info.json")) as f:
    run_info = json.load(f)
command_line, revision = run_info["command"], run_info["revision"]
TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


rows = {}     # run_name -> {"median_us", "cv", counters...}
contexts = []
for name in ("bench_tick", "bench_effects"):
    path = os.path.join(out_dir, name + ".json")
    if not os.path.exists(path):
        continue
    with open(path) as f:
        data = json.load(f)
    contexts.append(data.get("context", {}))
    for b in data["benchmarks"]:
        # Fixed-iteration benchmarks carry "/iterations:N" in their name.
        b["run_name"] = re.sub(r"/iterations:\d+", "", b["run_name"])
        if b.get("error_occurred"):
            rows.setdefault(b["run_name"], {})["error"] = b.get("error_message", "error")
            continue
        agg = b.get("aggregate_name")
        r = rows.setdefault(b["run_name"], {})
        t_us = b["real_time"] * TO_US[b.get("time_unit", "ns")]
        if agg == "median":
            r["median_us"] = t_us
            r["median_cpu_us"] = b["cpu_time"] * TO_US[b.get("time_unit", "ns")]
            for key, value in b.items():
                if key in ("phase_ticks", "punctures", "mesh_nodes_all_layers", "ticks_per_insertion", "contact_ticks",
                           "mesh_nodes", "ticks_to_complete") or \
                        (key.endswith("_us") and isinstance(value, (int, float))):
                    r["counter:" + key] = value
        elif agg == "mean":
            r["mean_us"] = t_us
        elif agg == "stddev":
            r["stddev_us"] = t_us
        elif agg is None:  # no repetitions: a single run
            r.setdefault("median_us", t_us)


def get(name):
    return rows.get(name, {})


def fmt_time(us):
    if us is None:
        return "n/a"
    if us >= 100:
        return f"{us:.0f}"
    if us >= 1:
        return f"{us:.2f}"
    return f"{us:.4f}"


def counter_text(result, key):
    """A benchmark's counter `key` as a time in us (n/a when it has none)."""
    return fmt_time(result.get("counter:" + key))


def fmt_ratio(value, ref):
    if value is None or ref is None or ref == 0:
        return "n/a"
    return f"{value / ref:.2f}"


def spread(r):
    if "stddev_us" in r and r.get("mean_us"):
        return f"{100.0 * r['stddev_us'] / r['mean_us']:.1f}"
    return "n/a"


def fmt_count(r, key):
    return str(int(r["counter:" + key])) if "counter:" + key in r else "n/a"


def table(header, lines):
    md = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    md += ["| " + " | ".join(line) + " |" for line in lines]
    return "\n".join(md)


def time_row(label, name, ref_name, extra=()):
    r, ref = get(name), get(ref_name)
    if "error" in r:
        return [label, *[""] * len(extra), "error: " + r["error"], "", "", ""]
    return [label, *[fmt_count(r, k) if k in ("phase_ticks", "punctures", "mesh_nodes_all_layers") else k
                     for k in extra],
            fmt_time(r.get("median_us")), fmt_time(r.get("median_cpu_us")),
            fmt_ratio(r.get("median_cpu_us"), ref.get("median_cpu_us")), spread(r)]


def tuned_sections():
    """The tuned preset's target, phases, single-tick distribution and effects (the page leads with them)."""
    out = []
    dist = get("BM_tick_distribution/tuned/whole_insertion")
    c = functools.partial(counter_text, dist)
    p99, worst = dist.get("counter:contact_p99_us"), dist.get("counter:contact_worst_tick_us")
    if p99 is not None and worst is not None:
        verdict = "met" if p99 <= 10.0 and worst <= 50.0 else "NOT met"
        out.append(f"**Target: tuned preset, ticks with contact p99 <= 10 us and no tick over 50 us: {verdict}.** "
                   f"Over the {fmt_count(dist, 'contact_ticks')} ticks with contact: mean {c('contact_mean_us')} us, "
                   f"p50 {c('contact_p50_us')} us, p99 {c('contact_p99_us')} us; the slowest tick by its own cost "
                   f"(the largest over the ticks of a tick's fastest time over the 10 insertions of a run) "
                   f"{c('contact_worst_tick_us')} us; the largest single measurement {c('contact_max_us')} us "
                   "includes the preemptions of this shared machine (table 'Single-tick distribution, tuned preset').")
        out.append("")
    out.append("## Tick by phase of the insertion (tuned preset)")
    out.append("")
    out.append("Phases as for the default scene below; in press_skin the stiffening skin mesh is solved by "
               "Newton's method every tick, and the muscle mesh from its contact until it breaks. Ratio: to "
               "whole_insertion.")
    out.append("")
    out.append(table(["phase", "ticks in phase", "median us / tick", "CPU us / tick", "ratio", "spread %"],
                     [time_row(p, f"BM_tick_phase/tuned/{p}", "BM_tick_phase/tuned/whole_insertion", ("phase_ticks",))
                      for p in ("press_skin", "after_skin_break", "inside_punctured", "in_tissue",
                                "whole_insertion")]))
    out.append("")
    out.append("## Single-tick distribution, tuned preset")
    out.append("")
    out.append("As 'Single-tick distribution (default scene)' below. worst tick: the largest over the ticks of a "
               "tick's fastest time over the 10 insertions of one benchmark run (what the tick itself costs; the "
               "max column also holds the ticks during which the process was preempted).")
    out.append("")
    out.append(table(["ticks", "p50 us", "p90 us", "p99 us", "max us", "worst tick us"],
                     [["all ticks of the insertion", c("p50_us"), c("p90_us"), c("p99_us"), c("max_us"), ""],
                      ["press_skin ticks", c("press_p50_us"), "", c("press_p99_us"), c("press_max_us"), ""],
                      [f"ticks with contact ({fmt_count(dist, 'contact_ticks')}; mean {c('contact_mean_us')} us)",
                       c("contact_p50_us"), "", c("contact_p99_us"), c("contact_max_us"), c("contact_worst_tick_us")]]))
    out.append("")
    out.append("## Effects on / off, tuned preset")
    out.append("")
    out.append("As 'Effects on / off' below, on the tuned preset. mesh_stiffening_off: linear force meshes (no "
               "axial surface springs, no virtual-spring stiffening; the skin then never reaches its critical "
               "force, so nothing is punctured and the phases after a puncture are empty); tip_stiffening_off: "
               "no strain-stiffening of the tip spring; surface_force_off also removes resumption. Ratio: to "
               "all_on for the same phase.")
    out.append("")
    lines = []
    for cfg in ("all_on", "mesh_stiffening_off", "tip_stiffening_off", "damping_off", "resumption_off",
                "cutting_off", "friction_off", "surface_force_off", "all_off"):
        for phase in ("press_skin", "in_tissue", "inside_punctured", "whole_insertion"):
            lines.append(time_row(f"{cfg} / {phase}", f"BM_effects/tuned/{cfg}/{phase}",
                                  f"BM_effects/tuned/all_on/{phase}", ("phase_ticks", "punctures")))
    out.append(table(["effects / phase", "ticks in phase", "punctures", "median us / tick", "CPU us / tick", "ratio",
                      "spread %"], lines))
    out.append("")
    out.extend(angle_section())
    return out


def angle_section():
    """The tuned preset with the needle at 0, 15 and 30 deg to the surface normal (BM_tick_angle)."""
    out = ["## The needle at an angle (tuned preset)", ""]
    ref, at30 = get("BM_tick_angle/0/in_tissue"), get("BM_tick_angle/30/in_tissue")
    if ref.get("median_cpu_us") and at30.get("median_cpu_us"):
        ratio = at30["median_cpu_us"] / ref["median_cpu_us"]
        verdict = "met" if ratio <= 1.5 else "NOT met"
        out.append(f"**Target: the tick with contact at 30 deg within 1.5x of 0 deg: {verdict}** "
                   f"(in_tissue, CPU: {fmt_time(at30['median_cpu_us'])} us against {fmt_time(ref['median_cpu_us'])} us, "
                   f"ratio {ratio:.2f}).")
        out.append("")
    out.append("The tuned preset's scripted insertion along the line through the entry point at the angle "
               "(core/include/puncture/needle.hpp): each layer is met where the inclined path crosses it, its force "
               "mesh laid there. Ratio: to 0 deg for the same phase.")
    out.append("")
    lines = [time_row(f"{a} deg / {p}", f"BM_tick_angle/{a}/{p}", f"BM_tick_angle/0/{p}", ("phase_ticks",))
             for a in (0, 15, 30) for p in ("press_skin", "in_tissue", "whole_insertion")]
    out.append(table(["angle / phase", "ticks in phase", "median us / tick", "CPU us / tick", "ratio", "spread %"],
                     lines))
    out.append("")
    dist = get("BM_tick_distribution/tuned_30deg/whole_insertion")
    c = functools.partial(counter_text, dist)
    out.append(f"Single ticks at 30 deg (as 'Single-tick distribution, tuned preset'): over the "
               f"{fmt_count(dist, 'contact_ticks')} ticks with contact mean {c('contact_mean_us')} us, p50 "
               f"{c('contact_p50_us')} us, p99 {c('contact_p99_us')} us, slowest tick by its own cost "
               f"{c('contact_worst_tick_us')} us.")
    out.append("")
    return out


ctx = contexts[0] if contexts else {}
now = run_info["started_utc"]
md = []
md.append("# Haptic tick benchmarks")
md.append("")
md.append(f"- Command: `{command_line}` (Google Benchmark, `--benchmark_repetitions=5 "
          "--benchmark_report_aggregates_only=true`; every time below is the median of the 5 "
          "repetitions, wall-clock time per iteration)")
md.append(f"- Machine: {cpu_model()}, {os.cpu_count()} cores, host `{socket.gethostname()}`"
          + (f", {ctx.get('mhz_per_cpu')} MHz" if ctx.get("mhz_per_cpu") else ""))
md.append(f"- Date: {now}")
md.append(f"- Git revision: {revision}")
md.append(f"- Build: CMake Release; Google Benchmark library build type: {ctx.get('library_build_type', 'n/a')}")
md.append("- Raw data: `bench_tick.json`, `bench_effects.json` next to this file")
md.append("- Before and after a change of the tick, the same scenes' `puncture run` interleaved: "
          "[tick_before_after.md](tick_before_after.md) (`scripts/tick_ab.sh`)")
md.append("- Spread: coefficient of variation (stddev / mean) of the wall time over the 5 repetitions, %")
md.append("- The Debian libbenchmark package reports itself as a debug build; that concerns the timing "
          "harness only, the project code is compiled Release (-O3)")
md.append("- Columns: `median us / tick` is wall-clock time (what the 1 kHz loop sees), `CPU us / tick` the "
          "process CPU time; they differ when other processes compete for the 2 cores (load average "
          f"{run_info['load_average_before']} before the run, {run_info['load_average_after']} after). "
          "Ratios use the CPU-time medians, which other processes disturb less.")
md.append("")
md.append("The haptic tick is stateful, so every benchmark replays the scene's scripted insertion "
          "(tick i at t = i ms) over a tick range ('phase') and rebuilds the simulator outside the "
          "timed region when the range ends (tests/benchmarks/bench_replay.hpp). One iteration is "
          "one `PunctureSimulator::tick()`. Two models: the tuned preset "
          "(results/tuned_preset/default_tuned.json, the model the app and every validation run: "
          "stiffening skin and muscle force meshes, whose step is a Newton solve in every tick that "
          "presses them; tip stiffening, cutting, friction) and the default scene (scenes/default.json, "
          "every effect on, linear force meshes). Both: SH degree l = 16, implicit force-mesh integrator, "
          "w = 8 / 4 / 10 (skin / fat / muscle).")
md.append("")
md.extend(tuned_sections())

whole = get("BM_tick_phase/whole_insertion").get("median_us")
dist = get("BM_tick_distribution/whole_insertion")
p50_all, p50_press = dist.get("counter:p50_us"), dist.get("counter:press_p50_us")
if p50_all is not None and p50_press is not None:
    verdict = "met" if max(p50_all, p50_press) <= 10.0 else "NOT met"
    md.append(f"**Target: median tick <= 10 us (default scene, all effects on, l = 16): {verdict}.** "
              f"Median single tick over the whole insertion {fmt_time(p50_all)} us; over the ticks that press "
              f"the skin (the most expensive phase) {fmt_time(p50_press)} us, p99 "
              f"{fmt_time(dist.get('counter:press_p99_us'))} us; over the ticks with contact mean "
              f"{fmt_time(dist.get('counter:contact_mean_us'))} us, p99 {fmt_time(dist.get('counter:contact_p99_us'))} us "
              "(table 'Single-tick distribution').")
    md.append("")
if whole is not None:
    phase_means = [(p, get(f"BM_tick_phase/{p}")) for p in
                   ("press_skin", "after_skin_break", "inside_punctured", "in_tissue", "whole_insertion")]
    worst_name, worst = max(((p, r) for p, r in phase_means if r.get("median_us") is not None),
                            key=lambda pr: pr[1]["median_us"])
    md.append(f"Mean tick per phase (median of 5 repetitions): whole insertion {fmt_time(whole)} us wall / "
              f"{fmt_time(get('BM_tick_phase/whole_insertion').get('median_cpu_us'))} us CPU; slowest phase "
              f"{worst_name}: {fmt_time(worst['median_us'])} us wall / {fmt_time(worst.get('median_cpu_us'))} us CPU "
              f"({100.0 * worst['median_us'] / 1000.0:.2f} % of the 1 ms haptic period). A phase mean includes "
              "the rare ticks during which the process is preempted, so under load it exceeds the median tick.")
    md.append("")

same = [(n, get(n)) for n in ("BM_tick_phase/press_skin", "BM_tick_integrator/implicit/press_skin",
                              "BM_tick_sh_degree/16/press_skin")]
same = [(n, r) for n, r in same if r.get("median_cpu_us") is not None]
if len(same) > 1:
    cpu = [r["median_cpu_us"] for _, r in same]
    md.append("Measurement noise: the default configuration's press_skin phase is measured three times "
              "(" + ", ".join(f"`{n}` {fmt_time(r['median_cpu_us'])} us CPU" for n, r in same) + f"); their "
              f"spread (max / min = {max(cpu) / min(cpu):.2f}) is the run-to-run noise of this shared machine, "
              "so ratios closer to 1 than that are not differences.")
    md.append("")

md.append("## Tick by phase of the insertion (default scene)")
md.append("")
md.append("press_skin: the skin is pressed (force mesh active) until it breaks; after_skin_break: the "
          "ticks of the skin's recovery time (resumption_time_s) after it broke (skin resumption running, fat pressed); "
          "inside_punctured: after the last puncture until the target depth (damping, friction and "
          "cutting of the punctured layers, resumption in its first ticks); in_tissue: every tick with "
          "the tip below the skin surface (the ticks with contact, where the work is: the cost axis of "
          "`puncture sweep` and `summary.json` is the mean and p99 over these); whole_insertion: "
          "approach, insertion, dwell and withdrawal (its median is a tick without contact). "
          "Ratio: to whole_insertion.")
md.append("")
md.append(table(["phase", "ticks in phase", "median us / tick", "CPU us / tick", "ratio", "spread %"],
                [time_row(p, f"BM_tick_phase/{p}", "BM_tick_phase/whole_insertion", ("phase_ticks",))
                 for p in ("press_skin", "after_skin_break", "inside_punctured", "in_tissue", "whole_insertion")]))
md.append("")

md.append("## Single-tick distribution (default scene)")
md.append("")
md.append("BM_tick_distribution: every tick of whole insertions timed one by one with steady_clock "
          "(adds ~20-50 ns per tick); percentiles over all ticks of one benchmark run, then the median "
          "over the 5 repetitions. The mean per phase above hides the slow ticks; these are what a 1 kHz "
          "loop must absorb.")
md.append("")
r = get("BM_tick_distribution/whole_insertion")
counter = functools.partial(counter_text, r)
md.append(table(["ticks", "p50 us", "p90 us", "p99 us", "max us"],
                [["all ticks of the insertion", counter("p50_us"), counter("p90_us"), counter("p99_us"),
                  counter("max_us")],
                 ["press_skin ticks", counter("press_p50_us"), "", counter("press_p99_us"),
                  counter("press_max_us")],
                 [f"ticks with contact ({fmt_count(r, 'contact_ticks')}; mean {counter('contact_mean_us')} us)",
                  counter("contact_p50_us"), "", counter("contact_p99_us"), ""]]))
md.append("")

md.append("## Force-mesh integrator")
md.append("")
md.append("Ratio: to the default (implicit) for the same phase.")
md.append("")
lines = []
for integ in ("quasi_static", "explicit", "implicit"):
    for phase in ("press_skin", "whole_insertion"):
        lines.append(time_row(f"{integ} / {phase}", f"BM_tick_integrator/{integ}/{phase}",
                              f"BM_tick_phase/{phase}", ("punctures",)))
md.append(table(["integrator / phase", "punctures", "median us / tick", "CPU us / tick", "ratio", "spread %"], lines))
md.append("")

md.append("## Rings w (every layer)")
md.append("")
md.append("All layers get the same w; L is kept where (w - 1) L <= 0.9 R (R = 30 mm sample radius) "
          "and shrunk to 0.9 R / (w - 1) otherwise, so the mesh stays inside the sample. A mesh of w "
          "rings has 1 + 3 w (w - 1) nodes; larger w needs more deflection before ring w is deformed, "
          "so the number of punctures reached by the 30 mm insertion changes with w (column "
          "punctures), and with it what the whole insertion contains. Ratio: to the default scene "
          "(w = 8 / 4 / 10) for the same phase.")
md.append("")
lines = []
for w in (2, 4, 8, 16, 32):
    for phase in ("press_skin", "whole_insertion"):
        lines.append(time_row(f"{w} / {phase}", f"BM_tick_rings_w/{w}/{phase}", f"BM_tick_phase/{phase}",
                              ("mesh_nodes_all_layers", "phase_ticks", "punctures")))
md.append(table(["w / phase", "mesh nodes (3 layers)", "ticks in phase", "punctures", "median us / tick", "CPU us / tick",
                 "ratio", "spread %"], lines))
md.append("")

md.append("## SH degree l")
md.append("")
md.append("Where l enters: the SH layer surface is queried inside the tick only by the contact ray "
          "(`LayerSurface::intersect_ray`) once per layer, the first tick that layer is reached; the "
          "force-mesh nodes are projected onto the surface at construction. So the per-tick cost "
          "should not depend on l; the ray query and the model construction do (tables below). "
          "Ratio: to l = 16 (default) for the same phase.")
md.append("")
lines = []
for l in (4, 8, 16, 24, 32):
    for phase in ("press_skin", "whole_insertion"):
        lines.append(time_row(f"{l} / {phase}", f"BM_tick_sh_degree/{l}/{phase}", f"BM_tick_phase/{phase}",
                              ("punctures",)))
md.append(table(["l / phase", "punctures", "median us / tick", "CPU us / tick", "ratio", "spread %"], lines))
md.append("")
md.append("### The SH query alone: `LayerSurface::intersect_ray` on the skin surface")
md.append("")
md.append("on_axis: the needle axis (the query the tick makes; it hits the parameterisation's north "
          "pole); off_axis: vertical rays at 64 lateral positions spread over 0.8 R. Ratio: to l = 16.")
md.append("")
lines = []
for l in (4, 8, 16, 24, 32):
    for mode in ("on_axis", "off_axis"):
        lines.append(time_row(f"{l} / {mode}", f"BM_sh_intersect_ray/{l}/{mode}",
                              f"BM_sh_intersect_ray/16/{mode}"))
md.append(table(["l / rays", "median us / query", "CPU us / query", "ratio", "spread %"], lines))
md.append("")
md.append("### Model construction (outside the haptic loop): `build_realtime_model`")
md.append("")
md.append("SH fit of the three layer surfaces + force-mesh layout + implicit factorisation. Ratio: to l = 16.")
md.append("")
lines = []
for l in (4, 8, 16, 24, 32):
    r = get(f"BM_build_realtime_model/{l}")
    ref = get("BM_build_realtime_model/16").get("median_us")
    ms = r.get("median_us") / 1e3 if r.get("median_us") is not None else None
    lines.append([str(l), f"{ms:.2f}" if ms is not None else "n/a",
                  fmt_ratio(r.get("median_cpu_us"), get("BM_build_realtime_model/16").get("median_cpu_us")), spread(r)])
md.append(table(["l", "median ms / build", "ratio", "spread %"], lines))
md.append("")

md.append("## Force mesh laid at an off-axis contact point")
md.append("")
md.append("`ForceMesh::relayout` on the layer's SH surface (l = 16) at a new contact point: the lattice is laid "
          "in the tangent plane at once (the force is exact from this tick: the mechanics are deflections along "
          "the normals), then `refine_layout` projects 4 nodes per tick onto the curved surface (a few us each) "
          "until the drawn mesh lies on it. An on-axis needle never pays either (the meshes are laid on the axis "
          "at construction).")
md.append("")
lines = []
for k, name in ((0, "skin (w = 8)"), (2, "muscle (w = 10)")):
    r, q = get(f"BM_force_mesh_relayout/{k}"), get(f"BM_force_mesh_refine/{k}")
    lines.append([name, fmt_count(r, "mesh_nodes") if "counter:mesh_nodes" in r else "n/a",
                  fmt_time(r.get("median_us")), fmt_time(q.get("median_us")),
                  fmt_count(q, "ticks_to_complete") if "counter:ticks_to_complete" in q else "n/a"])
md.append(table(["layer", "mesh nodes", "us in the contact tick", "us in each later tick", "later ticks"], lines))
md.append("")

md.append("## Effects on / off")
md.append("")
md.append("An effect that is off is not constructed (tests/core/model/test_effects_off.cpp checks the "
          "objects are absent and the forces exactly 0). all_on is the default scene (surface force, "
          "damping, resumption, cutting, friction); paper: Table 1 and Eq. 8 only; surface_force_off also "
          "removes resumption (it needs the force mesh) and every layer then breaks as soon as the tip "
          "passes its surface; stiffening_on and interaction_on add the tip stiffening and the layers in "
          "series (tests/benchmarks/bench_effects.cpp gives their parameters); surface_output does not "
          "enter the tick. Ratio: to all_on for the same phase.")
md.append("")
lines = []
for cfg in ("all_on", "paper", "surface_force_off", "damping_off", "resumption_off", "cutting_off", "friction_off",
            "stiffening_on", "interaction_on", "all_off"):
    for phase in ("whole_insertion", "in_tissue", "inside_punctured"):
        lines.append(time_row(f"{cfg} / {phase}", f"BM_effects/{cfg}/{phase}", f"BM_effects/all_on/{phase}",
                              ("phase_ticks", "punctures")))
md.append(table(["effects / phase", "ticks in phase", "punctures", "median us / tick", "CPU us / tick", "ratio", "spread %"],
                lines))
md.append("")

with open(os.path.join(out_dir, "tick_benchmarks.md"), "w") as f:
    f.write("\n".join(md))
print("wrote", os.path.join(out_dir, "tick_benchmarks.md"))
PY
