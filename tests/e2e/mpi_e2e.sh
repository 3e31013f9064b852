#!/usr/bin/env bash
# `mpirun -n 2 diverse run|resume` (src/distribute/cluster.h) against one process, on
# jump_high with N = 2, 8 samples per generation, one thread per rank:
#
#   mpi_e2e.sh DIVERSE_BINARY SOURCE_DIR MPIRUN
#
# 1. Two ranks give the summary.json of one process (the "timing" object aside), and
#    "timing" says 2 ranks; so does the simultaneous strategy.
# 2. A run of 2 ranks killed (rank 0, SIGKILL) after its checkpoint of generation 2 and
#    resumed by one process, and a run of one process killed the same way and resumed by 2
#    ranks, both end with the uninterrupted run's summary.
# 3. A worker rank killed (SIGKILL) mid-run: rank 0 prints one line naming what happened
#    and `diverse resume DIR`, exits 2 (mpirun reports the killed rank's status), and the
#    checkpoint left behind resumes, under 2 ranks, to the uninterrupted run's summary.
# 4. A worker rank stopped (SIGSTOP: alive to mpirun, silent to rank 0, as a hung rank or
#    a lost node): after --rank-timeout rank 0 prints one line naming the rank, mpirun
#    exits 2, nothing is left running, and the checkpoint resumes to the same summary.
# E2E_KEEP=DIR keeps the outputs in DIR.
set -uo pipefail
command -v jq >/dev/null || { echo "FAILED: needs jq (scripts/setup.sh installs it)"; exit 1; }
diverse="$1"
src="$2"
mpirun="$3"
task="$src/tasks/jump_high.toml"

if [ -n "${E2E_KEEP:-}" ]; then
  work="$E2E_KEEP"
  rm -rf "$work"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
# Root may start ranks only when it says so; two ranks on this machine whatever its cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpi=("$mpirun" -n 2 --oversubscribe)

fail() {
  echo "FAILED: $*"
  exit 1
}
summary() { jq -S 'del(.timing)' "$1/summary.json"; }
generation() { jq -e '.optimizer.generation' "$1/checkpoint.json" 2>/dev/null || echo -1; }
# The pid of rank R among the processes mpirun (pid $1) started.
rank_pid() {
  for p in $(pgrep -P "$1"); do
    if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$2"; then
      echo "$p"
      return 0
    fi
  done
  return 1
}
# Waits until DIR's checkpoint has reached generation G (or PID has ended).
wait_generation() {
  local dir="$1" g="$2" pid="$3"
  for _ in $(seq 1 3000); do
    [ "$(generation "$dir")" -ge "$g" ] && return 0
    kill -0 "$pid" 2>/dev/null || return 1
    sleep 0.01
  done
  return 1
}

args=(--n 2 --popsize 8 --sigma0 0.03 --seed 3 --threads 1 --quiet --no-render)

# 1. Same summary from one process and from two ranks (3 generations).
"$diverse" run "$task" "${args[@]}" --generations 3 --out "$work/one" || fail "diverse run (one process)"
"${mpi[@]}" "$diverse" run "$task" "${args[@]}" --generations 3 --out "$work/two" >"$work/two.txt" 2>&1 ||
  { cat "$work/two.txt"; fail "mpirun -n 2 diverse run"; }
[ "$(summary "$work/one")" == "$(summary "$work/two")" ] ||
  { diff <(summary "$work/one") <(summary "$work/two") | head -20; fail "2 ranks: summary.json differs from one process's"; }
[ "$(jq '.timing.ranks' "$work/two/summary.json")" == 2 ] || fail "2 ranks: timing.ranks is not 2"
[ "$(jq '.timing.ranks' "$work/one/summary.json")" == 1 ] || fail "one process: timing.ranks is not 1"
echo "ok: 2 ranks = 1 process"

# 1b. The simultaneous strategy (one batch of N x lambda per generation) under 2 ranks.
sim=("${args[@]}" --generations 2 --strategy simultaneous)
"$diverse" run "$task" "${sim[@]}" --out "$work/sim1" || fail "diverse run --strategy simultaneous (one process)"
"${mpi[@]}" "$diverse" run "$task" "${sim[@]}" --out "$work/sim2" >"$work/sim2.txt" 2>&1 ||
  { cat "$work/sim2.txt"; fail "mpirun -n 2 diverse run --strategy simultaneous"; }
[ "$(summary "$work/sim1")" == "$(summary "$work/sim2")" ] ||
  { diff <(summary "$work/sim1") <(summary "$work/sim2") | head -20; fail "simultaneous, 2 ranks: summary.json differs from one process's"; }
echo "ok: simultaneous, 2 ranks = 1 process"

# The uninterrupted run the interrupted ones must end with (6 generations, a checkpoint
# after every generation).
long=("${args[@]}" --generations 6 --checkpoint-seconds 0)
"$diverse" run "$task" "${long[@]}" --out "$work/reference" || fail "diverse run (reference)"
reference="$(summary "$work/reference")"

# 2a. Two ranks, rank 0 killed, resumed by one process.
"${mpi[@]}" "$diverse" run "$task" "${long[@]}" --out "$work/a" >"$work/a.txt" 2>&1 &
mpid=$!
wait_generation "$work/a" 2 "$mpid" || { cat "$work/a.txt"; fail "2a: the 2-rank run ended before generation 2"; }
kill -9 "$(rank_pid "$mpid" 0)" || fail "2a: no rank 0 to kill"
wait "$mpid"
[ -f "$work/a/summary.json" ] && fail "2a: the run finished before the kill"
"$diverse" resume "$work/a" --threads 1 --quiet --no-render || fail "2a: diverse resume (one process)"
[ "$(summary "$work/a")" == "$reference" ] || fail "2a: 2 ranks then 1 process: summary differs"
echo "ok: 2 ranks, killed, resumed by 1 process = uninterrupted"

# 2b. One process killed, resumed by two ranks.
"$diverse" run "$task" "${long[@]}" --out "$work/b" &
pid=$!
wait_generation "$work/b" 2 "$pid" || fail "2b: the run ended before generation 2"
kill -9 "$pid"
wait "$pid"
[ -f "$work/b/summary.json" ] && fail "2b: the run finished before the kill"
"${mpi[@]}" "$diverse" resume "$work/b" --threads 1 --quiet --no-render >"$work/b.txt" 2>&1 ||
  { cat "$work/b.txt"; fail "2b: mpirun -n 2 diverse resume"; }
[ "$(summary "$work/b")" == "$reference" ] || fail "2b: 1 process then 2 ranks: summary differs"
echo "ok: 1 process, killed, resumed by 2 ranks = uninterrupted"

# 3. A worker rank killed.
"${mpi[@]}" "$diverse" run "$task" "${long[@]}" --out "$work/c" >"$work/c.txt" 2>&1 &
mpid=$!
wait_generation "$work/c" 2 "$mpid" || { cat "$work/c.txt"; fail "3: the run ended before generation 2"; }
kill -9 "$(rank_pid "$mpid" 1)" || fail "3: no rank 1 to kill"
wait "$mpid"
status=$?
cat "$work/c.txt"
[ "$status" -ne 0 ] || fail "3: mpirun exited 0 after a worker was killed"
[ -f "$work/c/summary.json" ] && fail "3: the run finished before the kill"
lines="$(grep -c '^diverse: error: ' "$work/c.txt")"
[ "$lines" == 1 ] || fail "3: expected one 'diverse: error:' line, got $lines"
grep -q "^diverse: error: the run was stopped by mpirun (a rank ended.*; \`diverse resume $work/c\` continues from the last checkpoint (generation [0-9]*)$" \
  "$work/c.txt" || fail "3: the error line does not name what happened and how to resume"
"${mpi[@]}" "$diverse" resume "$work/c" --threads 1 --quiet --no-render >"$work/c2.txt" 2>&1 ||
  { cat "$work/c2.txt"; fail "3: mpirun -n 2 diverse resume after the killed worker"; }
[ "$(summary "$work/c")" == "$reference" ] || fail "3: resumed after a killed worker: summary differs"
echo "ok: killed worker: one line, resumable"

# 4. A worker rank stopped.
"${mpi[@]}" "$diverse" run "$task" "${long[@]}" --rank-timeout 2 --out "$work/d" >"$work/d.txt" 2>&1 &
mpid=$!
wait_generation "$work/d" 2 "$mpid" || { cat "$work/d.txt"; fail "4: the run ended before generation 2"; }
worker="$(rank_pid "$mpid" 1)" || fail "4: no rank 1 to stop"
kill -STOP "$worker"
# Generous: on a loaded machine the niced ranks may wait long for a core.
stopped_at=$SECONDS
while kill -0 "$mpid" 2>/dev/null && [ $((SECONDS - stopped_at)) -lt 120 ]; do sleep 0.2; done
if kill -0 "$mpid" 2>/dev/null; then
  cat "$work/d.txt"
  ps -o pid,stat,etime,args --ppid "$mpid" || true
  echo "checkpoint generation: $(generation "$work/d"); summary.json: $([ -f "$work/d/summary.json" ] && echo written || echo none)"
  # Where each rank is (gdb, where the machine lets it attach).
  for p in $(pgrep -P "$mpid"); do
    echo "== pid $p"
    timeout 30 gdb -p "$p" -batch -ex "thread apply all bt 12" 2>/dev/null | grep -E "^#|^Thread" | head -80 || true
  done
  kill -CONT "$worker"; kill -9 "$worker" "$mpid"
  fail "4: mpirun still runs 120 s after a worker was stopped (rank timeout 2 s)"
fi
wait "$mpid"
status=$?
cat "$work/d.txt"
[ "$status" == 2 ] || fail "4: mpirun exited $status after a worker stopped answering, expected 2"
for _ in $(seq 1 100); do kill -0 "$worker" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$worker" 2>/dev/null; then
  state="$(ps -o stat= -p "$worker")"
  kill -CONT "$worker"; kill -9 "$worker"
  fail "4: the stopped worker was left running (state $state) 10 s after mpirun ended"
fi
[ -f "$work/d/summary.json" ] && fail "4: the run finished before the stop"
lines="$(grep -c '^diverse: error: ' "$work/d.txt")"
[ "$lines" == 1 ] || fail "4: expected one 'diverse: error:' line, got $lines"
grep -q "^diverse: error: rank 1 ([^)]*) has not answered for 2 s while evaluating samples (.*--rank-timeout sets how long to wait); \`diverse resume $work/d\` continues from the last checkpoint (generation [0-9]*)$" \
  "$work/d.txt" || fail "4: the error line does not name the rank, the wait and how to resume"
"${mpi[@]}" "$diverse" resume "$work/d" --threads 1 --quiet --no-render >"$work/d2.txt" 2>&1 ||
  { cat "$work/d2.txt"; fail "4: mpirun -n 2 diverse resume after the stopped worker"; }
[ "$(summary "$work/d")" == "$reference" ] || fail "4: resumed after a stopped worker: summary differs"
echo "ok: stopped worker: one line after the rank timeout, mpirun exits 2, resumable"

echo "mpi_e2e: all passed"
