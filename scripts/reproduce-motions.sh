#!/usr/bin/env bash
# Paper figure 5 (2D rows): N = 4 diverse variations for each of the five 2D tasks with
# the paper's metric, then a table of the results (docs/results.md has the last one).
#   scripts/reproduce-motions.sh [GENERATIONS] [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
generations="${1:-500}"
out="${2:-$here/runs/fig5}"
diverse="$here/build/diverse"
for task in backflip jump_forward jump_onto jump_over jump_high; do
  "$diverse" run "$task" --n 4 --generations "$generations" --seed 1 --out "$out/$task" --force
done
"$diverse" report "$out"/backflip "$out"/jump_forward "$out"/jump_onto "$out"/jump_over "$out"/jump_high \
  | tee "$out/table.md"
