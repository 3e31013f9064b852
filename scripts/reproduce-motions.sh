#!/usr/bin/env bash
# Paper figure 5 (2D rows): N = 4 diverse variations for each of the five 2D tasks with
# the paper's metric, then a table of the results (docs/results.md has the last one).
# A task whose input motion (its m0 file) does not exist yet is left out, with a note.
#   scripts/reproduce-motions.sh [GENERATIONS] [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
generations="${1:-500}"
out="${2:-$here/runs/fig5}"
diverse="$here/build/diverse"
[ -x "$diverse" ] || { echo "reproduce-motions.sh: $diverse is not built (scripts/build.sh)" >&2; exit 2; }
runs=()
for task in backflip jump_forward jump_onto jump_over jump_high; do
  m0="$(sed -n 's/^m0 *= *"\(.*\)"/\1/p' "$here/tasks/$task.toml")"
  if [ ! -f "$here/tasks/$m0" ]; then
    echo "reproduce-motions.sh: $task left out: tasks/$m0 does not exist yet (diverse seed-motion $task)" >&2
    continue
  fi
  "$diverse" run "$task" --n 4 --generations "$generations" --seed 1 --out "$out/$task" --force
  runs+=("$out/$task")
done
"$diverse" report "${runs[@]}" | tee "$out/table.md"
