#!/usr/bin/env bash
# README command 1: install dependencies, build, and run the project's best model: the tuned
# preset of the default slab (results/tuned_preset/default_tuned.json, validated against the
# FEM in results/validation_tuned/), then print its punctures beside the FEM's.
#   bash scripts/main.sh            -> puncture run (the tuned preset) into out/default_tuned
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
cd "$root"
"${PUNCTURE_BUILD_DIR:-$root/build}/apps/puncture" run results/tuned_preset/default_tuned.json -o out/default_tuned
/usr/bin/python3 scripts/main_summary.py out/default_tuned
