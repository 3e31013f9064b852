#!/usr/bin/env bash
# examples/read_run.py (the module diverse) on a short real run: it prints every motion's
# C and dmin, names the recorded states' columns from the model (the planar human's root
# slides and hinge first), plots a variation's joint angles into a PNG, and refuses an
# unknown joint in one line with exit code 2.
#
#   read_run_e2e.sh DIVERSE_BINARY SOURCE_DIR
#
# Exits 77 (CTest: skipped) when no python3 has numpy, matplotlib and the module diverse
# built beside DIVERSE_BINARY (scripts/setup.sh installs python3-numpy, python3-matplotlib
# and pybind11; the build makes BUILD/python/diverse for /usr/bin/python3).
set -euo pipefail
diverse="$1"
src="$2"
export PYTHONPATH="$(cd "$(dirname "$diverse")" && pwd)/python${PYTHONPATH:+:$PYTHONPATH}"
# Debian's python3 first: the module is built for it, and another python3 on the PATH (a
# virtual environment, pyenv) may shadow it.
python=""
for candidate in /usr/bin/python3 python3; do
  if command -v "$candidate" >/dev/null && "$candidate" -c 'import numpy, matplotlib, diverse' 2>/dev/null; then
    python="$candidate"
    break
  fi
done
if [ -z "$python" ]; then
  echo "SKIPPED: no python3 with numpy, matplotlib and the module diverse (scripts/setup.sh, then the build)"
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$diverse" run "$src/tasks/jump_high.toml" --n 2 --generations 2 --popsize 8 --sigma0 0.03 --seed 3 \
  --quiet --no-render --out "$work/run"
out="$("$python" "$src/examples/read_run.py" "$work/run" --variation 2 --columns --out "$work/m2.png")"
echo "$out"
fail=0
expect() { if grep -qE "$1" <<<"$out"; then echo "ok - $2"; else echo "FAIL - $2"; fail=1; fi; }
expect '^jump_high: 3 motions, metric md' 'the summary line names the task, the motions and the metric'
expect '^ +M0 +0 ' 'M0 meets the task (C = 0)'
expect '^ +M2 ' 'every motion has a line'
expect '^column +0 slide +rootx$' 'qpos column 0 is the root slide x'
expect '^column +2 hinge +rooty$' 'qpos column 2 is the root pitch'
expect '^column +[0-9]+ hinge +knee_l$' 'the knee is a hinge column'
expect 'm2.png +\(3 joints, [0-9]+ states' 'the plot has the left leg joints'
if [ "$(head -c 8 "$work/m2.png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]; then
  echo "ok - the plot is a PNG"
else
  echo "FAIL - the plot is a PNG"; fail=1
fi
set +e
err="$("$python" "$src/examples/read_run.py" "$work/run" --joints elbow_x 2>&1 >/dev/null)"
code=$?
set -e
if [ "$code" = 2 ] && grep -q '^read_run.py: --joints: elbow_x: not hinge joints of m1.xml' <<<"$err"; then
  echo "ok - an unknown joint is one line, exit 2"
else
  echo "FAIL - an unknown joint is one line, exit 2 (got $code: $err)"; fail=1
fi
exit $fail
