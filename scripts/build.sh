#!/usr/bin/env bash
# Configures and builds diverse (Release) into ./build, or into the directory given.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
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
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)"
