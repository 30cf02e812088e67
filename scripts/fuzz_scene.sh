#!/usr/bin/env bash
# Fuzzes the scene reader (libFuzzer, clang; tests/fuzz/fuzz_scene_reader.cpp)
# from a seed corpus of the shipped scenes (scenes/*.json and the tuned
# preset), with a dictionary of the schema's keys (tests/fuzz/scene.dict).
#
#   bash scripts/fuzz_scene.sh --runs N [--fuzzer PATH] [--report FILE]
#   bash scripts/fuzz_scene.sh --short  (20 000 runs: the ctest test fuzz.scene_reader_short)
#
# Exits non-zero if the fuzzer found a crash, a sanitizer report, a hang or an
# uncaught exception, or did not execute the requested number of runs.
# Prints "executed: N" (libFuzzer's stat::number_of_executed_units).
# --report FILE writes key: value lines (runs, executed, crashes, seconds,
# corpus files) for scripts/results_fuzz.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
runs=""
fuzzer="${PUNCTURE_BUILD_DIR:-$root/build}/fuzz/fuzz_scene_reader"
report=""
while (( $# )); do
  case "$1" in
    --short) runs=20000 ;;
    --runs) runs="$2"; shift ;;
    --fuzzer) fuzzer="$2"; shift ;;
    --report) report="$2"; shift ;;
    *) echo "usage: fuzz_scene.sh --short | --runs N [--fuzzer PATH] [--report FILE]" >&2; exit 2 ;;
  esac
  shift
done
[[ -n "$runs" ]] || { echo "fuzz_scene.sh: give --short or --runs N" >&2; exit 2; }
if ! command -v clang++ > /dev/null; then
  echo "fuzz_scene.sh: clang++ not found: the fuzz target needs clang and libFuzzer (Debian packages clang," \
       "libclang-rt-14-dev); run scripts/setup.sh" >&2
  exit 1
fi
if [[ ! -x "$fuzzer" ]]; then
  echo "fuzz_scene.sh: no fuzz target at $fuzzer: build the project (bash scripts/build.sh) with clang installed" >&2
  exit 1
fi

work="$(dirname "$fuzzer")/run-$$"
rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts"
trap 'rm -rf "$work"' EXIT
cp "$root"/scenes/*.json "$work/corpus/"
[[ -f "$root/results/tuned_preset/default_tuned.json" ]] && cp "$root/results/tuned_preset/default_tuned.json" "$work/corpus/"
seeds=$(ls "$work/corpus" | wc -l)

start=$(date +%s)
set +e
"$fuzzer" -runs="$runs" -seed=1 -dict="$root/tests/fuzz/scene.dict" -max_len=16384 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" > "$work/log" 2>&1
status=$?
set -e
seconds=$(( $(date +%s) - start ))
executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log" | tail -1)
crashes=$(ls "$work/artifacts" | wc -l)
corpus=$(ls "$work/corpus" | wc -l)
echo "fuzz_scene_reader: status $status, executed: ${executed:-0} of $runs runs, $crashes crash artifacts," \
     "$seconds s, corpus $seeds seeds -> $corpus inputs"
if [[ -n "$report" ]]; then
  printf 'runs: %s\nexecuted: %s\ncrashes: %s\nexit_status: %s\nseconds: %s\nseed_files: %s\ncorpus_files: %s\n' \
    "$runs" "${executed:-0}" "$crashes" "$status" "$seconds" "$seeds" "$corpus" > "$report"
  grep -E '^(#[0-9]+ +DONE|stat::)' "$work/log" >> "$report" || true
fi
if (( status != 0 || crashes != 0 )) || [[ "${executed:-0}" -lt "$runs" ]]; then
  echo "fuzz_scene.sh: FAILED (log below)" >&2
  tail -60 "$work/log" >&2
  mkdir -p "$root/out/fuzz_findings"
  cp "$work"/artifacts/* "$root/out/fuzz_findings/" 2>/dev/null || true
  exit 1
fi
