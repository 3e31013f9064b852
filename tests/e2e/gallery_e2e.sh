#!/usr/bin/env bash
# End-to-end test of `diverse gallery` and `diverse export --bvh --gltf` in headless
# Chromium: makes a short real run (the planar human's high jump) with 12 blends (and a copy
# of it as a run made before runs ended with the robustness suite), a run of 3D motions
# (the 3D human pushed three ways under stance control, tests/support/stance_run.h) and a
# 3D walk that the views follow, their gallery pages, BVH and glTF files, then runs
# web/test/gallery.e2e.mjs on each (no network: the page must work from disk).
#
#   gallery_e2e.sh DIVERSE_BINARY SOURCE_DIR MAKE_STANCE_RUN_BINARY
#
# Exits 77 (CTest: skipped) only when node or Chromium is not installed; scripts/setup.sh
# installs both. E2E_KEEP=DIR keeps the run (with gallery-screenshot.png) in DIR.
set -euo pipefail
diverse="$1"
src="$2"
make_stance_run="$3"
chromium="${CHROMIUM:-/usr/bin/chromium}"
if ! command -v node >/dev/null; then
  echo "SKIPPED: node is not installed (scripts/setup.sh installs nodejs and npm)"
  exit 77
fi
if [ ! -x "$chromium" ]; then
  echo "SKIPPED: $chromium is not installed (scripts/setup.sh installs chromium)"
  exit 77
fi
if [ ! -d "$src/web/node_modules/playwright-core" ] || [ ! -d "$src/web/node_modules/three" ] ||
   [ ! -d "$src/web/node_modules/gltf-validator" ]; then
  echo "FAILED: $src/web/node_modules is missing: run \`npm ci\` in $src/web (scripts/build.sh does)"
  exit 1
fi

if [ -n "${E2E_KEEP:-}" ]; then
  work="$E2E_KEEP"
  rm -rf "$work/run" "$work/old" "$work/run3d" "$work/walk"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
# Short but real: 2 variations, 3 generations of 8 samples, from a small step (the high
# jump's feasible neighbourhood under the half-timestep check is thin), within bounds the
# page shows.
"$diverse" run "$src/tasks/jump_high.toml" --n 2 --generations 3 --popsize 8 --sigma0 0.01 --seed 5 \
  --effort-bound 3 --max-distance 1000 --quiet --no-render --out "$work/run"
"$diverse" blend "$work/run" --samples 12 --path-points 4
"$diverse" gallery "$work/run"
"$diverse" export "$work/run" --bvh --gltf
CHROMIUM="$chromium" node "$src/web/test/gallery.e2e.mjs" "$work/run"
# The fresh run ended with the robustness suite: its page carries every motion's shares.
grep -q '"robustness":{"motions":\[{"count":19' "$work/run/gallery.html" ||
  { echo "FAILED: the fresh run's gallery has no robustness shares"; exit 1; }

# A run made before runs ended with the robustness suite (no robustness.json, no
# "robustness" in summary.json) still renders, saying the suite was not run.
rm -rf "$work/old"
cp -r "$work/run" "$work/old"
rm -rf "$work/old/robustness.json" "$work/old/gallery.html" "$work/old/blend"
node -e 'const fs = require("fs"); const f = process.argv[1]; const s = JSON.parse(fs.readFileSync(f, "utf8"));
         delete s.robustness; fs.writeFileSync(f, JSON.stringify(s, null, 1));' "$work/old/summary.json"
"$diverse" gallery "$work/old" --no-paths
CHROMIUM="$chromium" node "$src/web/test/gallery.e2e.mjs" "$work/old"

# 3D: 1.2 s of the 3D human pushed forward, to its left and back-right.
"$make_stance_run" "$work/run3d" human3d 1.2 0.3,0 0,0.3 -0.2,-0.2
"$diverse" gallery "$work/run3d" --no-paths
"$diverse" export "$work/run3d" --bvh --gltf
CHROMIUM="$chromium" node "$src/web/test/gallery.e2e.mjs" "$work/run3d"

# A walker: 12 steps of the 3D human's SIMBICON walk (about 6 m), which the views follow.
"$make_stance_run" "$work/walk" human3d walk 12 silly_walk_start.json
"$diverse" gallery "$work/walk" --no-paths
"$diverse" export "$work/walk" --bvh --gltf
CHROMIUM="$chromium" node "$src/web/test/gallery.e2e.mjs" "$work/walk"
