#!/usr/bin/env bash
# Kills a short run with SIGKILL at TRIALS points and resumes each: every resumed run must
# end with the summary.json of the uninterrupted run (the "timing" object aside).
#
#   scripts/kill-resume.sh [TRIALS] [OUT]        (defaults: 20, runs/kill-resume)
#
# The run: jump_high, N = 2, 8 samples per variation per generation, 8 generations, a
# checkpoint after every generation, one thread. The kill points cycle through three kinds:
#   random      a uniformly random moment of the run (start-up, rollouts, checkpoints, the
#               outputs at the end)
#   mid-write   while a checkpoint is being written (its temporary file exists)
#   boundary    as soon as the checkpoint of generation g (random) is in place
# Every third trial also kills the first resume at a random moment and resumes again.
# Needs jq. Prints one line per trial and a total; exits non-zero if any summary differs.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
diverse="${DIVERSE:-$here/build/diverse}"
trials="${1:-20}"
out="${2:-runs/kill-resume}"
generations=8
args=(run "$here/tasks/jump_high.toml" --n 2 --popsize 8 --sigma0 0.03 --generations "$generations"
      --seed 3 --threads 1 --checkpoint-seconds 0 --quiet --no-render)
command -v jq >/dev/null || { echo "kill-resume.sh: needs jq (scripts/setup.sh installs it)" >&2; exit 2; }
rm -rf "$out"
mkdir -p "$out"

start=$(date +%s%N)
"$diverse" "${args[@]}" --out "$out/reference"
duration_ms=$((($(date +%s%N) - start) / 1000000))
reference=$(jq -S 'del(.timing)' "$out/reference/summary.json")
echo "reference run: $duration_ms ms"
# A random moment of the run, in seconds for sleep.
random_moment() { awk -v ms="$duration_ms" -v r=$((RANDOM % 1000)) 'BEGIN { printf "%.3f", ms * r / 1000000 }'; }

# The generation of DIR's checkpoint, or -1.
generation() { jq -e '.optimizer.generation' "$1/checkpoint.json" 2>/dev/null || echo -1; }

RANDOM=7
failures=0
for ((i = 1; i <= trials; ++i)); do
  dir="$out/trial-$i"
  kinds=(random mid-write boundary)
  kind=${kinds[$(((i - 1) % 3))]}
  target=$((1 + RANDOM % (generations - 1)))
  "$diverse" "${args[@]}" --out "$dir" &
  pid=$!
  case $kind in
    random)
      sleep "$(random_moment)";;
    mid-write)
      until (($(generation "$dir") >= target - 1)) || ! kill -0 $pid 2>/dev/null; do sleep 0.005; done
      until compgen -G "$dir/checkpoint.json.tmp.*" >/dev/null || ! kill -0 $pid 2>/dev/null; do :; done;;
    boundary)
      until (($(generation "$dir") >= target)) || ! kill -0 $pid 2>/dev/null; do sleep 0.002; done;;
  esac
  kill -9 $pid 2>/dev/null || true
  wait $pid 2>/dev/null || true
  at="generation $(generation "$dir")"
  [ -f "$dir/summary.json" ] && at="after the summary"
  [ -f "$dir/run.json" ] || at="before run.json"
  tmp=$(compgen -G "$dir/checkpoint.json.tmp.*" >/dev/null && echo ", temporary left" || true)
  if [ ! -f "$dir/run.json" ]; then
    # Killed before the run existed on disk: nothing to resume; the user starts it again.
    "$diverse" "${args[@]}" --out "$dir" --force
  else
    if ((i % 3 == 0)); then
      "$diverse" resume "$dir" --quiet --no-render --threads 2 &
      rpid=$!
      sleep "$(random_moment)"
      kill -9 $rpid 2>/dev/null || true
      wait $rpid 2>/dev/null || true
      at="$at, resume killed at generation $(generation "$dir")"
    fi
    "$diverse" resume "$dir" --quiet --no-render --threads 2
  fi
  if [ "$(jq -S 'del(.timing)' "$dir/summary.json")" == "$reference" ]; then
    echo "trial $i ($kind): killed at $at$tmp: resumed summary identical"
  else
    echo "trial $i ($kind): killed at $at$tmp: resumed summary DIFFERS"
    failures=$((failures + 1))
  fi
done
echo "$((trials - failures)) of $trials kill points resumed to the identical summary"
((failures == 0))
