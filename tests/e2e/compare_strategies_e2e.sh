#!/usr/bin/env bash
# scripts/compare-strategies.sh end to end at 2 generations per run: the ten runs and
# the table; started again, it keeps the finished runs and resumes an interrupted one
# (its summary removed, its checkpoint kept) to the same table, whatever else the output
# folder holds; SEEDS picks seeds; another budget or the paper's variant of the optimizer
# runs afresh.
#
#   compare_strategies_e2e.sh DIVERSE_BINARY SOURCE_DIR
set -euo pipefail
# The script's mechanics do not depend on the task: the high jump's rollouts are the
# cheapest (the backflip runs at 1 ms).
export TASK=jump_high
diverse="$1"
src="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAILED: $*"; exit 1; }

DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 2 "$work/out" > "$work/first.txt"
[ "$(grep -c ': running$' "$work/first.txt")" = 10 ] || fail "expected 10 fresh runs: $(cat "$work/first.txt")"
grep -q '^ours:  round-robin  Dmin .* (5 runs)$' "$work/first.txt" || fail "no round-robin line"
grep -q '^ours:  progressive  Dmin .* (5 runs)$' "$work/first.txt" || fail "no progressive line"
cp "$work/out/table.md" "$work/table-first.md"

rm "$work/out/progressive-3/summary.json"
# Other files beside the run directories (a log kept next to them) are not runs.
echo "log" > "$work/out/round-robin-1.log"
DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 2 "$work/out" > "$work/second.txt"
[ "$(grep -c ': finished earlier, kept$' "$work/second.txt")" = 9 ] || fail "expected 9 kept runs: $(cat "$work/second.txt")"
grep -q '^progressive seed 3: resuming$' "$work/second.txt" || fail "progressive seed 3 was not resumed"
# The same figures (the minutes column may differ).
cut -d'|' -f2-7,9- "$work/table-first.md" > "$work/a"
cut -d'|' -f2-7,9- "$work/out/table.md" > "$work/b"
diff "$work/a" "$work/b" || fail "the table changed after resuming"

# SEEDS picks seeds: their runs are kept and the table has only them.
SEEDS="2 4" DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 2 "$work/out" > "$work/seeds.txt"
[ "$(grep -c ': finished earlier, kept$' "$work/seeds.txt")" = 4 ] || fail "expected 4 kept runs for SEEDS: $(cat "$work/seeds.txt")"
grep -q '^ours:  round-robin  Dmin .* (2 runs)$' "$work/seeds.txt" || fail "SEEDS did not pick two round-robin runs"
grep -q '^round-robin seed 3' "$work/seeds.txt" && fail "SEEDS=\"2 4\" ran seed 3"
for bad in "x" "1,2" " "; do
  if SEEDS="$bad" DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 2 "$work/out" 2> "$work/err.txt" >/dev/null; then
    fail "SEEDS='$bad' was accepted"
  fi
  grep -q "compare-strategies.sh: SEEDS: expected" "$work/err.txt" || fail "unclear SEEDS error: $(cat "$work/err.txt")"
done

# Another budget is another experiment: runs of 2 generations are not kept for 3.
DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 3 "$work/out" > "$work/third.txt"
[ "$(grep -c ': running$' "$work/third.txt")" = 10 ] || fail "expected 10 fresh runs at 3 generations"
# So is the paper's variant of the optimizer: every run again, with its options.
DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 3 "$work/out" paper > "$work/fourth.txt"
[ "$(grep -c ': running$' "$work/fourth.txt")" = 10 ] || fail "expected 10 fresh runs for the paper variant"
jq -e '.options.constraints == "penalty" and .options.point == "mean"' "$work/out/progressive-2/run.json" >/dev/null ||
  fail "the paper variant did not run with --constraints penalty --point mean"
if DIVERSE="$diverse" bash "$src/scripts/compare-strategies.sh" 3 "$work/out" literal 2> "$work/err.txt"; then
  fail "an unknown variant was accepted"
fi
grep -q "VARIANT: expected ours or paper, got 'literal'" "$work/err.txt" || fail "unclear error: $(cat "$work/err.txt")"
echo "compare-strategies.sh: fresh, kept, resumed and re-run as expected"
