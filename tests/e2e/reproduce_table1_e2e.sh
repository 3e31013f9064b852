#!/usr/bin/env bash
# scripts/reproduce-table1.sh end to end at 1 generation per run, the forward jump's rows
# only (TASKS): six runs and the table; started again it keeps the finished runs and
# resumes an interrupted one (its summary removed, its checkpoint kept) to the same table;
# another budget runs afresh; an unknown task is refused with one line and exit 2.
#
#   reproduce_table1_e2e.sh DIVERSE_BINARY SOURCE_DIR
set -euo pipefail
diverse="$1"
src="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAILED: $*"; exit 1; }
table1() { TASKS=jump_forward bash "$src/scripts/reproduce-table1.sh" --diverse "$diverse" --threads 2 --out "$work/out" "$@"; }

table1 --generations 1 2> "$work/first.txt" >/dev/null
[ "$(grep -c -- '-> ' "$work/first.txt")" = 6 ] || fail "expected 6 fresh runs: $(cat "$work/first.txt")"
grep -q '^| jump_forward | md |' "$work/out/table1.md" || fail "no md row: $(cat "$work/out/table1.md")"
grep -q '^| jump_forward | shape |' "$work/out/table1.md" || fail "no shape row"
grep -q '^| backflip' "$work/out/table1.md" && fail "TASKS=jump_forward tabled the backflip"
cp "$work/out/table1.md" "$work/table-first.md"

rm "$work/out/jump_forward-shape-2/summary.json"
[ -f "$work/out/jump_forward-shape-2/checkpoint.json" ] || fail "a finished run keeps no checkpoint"
table1 --generations 1 2> "$work/second.txt" >/dev/null
[ "$(grep -c ': finished earlier, kept' "$work/second.txt")" = 5 ] || fail "expected 5 kept runs: $(cat "$work/second.txt")"
grep -q '^jump_forward, objective shape, seed 2: resuming' "$work/second.txt" || fail "shape seed 2 was not resumed"
# The same figures (the line with the minutes may differ).
grep '^|' "$work/table-first.md" > "$work/a"
grep '^|' "$work/out/table1.md" > "$work/b"
diff "$work/a" "$work/b" || fail "the table changed after resuming"

# Another budget is another experiment.
table1 --generations 2 2> "$work/third.txt" >/dev/null
[ "$(grep -c -- '-> ' "$work/third.txt")" = 6 ] || fail "expected 6 fresh runs at 2 generations"

if TASKS=walk bash "$src/scripts/reproduce-table1.sh" --diverse "$diverse" --out "$work/out" 2> "$work/err.txt"; then
  fail "TASKS=walk was accepted"
fi
[ "$(wc -l < "$work/err.txt")" = 1 ] || fail "more than one line: $(cat "$work/err.txt")"
grep -q "reproduce-table1.sh: TASKS: expected jump_forward and/or backflip, got 'walk'" "$work/err.txt" ||
  fail "unclear error: $(cat "$work/err.txt")"
echo "reproduce-table1.sh: fresh, kept, resumed and re-run as expected"
