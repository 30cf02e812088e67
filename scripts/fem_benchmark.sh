#!/usr/bin/env bash
# fem_benchmark.sh: speed of the FEM reference versus problem size and ranks.
#
# The 3D reference (fem.geometry "3d", the model for blunt tips) on the
# default slab with a flat tip (scripts/blunt_3d_scene.py). Three mesh sizes
# (8, 16 and 24 cells around the circumference, Q1), each on 1 and 2 MPI ranks: an indentation to DEPTH_MM
# (default 1 mm, two load steps of the scene); time per Newton iteration and
# per load step. With FULL=1 also the full insertion of that scene at
# its default resolution on 2 ranks (wall time of `puncture_fem_study run`,
# its punctures and Newton counts).
#
# Usage: scripts/fem_benchmark.sh [BUILD_DIR]   (default: build)
# Writes results/fem_benchmark.md.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
EXE=$BUILD/reference_fem/puncture_fem_study
SRC_SCENE=${SCENE:-$ROOT/scenes/default.json}
DEPTH=${DEPTH_MM:-1.0}
OUT=$ROOT/results/fem_benchmark.md
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPIRUN=${MPIRUN:-mpirun --oversubscribe}

rows=$(mktemp)
SCENE=$(mktemp --suffix=.json)
trap 'rm -f "$rows" "$OUT.part" "$SCENE"' EXIT
/usr/bin/python3 "$ROOT/scripts/blunt_3d_scene.py" "$SRC_SCENE" "$SCENE"
for sectors in 8 16 24; do
  for ranks in 1 2; do
    printf '| %s ' "$sectors" >> "$rows"
    $MPIRUN -np "$ranks" "$EXE" bench "$SCENE" "$DEPTH" "$sectors" 0 1 | tail -n 1 >> "$rows"
  done
done
full=""
if [ "${FULL:-0}" = "1" ]; then
  full_dir=$(mktemp -d)
  t0=$(date +%s)
  $MPIRUN -np 2 "$EXE" run "$SCENE" "$full_dir" > "$full_dir/log.txt"
  wall=$(( $(date +%s) - t0 ))
  full=$(/usr/bin/python3 - "$full_dir/fem_summary.json" "$wall" "$(basename "$SRC_SCENE") (flat tip, 3d)" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
p = ", ".join(f'{e["name"]} at {e["depth_mm"]:.3f} mm ({e["force_N"]:.4f} N)' for e in s["punctures"])
print(f"Full insertion of {sys.argv[3]} at its default resolution ({s['n_dofs']} DoFs), 2 ranks: "
      f"{sys.argv[2]} s wall; {s['load_steps']} load steps, {s['newton_iterations']} Newton iterations, "
      f"{s['puncture_bisections']} puncture bisections, {s['spring_back_stages']} spring-back stages, "
      f"{s['step_cuts']} step cuts; punctures: {p}.")
PY
)
fi
{
  echo "# 3D FEM reference (blunt tip): time per Newton iteration and per load step"
  echo
  echo "Command: \`scripts/fem_benchmark.sh\` (DEPTH_MM=$DEPTH, scene $(basename "$SRC_SCENE") with a flat tip and fem.geometry 3d, scripts/blunt_3d_scene.py), git $(git -C "$ROOT" rev-parse --short HEAD)."
  echo "Machine: $(uname -srm), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))."
  echo "Date: $(date -u '+%Y-%m-%d %H:%M UTC'). Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
  echo
  echo "Q1-P0 three-field, CG + ML AMG (rigid-body near null space, rebuilt once per load step),"
  echo "inexact Newton (CG to 1e-4 relative), extrapolated predictor. Times include assembly,"
  echo "line search and linear solves (s)."
  echo
  echo "| sectors | ranks | dofs | load steps | Newton its | CG its / Newton it | s / Newton it | s / load step | wall (s) |"
  echo "|---|---|---|---|---|---|---|---|---|"
  cat "$rows"
  echo
  if [ -n "$full" ]; then echo "$full"; else
    echo "The default scene (bevel needle) runs the axisymmetric reference; its full-trajectory timing is"
    echo "results/fem_axisymmetric_timing.md. FULL=1 adds a full insertion of the flat-tip scene here."
  fi
} > "$OUT.part"
mv "$OUT.part" "$OUT"
echo "wrote $OUT"
