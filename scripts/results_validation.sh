#!/usr/bin/env bash
# Regenerates the committed validation results of the default scene:
#   results/validation_default/  puncture validate: the default (Table 2) real-time
#                                model against the FEM reference
#   results/fem_vs_literature.md the FEM reference's numbers beside the measurements
#   results/validation_paper_table2/ puncture validate of the paper's model as written
#   results/tuned_preset/        puncture calibrate: tuned preset of the Table 2 slab
#                                with the physical force law (scenes/default_force_law.json:
#                                critical-force breakthrough, stiffening, cutting, friction),
#                                in two steps: single_speed/ the force meshes of the skin and
#                                muscle from the FEM's force and surface profiles together
#                                (--surface-fit), then everything but d on the FEM
#                                reference at the scene's 10 mm/s (d cannot be told from the
#                                friction at one speed); then d, the breakthrough rate
#                                exponents n, the cutting viscous fractions b and the release
#                                rate exponents m from the viscoelastic FEM references at 1 and
#                                10 mm/s (3 and 20 mm/s stay held
#                                out, scripts/results_heldout.sh): default_tuned.json;
#                                provenance, identifiability, before/after plot, wall time
#   results/liver_calibration/   puncture calibrate of the two-layer liver scene against the
#                                measured Okamura 2004 curve (../shared/data)
#   results/validation_tuned/    puncture validate of the tuned preset
#   results/surface_transmission/ how the FEM's layer surfaces move together, beside the
#                                rules of the coupled_surfaces effect (surface_transmission_study.py)
#   results/accuracy_cost/       puncture sweep of the tuned preset (real-time knobs
#                                against the default-resolution FEM)
# The FEM reference runs once, on RANKS MPI ranks (default 2; about 5 min), and is
# cached in out/.fem_cache: the later commands read it from there.
#   bash scripts/results_validation.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
ranks="${RANKS:-2}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
export OMPI_ALLOW_RUN_AS_ROOT="${OMPI_ALLOW_RUN_AS_ROOT:-1}" OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}"
mpi=(mpirun --oversubscribe -np "$ranks")
"${mpi[@]}" "$build/apps/puncture" validate scenes/default.json -o results/validation_default
# The FEM reference beside the measurements (from the cached FEM run just
# used), with the speed trends of results/fem_rate (scripts/fem_rate_study.sh).
py="${PYTHON:-$(command -v /usr/bin/python3 || command -v python3)}"
fem_dir="$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["fem_reference"]["cache_dir"])' results/validation_default/validation_metrics.json)"
rate=()
[ -f results/fem_rate/rate.json ] && rate=(results/fem_rate/rate.json)
"$py" scripts/fem_vs_literature.py "${fem_dir%/}" scenes/default.json results/fem_vs_literature.md "${rate[@]}"
# The seed paper's model as written, on the same slab and FEM reference.
"${mpi[@]}" "$build/apps/puncture" validate scenes/paper_table2.json -o results/validation_paper_table2
# Puncture forces weigh 4x (the acceptance asks for them within 10 %, and a
# weight of 1 let the skin's trade 10 % for a closer fit after its peak);
# puncture depths weigh 1 per L (0.1 let the muscle break 4.8 mm early).
# --surface-fit: the skin's and muscle's force meshes (K, k_s, k_a, z_v) from
# the FEM's force and surface profiles together, no tip stiffening.
"$build/apps/puncture" calibrate scenes/default_force_law.json -o results/tuned_preset/single_speed --name default_tuned_single_speed \
  --integrator implicit --force-weight 4 --depth-weight 1 --surface-fit
# d, the breakthrough rate exponents n (core/include/puncture/breakthrough_rate.hpp), the
# cutting viscous fractions b and release rate exponents m (core/include/puncture/cutting.hpp)
# from two speeds, with the shaft friction (f_d and presliding): at one speed the
# friction cannot be told from d h v, so the single-speed step's split (d at its start
# value) would stay; every other parameter kept at the single-speed values (tuning
# them on both speeds at once let the muscle stop puncturing).
"${mpi[@]}" "$build/apps/puncture" calibrate results/tuned_preset/single_speed/default_tuned_single_speed.json -o results/tuned_preset \
  --name default_tuned --integrator implicit --force-weight 4 --depth-weight 1 --fem-speeds 1,10 \
  --keep K,breakthrough,cutting,stiffening
shared="${PUNCTURE_SHARED_DATA_DIR:-$root/../shared/data}"
"$build/apps/puncture" calibrate scenes/liver_okamura.json -o results/liver_calibration --name liver_tuned \
  --reference "$shared/okamura2004_liver_depth_force.csv" --reference-depth-offset 9.5 --puncture-depths 9.65,9.66
rm -rf results/validation_tuned  # no frames left from an earlier FEM reference
"${mpi[@]}" "$build/apps/puncture" validate results/tuned_preset/default_tuned.json -o results/validation_tuned
tuned_fem="$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["fem_reference"]["cache_dir"])' results/validation_tuned/validation_metrics.json)"
"$py" scripts/surface_transmission_study.py "${tuned_fem%/}" results/tuned_preset/default_tuned.json results/surface_transmission
"$build/apps/puncture" sweep results/tuned_preset/default_tuned.json --no-fem-knobs -o results/accuracy_cost
echo "results in results/validation_default, results/validation_paper_table2, results/tuned_preset, results/liver_calibration, results/validation_tuned, results/surface_transmission, results/accuracy_cost"
