#!/usr/bin/env bash
# fem_mesh_convergence.sh: mesh-convergence study of the FEM indentation force.
#
# The 3D reference (fem.geometry "3d", the model for blunt tips) on the default
# scene's slab (materials, thicknesses, needle radius) with a flat tip
# (scripts/blunt_3d_scene.py) is indented to DEPTH_MM (default 0.5 mm,
# puncture switched off) on a sequence of meshes (cells around the
# circumference, uniform refinements, element degree); the force at that
# depth is tabulated with its change relative to the mesh with the most dofs.
#
# Usage: scripts/fem_mesh_convergence.sh [BUILD_DIR]   (default: build)
#   needs the target puncture_fem_study:  cmake --build BUILD_DIR --target puncture_fem_study
# Writes results/fem_mesh_convergence.md.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
EXE=$BUILD/reference_fem/puncture_fem_study
SRC_SCENE=${SCENE:-$ROOT/scenes/default.json}
DEPTH=${DEPTH_MM:-0.5}
OUT=$ROOT/results/fem_mesh_convergence.md
# sectors refinement degree
CONFIGS=${CONFIGS:-"8 0 1;16 0 1;24 0 1;32 0 1;8 1 1;16 1 1"}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

rows=$(mktemp)
SCENE=$(mktemp --suffix=.json)
trap 'rm -f "$rows" "$OUT.part" "$SCENE"' EXIT
/usr/bin/python3 "$ROOT/scripts/blunt_3d_scene.py" "$SRC_SCENE" "$SCENE"
IFS=';' read -ra list <<< "$CONFIGS"
for cfg in "${list[@]}"; do
  # shellcheck disable=SC2086
  set -- $cfg
  echo "== sectors $1, refinement $2, Q$3" >&2
  "$EXE" indent "$SCENE" "$DEPTH" "$1" "$2" "$3" | tail -n 1 >> "$rows"
done
finest=$(sort -t'|' -k6,6n "$rows" | tail -n 1 | awk -F'|' '{print $7}')
{
  echo "# 3D FEM reference (blunt tip): mesh convergence of the indentation force"
  echo
  echo "Command: \`scripts/fem_mesh_convergence.sh\` (DEPTH_MM=$DEPTH, scene $(basename "$SRC_SCENE") with a flat tip and fem.geometry 3d, scripts/blunt_3d_scene.py), git $(git -C "$ROOT" rev-parse --short HEAD)."
  echo "Machine: $(uname -srm), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')), 1 MPI rank."
  echo "Date: $(date -u '+%Y-%m-%d %H:%M UTC')."
  echo
  echo "This is the reference for blunt (flat) tips; the default scene's bevel needle runs the axisymmetric"
  echo "reference, whose convergence study is fem_axisymmetric_convergence.md. Flat rigid needle tip (radius"
  echo "from the scene, held laterally: no slip under the punch) pressed to $DEPTH mm into the three-layer slab,"
  echo "puncture off, Hu-Washizu three-field formulation (Q1-P0 / Q2-P1). Refinement is uniform (every hexahedron"
  echo "split in 8), sectors refine only around the circumference and radially. The last column is the force"
  echo "relative to the mesh with the most dofs."
  echo
  echo "| sectors | refinements | element | formulation | dofs | force (N) | wall (s) | force / finest |"
  echo "|---|---|---|---|---|---|---|---|"
  awk -F'|' -v f="$finest" '{printf "|%s|%s|%s|%s|%s|%s|%s| %.4f |\n", $2,$3,$4,$5,$6,$7,$8, $7/f}' "$rows"
  echo
  echo "More sectors alone leave the error under the punch and through the thickness: the unrefined Q1 meshes"
  echo "converge (in sectors) to a force well above the uniformly refined ones. An independent finite-element code"
  echo "with quadratic elements on the same geometry (a check made outside this repository) converges to about"
  echo "0.0052 N at 0.5 mm, which one uniform refinement reproduces. The 3D run warns when it runs at Q1 without"
  echo "refinement (its default); use \`--refinement 1\` where the small-indentation force matters."
} > "$OUT.part"
mv "$OUT.part" "$OUT"
echo "wrote $OUT"
