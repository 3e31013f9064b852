#!/usr/bin/env bash
# End-to-end test of `diverse gallery` and `diverse export --bvh` in headless Chromium:
# makes a short real run, its gallery page and BVH files, then runs
# web/test/gallery.e2e.mjs on them (no network: the page must work from disk).
#
#   gallery_e2e.sh DIVERSE_BINARY SOURCE_DIR
#
# Exits 77 (CTest: skipped) only when node or Chromium is not installed; scripts/setup.sh
# installs both. E2E_KEEP=DIR keeps the run (with gallery-screenshot.png) in DIR.
set -euo pipefail
diverse="$1"
src="$2"
chromium="${CHROMIUM:-/usr/bin/chromium}"
if ! command -v node >/dev/null; then
  echo "SKIPPED: node is not installed (scripts/setup.sh installs nodejs and npm)"
  exit 77
fi
if [ ! -x "$chromium" ]; then
  echo "SKIPPED: $chromium is not installed (scripts/setup.sh installs chromium)"
  exit 77
fi
if [ ! -d "$src/web/node_modules/playwright-core" ] || [ ! -d "$src/web/node_modules/three" ]; then
  echo "FAILED: $src/web/node_modules is missing: run \`npm ci\` in $src/web (scripts/build.sh does)"
  exit 1
fi

if [ -n "${E2E_KEEP:-}" ]; then
  work="$E2E_KEEP"
  rm -rf "$work/run"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
# Short but real: 2 variations, 3 generations of 8 samples.
"$diverse" run "$src/tasks/jump_high.toml" --n 2 --generations 3 --popsize 8 --sigma0 0.03 --seed 5 \
  --quiet --no-render --out "$work/run"
"$diverse" gallery "$work/run"
"$diverse" export "$work/run" --bvh
CHROMIUM="$chromium" node "$src/web/test/gallery.e2e.mjs" "$work/run"
