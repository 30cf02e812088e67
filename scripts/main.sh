#!/usr/bin/env bash
# README command 1: install dependencies, build, and run the default scene.
#   bash scripts/main.sh            -> puncture run (scenes/default.json) into out/default
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
cd "$root"
"${PUNCTURE_BUILD_DIR:-$root/build}/apps/puncture" run
