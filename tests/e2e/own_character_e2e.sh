#!/usr/bin/env bash
# End to end with a character that is not the planar human: examples/own-character/
# (the tailwalker, a short-legged, long-armed biped with a tail, and its forward leap).
#
#   own_character_e2e.sh DIVERSE_BINARY SOURCE_DIR
#
# 1. `diverse simulate` of the committed input motion meets the task (C = 0).
# 2. `diverse run` with N = 2 for 2 generations writes summary.json, and every variation
#    meets the task (all_satisfied, every C = 0).
# E2E_KEEP=DIR keeps the outputs in DIR.
set -euo pipefail
command -v jq >/dev/null || { echo "FAILED: needs jq (scripts/setup.sh installs it)"; exit 1; }
diverse="$1"
src="$2"
task="$src/examples/own-character/leap.toml"

if [ -n "${E2E_KEEP:-}" ]; then
  work="$E2E_KEEP"
  rm -rf "$work/sim" "$work/run"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi

fail() {
  echo "FAILED: $*"
  exit 1
}

# 1. The committed M0 at the task's timestep.
"$diverse" simulate "$task" --out "$work/sim" >"$work/simulate.txt" 2>&1 ||
  { cat "$work/simulate.txt"; fail "diverse simulate $task"; }
cat "$work/simulate.txt"
grep -qx 'C = 0' "$work/simulate.txt" || fail "M0 of $task does not meet the task (expected the line 'C = 0')"
[ -s "$work/sim/motion.json" ] || fail "diverse simulate wrote no motion.json"

# 2. A short run: 2 variations, 2 generations.
"$diverse" run "$task" --n 2 --generations 2 --seed 1 --quiet --no-render --out "$work/run" ||
  fail "diverse run $task"
summary="$work/run/summary.json"
[ -s "$summary" ] || fail "no $summary"
jq -c '{all_satisfied, D, C: [.motions[].constraint]}' "$summary"
jq -e '.all_satisfied == true and (.motions | length) == 3 and all(.motions[]; .constraint == 0)' \
  "$summary" >/dev/null || fail "not every variation meets the task ($summary)"
echo "PASSED"
