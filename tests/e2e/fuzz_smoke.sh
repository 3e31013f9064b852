#!/usr/bin/env bash
# A short pass of every libFuzzer target: its committed corpus (fuzz/corpus/<target>/) plus
# SECONDS_EACH seconds of new inputs in a scratch directory. Any crash, hang, sanitizer
# report or uncaught exception (an "internal error") fails. Skipped (77) where the targets
# were not built (no clang).
set -euo pipefail
fuzz_dir="$1"
source_dir="$2"
seconds_each="${SECONDS_EACH:-8}"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
status=0
for target in task_file character_file parameter_file motion_file checkpoint; do
  binary="$fuzz_dir/${target}_fuzzer"
  if [ ! -x "$binary" ]; then
    echo "fuzz_smoke: $binary not built" >&2
    exit 77
  fi
  mkdir -p "$scratch/$target"
  if ! (cd "$scratch" && "$binary" -max_total_time="$seconds_each" -timeout=10 -rss_limit_mb=2048 \
          -print_final_stats=1 "$scratch/$target" "$source_dir/fuzz/corpus/$target" \
          >"$scratch/$target.log" 2>&1); then
    echo "fuzz_smoke: $target failed:" >&2
    tail -40 "$scratch/$target.log" >&2
    status=1
  else
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$scratch/$target.log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_smoke: $target: $runs inputs, no failure"
  fi
done
exit $status
