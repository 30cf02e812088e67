#!/usr/bin/env bash
# results/fuzz/: the scene reader fuzzed for at least 10^6 executions
# (scripts/fuzz_scene.sh), with the count, crashes (must be 0), time and
# provenance in results/fuzz/fuzz_scene_reader.md.
#   bash scripts/results_fuzz.sh [RUNS]     (default 1000000)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
runs="${1:-1000000}"
cd "$root"
[[ -x "$build/fuzz/fuzz_scene_reader" ]] || bash scripts/build.sh
mkdir -p results/fuzz
report="$(mktemp)"
bash scripts/fuzz_scene.sh --runs "$runs" --fuzzer "$build/fuzz/fuzz_scene_reader" --report "$report"
when="$(date -u +%Y-%m-%dT%H:%M:%SZ)"
machine="$(hostname) ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores)"
rev="$(git rev-parse --short=7 HEAD 2>/dev/null || echo unknown)"
[[ -z "$(git status --porcelain --untracked-files=no 2>/dev/null)" ]] || rev="$rev-dirty"
clang="$(clang++ --version | head -1)"
value() { sed -n "s/^$1: *//p" "$report" | head -1; }
tmp="results/fuzz/.fuzz_scene_reader.md.tmp"
{
  echo "# Fuzzing the scene reader"
  echo
  echo "Made by \`bash scripts/results_fuzz.sh $runs\` on $machine, $when (git $rev), $clang."
  echo
  echo "libFuzzer target \`tests/fuzz/fuzz_scene_reader.cpp\` (AddressSanitizer + UndefinedBehaviorSanitizer):"
  echo "any bytes through \`parse_scene\` must give a Scene or a SceneError; a scene that loads must"
  echo "serialise to a text that loads again and is stable after one round trip. Seed corpus: the"
  echo "shipped scenes (\`scenes/*.json\`, \`results/tuned_preset/default_tuned.json\`); dictionary:"
  echo "\`tests/fuzz/scene.dict\` (the schema's keys); \`-seed=1 -max_len=16384 -timeout=10\`."
  echo
  echo "| quantity | value |"
  echo "|---|---|"
  echo "| runs requested | $(value runs) |"
  echo "| executions (stat::number_of_executed_units) | $(value executed) |"
  echo "| crashes, sanitizer reports, timeouts, uncaught exceptions | $(value crashes) |"
  echo "| fuzzer exit status | $(value exit_status) |"
  echo "| wall time | $(value seconds) s |"
  echo "| corpus | $(value seed_files) seeds -> $(value corpus_files) inputs |"
  echo "| peak RSS | $(value stat::peak_rss_mb) MB |"
  echo "| new units added | $(value stat::new_units_added) |"
} > "$tmp"
mv "$tmp" results/fuzz/fuzz_scene_reader.md
rm -f "$report"
cat results/fuzz/fuzz_scene_reader.md
