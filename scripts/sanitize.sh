#!/usr/bin/env bash
# Builds diverse with GCC's AddressSanitizer and UndefinedBehaviorSanitizer
# (-DDIVERSE_SANITIZE=ON) into ./build-asan, or the directory given, and runs the whole
# test suite under them, the end-to-end tests included (docs/reference/reliability.md,
# "Sanitizers").
#
#   scripts/sanitize.sh [BUILD_DIR] [CTEST_ARGS...]     e.g. scripts/sanitize.sh -R Rollout
#
# JOBS sets the parallel jobs of the build and of ctest (default: the number of cores).
# Every program of the project that the tests start, the `diverse` tool included, runs
# instrumented:
# AddressSanitizer and LeakSanitizer reports go to BUILD_DIR/sanitizer-reports/ (stderr
# of a tool run by a test is often discarded), UndefinedBehaviorSanitizer reports to the
# process's stderr, and any report stops the process with a failing exit code. The script
# fails if a test fails or any report was written, and prints the reports and the figures.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$here/build-asan"
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  build="$1"
  shift
fi
jobs="${JOBS:-$(nproc)}"

cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDIVERSE_SANITIZE=ON \
  -DDIVERSE_BUILD_FUZZ=OFF -DDIVERSE_BUILD_BENCH=OFF >/dev/null
build_start=$(date +%s)
cmake --build "$build" -j "$jobs"
build_seconds=$(( $(date +%s) - build_start ))

reports="$build/sanitizer-reports"
rm -rf "$reports"
mkdir -p "$reports"
# Leaks inside the uninstrumented system libraries (Mesa's llvmpipe) are suppressed, and
# only those: scripts/lsan-suppressions.txt says which and why.
export ASAN_OPTIONS="log_path=$reports/asan:detect_leaks=1:check_initialization_order=1:strict_init_order=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$here/scripts/lsan-suppressions.txt:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

test_start=$(date +%s)
status=0
ctest --test-dir "$build" -j "$jobs" --output-on-failure "$@" || status=$?
test_seconds=$(( $(date +%s) - test_start ))

log="$build/Testing/Temporary/LastTest.log"
ubsan=$(grep -c 'runtime error:' "$log" 2>/dev/null || true)
found=0
for f in "$reports"/asan.*; do
  [ -e "$f" ] || continue
  found=$((found + 1))
  echo "==== $f"
  cat "$f"
done
if [ "${ubsan:-0}" -gt 0 ]; then
  echo "==== UndefinedBehaviorSanitizer ($log)"
  grep -A12 'runtime error:' "$log"
fi
echo "sanitize.sh: build ${build_seconds} s, tests ${test_seconds} s (${jobs} jobs);" \
     "AddressSanitizer/LeakSanitizer reports: ${found}, UndefinedBehaviorSanitizer reports: ${ubsan:-0}"
if [ "$status" -ne 0 ] || [ "$found" -gt 0 ] || [ "${ubsan:-0}" -gt 0 ]; then
  exit 1
fi
