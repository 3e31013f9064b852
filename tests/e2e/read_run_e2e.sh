#!/usr/bin/env bash
# examples/read_run.py on a short real run: it prints every motion's C and dmin, names the
# recorded states' columns from the model (the planar human's root slides and hinge first),
# plots a variation's joint angles into a PNG, and refuses an unknown joint in one line
# with exit code 2.
#
#   read_run_e2e.sh DIVERSE_BINARY SOURCE_DIR
#
# Exits 77 (CTest: skipped) when python3 lacks numpy or matplotlib (scripts/setup.sh
# installs python3-numpy and python3-matplotlib).
set -euo pipefail
diverse="$1"
src="$2"
# The first python3 on PATH with numpy and matplotlib; Debian's packages are those of
# /usr/bin/python3, which another python3 (a virtual environment, pyenv) may shadow.
python=""
for candidate in python3 /usr/bin/python3; do
  if command -v "$candidate" >/dev/null && "$candidate" -c 'import numpy, matplotlib' 2>/dev/null; then
    python="$candidate"
    break
  fi
done
if [ -z "$python" ]; then
  echo "SKIPPED: python3 with numpy and matplotlib is not installed (scripts/setup.sh installs them)"
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
