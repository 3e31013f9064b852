#!/usr/bin/env bash
# The Python module's examples (docs/guide/python.md) run as a user runs them:
# examples/sweep_parameter.py sweeps a parameter of the input motion and plots it, and
# examples/python_metric_search.py drives a small run with a Python distance to variations
# that meet the task; both refuse a bad argument in one line with exit code 2.
#
#   python_examples_e2e.sh DIVERSE_BINARY SOURCE_DIR
#
# Exits 77 (CTest: skipped) when /usr/bin/python3 lacks numpy, matplotlib or the module.
set -euo pipefail
diverse="$1"
src="$2"
export PYTHONPATH="$(cd "$(dirname "$diverse")" && pwd)/python${PYTHONPATH:+:$PYTHONPATH}"
python=/usr/bin/python3
if ! "$python" -c 'import numpy, matplotlib, diverse' 2>/dev/null; then
  echo "SKIPPED: /usr/bin/python3 lacks numpy, matplotlib or the module diverse (scripts/setup.sh, then the build)"
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail=0
check() { if grep -qE "$1" <<<"$2"; then echo "ok - $3"; else echo "FAIL - $3"; fail=1; fi; }

out="$("$python" "$src/examples/sweep_parameter.py" jump_high --parameter start.knee --steps 9 --out "$work/sweep.png")"
echo "$out"
check '^jump_high: start.knee from -2.6 to 0 \(M0 -0.1138\), [1-8] of 9 motions meet the task$' "$out" \
  'the sweep names the parameter and its range, and some motions meet the task but not all'
check '^ +0 peak +1\.[0-9]+ m' "$out" 'the upper end of the range jumps'
check 'sweep.png +\(9 motions\)' "$out" 'the plot is written'
[ "$(head -c 8 "$work/sweep.png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] && echo "ok - a PNG" || { echo "FAIL - a PNG"; fail=1; }

out="$("$python" "$src/examples/python_metric_search.py" --out "$work/run" --generations 2 --seed 3)"
echo "$out"
check '^generation +2: D = ' "$out" 'the callback reports every generation'
check '^jump_high: D = [0-9.e+]+ under python: limbs_apart, all meet the task: True$' "$out" \
  'the run is under the Python distance and every variation meets the task'
check '^ +M4 +C 0 ' "$out" 'four variations'

set +e
err="$("$python" "$src/examples/sweep_parameter.py" jump_high --parameter nope 2>&1 >/dev/null)"
code=$?
set -e
if [ "$code" = 2 ] && grep -q '^sweep_parameter.py: --parameter: expected a parameter of jump_high' <<<"$err"; then
  echo "ok - an unknown parameter is one line, exit 2"
else
  echo "FAIL - an unknown parameter is one line, exit 2 (got $code: $err)"; fail=1
fi
exit $fail
