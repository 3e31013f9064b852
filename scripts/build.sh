#!/usr/bin/env bash
# Configures and builds diverse (Release).
#   ./scripts/build.sh [BUILD_DIR]          everything: the tool, tests, benchmarks, fuzz
#                                           targets and the gallery page (default ./build)
#   ./scripts/build.sh --tool [BUILD_DIR]   only the diverse tool (what the main job runs)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
mode=all
if [ "${1:-}" = --tool ]; then
  mode=tool
  shift
elif [ "${1:-}" != "" ] && [ "${1#-}" != "${1}" ]; then
  echo "build.sh: expected --tool or a build directory, got '$1'" >&2
  exit 2
fi
build="${1:-$here/build}"
if [ "$mode" = tool ]; then
  cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDIVERSE_BUILD_TESTS=OFF \
    -DDIVERSE_BUILD_BENCH=OFF -DDIVERSE_BUILD_FUZZ=OFF >/dev/null
  cmake --build "$build" -j "$(nproc)" --target diverse
  exit 0
fi
# The gallery page's npm dependencies (web/package-lock.json); the C++ build does not need
# them, so a missing npm or a failed download only leaves `diverse gallery` without its page.
if command -v npm >/dev/null; then
  lock="$here/web/node_modules/.package-lock.json"
  if [ ! -f "$lock" ] || [ "$here/web/package-lock.json" -nt "$lock" ]; then
    (cd "$here/web" && npm ci --no-audit --no-fund --loglevel=error) ||
      echo "build.sh: npm ci failed in web/: the gallery page is not built" >&2
  fi
else
  echo "build.sh: npm not found: the gallery page is not built (scripts/setup.sh installs it)" >&2
fi
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDIVERSE_BUILD_TESTS=ON \
  -DDIVERSE_BUILD_BENCH=ON -DDIVERSE_BUILD_FUZZ=ON >/dev/null
cmake --build "$build" -j "$(nproc)"
