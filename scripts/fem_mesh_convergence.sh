#!/usr/bin/env bash
# fem_mesh_convergence.sh: mesh-convergence study of the FEM indentation force.
#
# The default scene's slab (materials, thicknesses, needle) is indented by the
# flat needle tip to DEPTH_MM (default 0.5 mm, puncture switched off) on a
# sequence of meshes (cells around the circumference, global refinements,
# element degree); the force at that depth is tabulated with its change
# relative to the finest mesh.
#
# Usage: scripts/fem_mesh_convergence.sh [BUILD_DIR]   (default: build)
#   needs the target puncture_fem_study:  cmake --build BUILD_DIR --target puncture_fem_study
# Writes results/fem_mesh_convergence.md.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
EXE=$BUILD/reference_fem/puncture_fem_study
SCENE=${SCENE:-$ROOT/scenes/default.json}
DEPTH=${DEPTH_MM:-0.5}
OUT=$ROOT/results/fem_mesh_convergence.md
# sectors refinement degree
CONFIGS=${CONFIGS:-"8 0 1;12 0 1;16 0 1;24 0 1;8 0 2;12 0 2"}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

rows=$(mktemp)
trap 'rm -f "$rows" "$OUT.part"' EXIT
IFS=';' read -ra list <<< "$CONFIGS"
for cfg in "${list[@]}"; do
  # shellcheck disable=SC2086
  set -- $cfg
  "$EXE" indent "$SCENE" "$DEPTH" "$1" "$2" "$3" | tail -n 1 >> "$rows"
done
finest=$(sort -t'|' -k6,6n "$rows" | tail -n 1 | awk -F'|' '{print $7}')
{
  echo "# FEM mesh convergence: indentation force of the default slab"
  echo
  echo "Command: \`scripts/fem_mesh_convergence.sh\` (DEPTH_MM=$DEPTH, scene $(basename "$SCENE"))."
  echo "Machine: $(uname -srm), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')), 1 MPI rank."
  echo "Date: $(date -u '+%Y-%m-%d %H:%M UTC')."
  echo
  echo "Flat rigid needle tip (radius from the scene) pressed to $DEPTH mm into the"
  echo "three-layer slab, puncture off, Hu-Washizu three-field formulation (Q1-P0 / Q2-P1)."
  echo "The last column is the force relative to the mesh with the most dofs."
  echo
  echo "| sectors | refinements | element | formulation | dofs | force (N) | wall (s) | force / finest |"
  echo "|---|---|---|---|---|---|---|---|"
  awk -F'|' -v f="$finest" '{printf "|%s|%s|%s|%s|%s|%s|%s| %.4f |\n", $2,$3,$4,$5,$6,$7,$8, $7/f}' "$rows"
} > "$OUT.part"
mv "$OUT.part" "$OUT"
echo "wrote $OUT"
