#!/usr/bin/env bash
# The commands of docs/new-skill.md on examples/own-skill/ (a pike jump for the planar
# human, a skill added by files alone), at a small budget:
#
#   own_skill_e2e.sh DIVERSE_BINARY SOURCE_DIR
#
# 1. `diverse skill check` binds the skill to the planar human; a copy with a transition
#    to a phase that does not exist is refused in one line naming the file, the line and
#    the field, with exit code 2.
# 2. `diverse skill show` lists the pike's parameters with the ranges that keep its shape.
# 3. `diverse simulate` of the starting guess: it jumps and falls (C > 0), draws a film strip.
# 4. `diverse seed-motion` for 2 generations writes a parameter file with the pike's names.
# 5. `diverse simulate` of the committed input motion meets the task (C = 0).
# 6. `diverse run` with N = 2 for 2 generations: every variation meets the task, and a
#    variation replays exactly in plain MuJoCo (`diverse replay`).
# E2E_KEEP=DIR keeps the outputs in DIR.
set -euo pipefail
command -v jq >/dev/null || { echo "FAILED: needs jq (scripts/setup.sh installs it)"; exit 1; }
diverse="$1"
src="$2"
dir="$src/examples/own-skill"
task="$dir/pike.toml"
human="$src/assets/characters/human2d.toml"

if [ -n "${E2E_KEEP:-}" ]; then
  work="$E2E_KEEP"
  rm -rf "$work"/*
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
fail() {
  echo "FAILED: $*"
  exit 1
}

# 1. check, and a broken copy refused
"$diverse" skill check "$dir/pike_jump.toml" --character "$human" >"$work/check.txt" 2>&1 ||
  { cat "$work/check.txt"; fail "skill check"; }
cat "$work/check.txt"
grep -q 'skill pike_jump binds to .*human2d.toml: 6 phases, 2 modules, 90 parameters' "$work/check.txt" ||
  fail "skill check did not bind the pike jump (6 phases, 2 modules, 90 parameters)"
sed 's/{ to = "fall", on = "peak" }/{ to = "falling", on = "peak" }/' "$dir/pike_jump.toml" >"$work/broken.toml"
set +e
"$diverse" skill check "$work/broken.toml" --character "$human" >"$work/broken.txt" 2>&1
rc=$?
set -e
cat "$work/broken.txt"
[ "$rc" -eq 2 ] || fail "a transition to a missing phase: exit code $rc, expected 2"
[ "$(wc -l <"$work/broken.txt")" -eq 1 ] || fail "a transition to a missing phase: expected one line"
grep -q "broken.toml: line [0-9]*: .*falling" "$work/broken.txt" || fail "the error does not name the file, the line and the missing phase"

# 2. show
"$diverse" skill show "$dir/pike_jump.toml" --character "$human" >"$work/show.txt" || fail "skill show"
grep -Eq '^ +rise\.pike_hip +\[1\.2, 2\.2\] rad' "$work/show.txt" || fail "skill show does not list rise.pike_hip in [1.2, 2.2]"
grep -Eq '^ +rise\.pike_knee +\[-0\.3, 0\] rad' "$work/show.txt" || fail "skill show does not list rise.pike_knee in [-0.3, 0]"

# 3. the starting guess
"$diverse" simulate "$task" --params "$dir/pike_start.json" --out "$work/start" >"$work/start.txt" 2>&1 ||
  { cat "$work/start.txt"; fail "simulate the starting guess"; }
grep -Eq '^C = [1-9]' "$work/start.txt" || fail "the starting guess meets the task already (expected C > 0)"
[ -s "$work/start/filmstrip.png" ] || fail "no film strip of the starting guess"

# 4. a short search
"$diverse" seed-motion "$task" --threads 1 --generations 2 --out "$work/m0.json" >"$work/seed.txt" 2>&1 ||
  { cat "$work/seed.txt"; fail "seed-motion"; }
jq -e '.parameters["rise.pike_hip"] >= 1.2 and .parameters["rise.pike_hip"] <= 2.2 and (.parameters | length) == 90' \
  "$work/m0.json" >/dev/null || fail "seed-motion wrote no pike parameters ($work/m0.json)"

# 5. the committed input motion
"$diverse" simulate "$task" --out "$work/sim" >"$work/simulate.txt" 2>&1 ||
  { cat "$work/simulate.txt"; fail "simulate $task"; }
grep -qx 'C = 0' "$work/simulate.txt" || { cat "$work/simulate.txt"; fail "M0 of $task does not meet the task"; }

# 6. a short run, and a replay
"$diverse" run "$task" --n 2 --generations 2 --seed 1 --quiet --no-render --out "$work/run" || fail "diverse run $task"
summary="$work/run/summary.json"
jq -c '{all_satisfied, D, C: [.motions[].constraint]}' "$summary"
jq -e '.all_satisfied == true and (.motions | length) == 3 and all(.motions[]; .constraint == 0)' \
  "$summary" >/dev/null || fail "not every variation meets the task ($summary)"
"$diverse" replay "$work/run/motions/m1.json" >"$work/replay.txt" || fail "replay"
cat "$work/replay.txt"
grep -q 'max |qpos difference| = 0$' "$work/replay.txt" || fail "m1 does not replay exactly"
echo "PASSED"
