#!/usr/bin/env bash
# Paper section 9: N = 10 against N = 4 variations on the backflip and the high jump, the
# same generations per variation and seed, then the table of scripts/distinct-variations.py
# (pairs farther apart than multiples of the nudged-M0 distance, the largest set of
# pairwise distinct motions, mean distances; docs/results.md has the last one).
#   scripts/compare-n.sh [GENERATIONS] [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
generations="${1:-500}"
out="${2:-$here/runs/compare-n}"
diverse="$here/build/diverse"
[ -x "$diverse" ] || { echo "compare-n.sh: $diverse is not built (scripts/build.sh)" >&2; exit 2; }
runs=()
for task in backflip jump_high; do
  for n in 4 10; do
    "$diverse" run "$task" --n "$n" --generations "$generations" --seed 1 --out "$out/$task-n$n" --force
    runs+=("$out/$task-n$n")
  done
done
python3 "$here/scripts/distinct-variations.py" "${runs[@]}" | tee "$out/table.md"
