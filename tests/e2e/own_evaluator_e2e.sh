#!/usr/bin/env bash
# The installed library from another project (examples/own-evaluator, docs/guide/library.md):
# `cmake --install` into a temporary prefix, a standalone CMake project that finds it with
# find_package(diverse) and links diverse::core, built and run: its own DiversityProblem
# (a two-link arm) optimized into 3 variations that all meet its task.
#
#   own_evaluator_e2e.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1"
src="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
for f in lib/libdiverse_core.a include/diverse/optimize/diversity.h include/diverse/optimize/cmaes.h \
         include/diverse/metric/metric.h include/diverse/run/run.h include/diverse/params/parameters.h \
         include/diverse/finished/run_view.h include/diverse/finished/run_problem.h lib/cmake/diverse/diverseConfig.cmake \
         bin/diverse; do
  [ -e "$work/prefix/$f" ] || { echo "FAIL - installed $f"; exit 1; }
done
echo "ok - cmake --install writes the library, its headers, the package config and the tool"
if [ -f "$build/web/gallery-template.html" ]; then
  # The installed tool uses the page installed beside it: marked here, it shows in a gallery.
  page="$work/prefix/share/diverse/gallery-template.html"
  [ -f "$page" ] || { echo "FAIL - installed the gallery page"; exit 1; }
  echo "<!-- the installed page -->" >>"$page"
  "$work/prefix/bin/diverse" run "$src/tasks/jump_high.toml" --n 1 --generations 1 --popsize 4 --seed 2 \
    --quiet --no-render --out "$work/run" >/dev/null
  DIVERSE_GALLERY_TEMPLATE= "$work/prefix/bin/diverse" gallery "$work/run" --no-paths >/dev/null
  grep -q "<!-- the installed page -->" "$work/run/gallery.html" ||
    { echo "FAIL - the installed tool's gallery uses the installed page"; exit 1; }
  echo "ok - the installed tool makes galleries with the page installed beside it"
fi
cmake -S "$src/examples/own-evaluator" -B "$work/swing" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/swing" -j2 >/dev/null
echo "ok - a project of its own builds against find_package(diverse) and diverse::core"
out="$("$work/swing/swing_variations" 3 30 1)"
echo "$out"
grep -q '^M0: C = 0 ' <<<"$out" || { echo "FAIL - the reference swing meets the task"; exit 1; }
grep -q '^3 of 3 variations meet the task$' <<<"$out" || { echo "FAIL - every variation meets the task"; exit 1; }
echo "ok - the optimizer finds 3 swings that meet the task"
