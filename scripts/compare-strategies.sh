#!/usr/bin/env bash
# Paper section 9: round-robin against progressive addition on the backflip, N = 4,
# five seeds each; prints Dmin, mean and Dmax of both beside the paper's figures.
#   scripts/compare-strategies.sh [GENERATIONS] [OUT] [VARIANT] [STRATEGIES]
# STRATEGIES (default "round-robin progressive") names the strategies to compare, e.g.
# "round-robin simultaneous" (docs/results.md); every one runs the same five seeds.
# VARIANT is `ours` (default: violating samples rank below feasible ones, a variation
# stands at its best sample) or `paper` (eq. 1 literally: --constraints penalty --point
# mean, as the paper prints it).
# (DIVERSE=path picks the `diverse` binary; default build/diverse. TASK=name runs another
# task than the backflip, e.g. to try the script quickly. SEEDS="1 2" runs and reports
# only those seeds, so a long comparison can be made a pair of runs at a time.)
# At 500 generations one backflip run (2 ms, constrained damping) takes about 10 minutes on
# an idle 2-core machine (round-robin, seed 1: 625.9 s), so the ten take under two hours. The script
# can be stopped at any moment and started again with the same arguments: a finished
# run with the same settings is kept, an interrupted one continues from its checkpoint
# (`diverse resume`, same result as uninterrupted), anything else is run afresh.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
generations="${1:-500}"
out="${2:-$here/runs/section9}"
variant="${3:-ours}"
strategies="${4:-round-robin progressive}"
seeds="${SEEDS:-1 2 3 4 5}"
diverse="${DIVERSE:-$here/build/diverse}"
task="${TASK:-backflip}"
case "$variant" in
  ours) constraints=dominant point=best-sample ;;
  paper) constraints=penalty point=mean ;;
  *) echo "compare-strategies.sh: VARIANT: expected ours or paper, got '$variant'" >&2; exit 2 ;;
esac
for seed in $seeds; do
  [[ "$seed" =~ ^[0-9]+$ ]] || { echo "compare-strategies.sh: SEEDS: expected whole numbers separated by spaces, got '$seeds'" >&2; exit 2; }
done
[ -n "${seeds// /}" ] || { echo "compare-strategies.sh: SEEDS: expected at least one seed, got an empty list" >&2; exit 2; }
[ -x "$diverse" ] || { echo "compare-strategies.sh: $diverse is not built (scripts/build.sh)" >&2; exit 2; }
command -v jq >/dev/null || { echo "compare-strategies.sh: needs jq (scripts/setup.sh installs it)" >&2; exit 2; }

# Does DIR hold a run of this comparison (task, strategy, seed, generations, variant)?
same_run() {
  [ -f "$1/run.json" ] &&
    jq -e --arg s "$2" --argjson seed "$3" --argjson g "$generations" \
      --arg c "$constraints" --arg p "$point" --arg t "$task" \
      '(.task_file | sub(".*/"; "") | sub("\\.toml$"; "")) == $t and .options.strategy == $s and .options.seed == $seed and .options.max_generations == $g and .options.variations == 4 and .options.constraints == $c and .options.point == $p' \
      "$1/run.json" >/dev/null 2>&1
}

runs=()
for strategy in $strategies; do
  for seed in $seeds; do
    dir="$out/$strategy-$seed"
    runs+=("$dir")
    if same_run "$dir" "$strategy" "$seed" && [ -f "$dir/summary.json" ]; then
      echo "$strategy seed $seed: finished earlier, kept"
    elif same_run "$dir" "$strategy" "$seed" && [ -f "$dir/checkpoint.json" ]; then
      echo "$strategy seed $seed: resuming"
      "$diverse" resume "$dir" --quiet
    else
      echo "$strategy seed $seed: running"
      "$diverse" run "$task" --n 4 --generations "$generations" --strategy "$strategy" \
        --seed "$seed" --constraints "$constraints" --point "$point" --out "$dir" --force --quiet
    fi
  done
done
"$diverse" report "${runs[@]}" | tee "$out/table.md"
echo
echo "paper: progressive Dmin 41.8, mean 54.4, Dmax 64.1; round-robin 71.2 / 83.5 / 103.7"
for strategy in $strategies; do
  awk -F'|' -v s="$strategy" '$5 ~ s { d = $9 + 0; n++; sum += d; if (n == 1 || d < lo) lo = d; if (n == 1 || d > hi) hi = d }
    END { printf "ours:  %-12s Dmin %.4g, mean %.4g, Dmax %.4g (%d runs)\n", s, lo, sum / n, hi, n }' "$out/table.md"
done
