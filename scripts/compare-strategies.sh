#!/usr/bin/env bash
# Paper section 9: round-robin against progressive addition on the backflip, N = 4,
# five seeds each; prints Dmin, mean and Dmax of both beside the paper's figures.
#   scripts/compare-strategies.sh [GENERATIONS] [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
generations="${1:-500}"
out="${2:-$here/runs/section9}"
diverse="$here/build/diverse"
for strategy in round-robin progressive; do
  for seed in 1 2 3 4 5; do
    "$diverse" run backflip --n 4 --generations "$generations" --strategy "$strategy" \
      --seed "$seed" --out "$out/$strategy-$seed" --force --quiet
  done
done
"$diverse" report "$out"/round-robin-* "$out"/progressive-* | tee "$out/table.md"
echo
echo "paper: progressive Dmin 41.8, mean 54.4, Dmax 64.1; round-robin 71.2 / 83.5 / 103.7"
for strategy in round-robin progressive; do
  awk -F'|' -v s="$strategy" '$5 ~ s { d = $9 + 0; n++; sum += d; if (n == 1 || d < lo) lo = d; if (n == 1 || d > hi) hi = d }
    END { printf "ours:  %-12s Dmin %.4g, mean %.4g, Dmax %.4g (%d runs)\n", s, lo, sum / n, hi, n }' "$out/table.md"
done
