#!/usr/bin/env bash
# The skills added by files alone (skills/hop.toml, skills/split_leap.toml,
# skills/tuck_jump.toml on the tailwalker, skills/star_jump.toml on the 3D human,
# skills/robot_tuck_hop.toml on the bird robot), end to end at a small budget:
#
#   new_skills_e2e.sh DIVERSE_BINARY SOURCE_DIR [TASK ...]
#
# For each task: its skill binds to its character (`diverse skill check`), its committed
# input motion meets it (C = 0), a run of N = 2 for 2 generations returns variations that
# all meet it, and every motion of the run replays exactly in plain MuJoCo with no net
# torque over a limit (`diverse replay`).
# E2E_KEEP=DIR keeps the outputs in DIR.
set -euo pipefail
command -v jq >/dev/null || { echo "FAILED: needs jq (scripts/setup.sh installs it)"; exit 1; }
diverse="$1"
src="$2"
shift 2
tasks=("$@")
[ "${#tasks[@]}" -gt 0 ] || tasks=(hop split_leap tailwalker_tuck_jump star_jump robot_tuck_hop)

if [ -n "${E2E_KEEP:-}" ]; then
  work="$E2E_KEEP"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
fail() {
  echo "FAILED: $*"
  exit 1
}

for name in "${tasks[@]}"; do
  task="$src/tasks/$name.toml"
  out="$work/$name"
  rm -rf "$out"
  mkdir -p "$out"
  skill="$src/tasks/$(sed -n 's/^skill = "\(.*\)".*/\1/p' "$task")"
  character="$src/tasks/$(sed -n 's/^character = "\(.*\)".*/\1/p' "$task")"
  "$diverse" skill check "$skill" --character "$character" || fail "$name: skill check $skill"

  "$diverse" simulate "$task" --out "$out/sim" --no-film >"$out/simulate.txt" 2>&1 ||
    { cat "$out/simulate.txt"; fail "$name: simulate"; }
  grep -qx 'C = 0' "$out/simulate.txt" || { cat "$out/simulate.txt"; fail "$name: M0 does not meet the task"; }

  "$diverse" run "$task" --n 2 --generations 2 --seed 1 --quiet --no-render --out "$out/run" ||
    fail "$name: diverse run"
  summary="$out/run/summary.json"
  echo "$name: $(jq -c '{all_satisfied, D, C: [.motions[].constraint]}' "$summary")"
  jq -e '.all_satisfied == true and (.motions | length) == 3 and all(.motions[]; .constraint == 0)' \
    "$summary" >/dev/null || fail "$name: not every variation meets the task ($summary)"
  for i in 0 1 2; do
    "$diverse" replay "$out/run/motions/m$i.json" >"$out/replay$i.txt" || fail "$name: replay m$i"
    grep -q 'max |qpos difference| = 0$' "$out/replay$i.txt" || { cat "$out/replay$i.txt"; fail "$name: m$i does not replay exactly"; }
    grep -q 'worst excess over the limit +0 %' "$out/replay$i.txt" || { cat "$out/replay$i.txt"; fail "$name: m$i over a torque limit"; }
  done
done
echo "PASSED"
