#!/usr/bin/env bash
# scripts/check-layers.py: first on a small tree whose mismatches are known (an include of a
# folder the row does not list, a listed folder no file includes, a folder without a row, a
# row without a folder, a row that lists a folder below it), which it must name line by
# line; then on the repository's src/ and docs/architecture.md.
set -euo pipefail
source_dir=$1
checker=$source_dir/scripts/check-layers.py
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

mkdir -p "$scratch/docs" "$scratch/src/core" "$scratch/src/physics" "$scratch/src/render" \
  "$scratch/src/task" "$scratch/src/extra"
cat > "$scratch/docs/architecture.md" <<'PAGE'
# Architecture

| folder | what it holds | depends on |
|---|---|---|
| `core/` | errors | — |
| `physics/` | rollouts, `a | b` | core |
| `render/` | pictures | core, task |
| `task/` | tasks | core, physics |
| `gone/` | nothing now | core |
PAGE
printf '#pragma once\n#include <vector>\n' > "$scratch/src/core/error.h"
printf '#include "core/error.h"\n#include "physics/rollout.h"\n' > "$scratch/src/physics/rollout.cc"
printf '#pragma once\n' > "$scratch/src/physics/rollout.h"
printf '#include "task/task.h"\n' > "$scratch/src/render/image.cc"
printf '#pragma once\n#include "core/error.h"\n  #include "render/image.h"\n// #include "run/run.h"\n' \
  > "$scratch/src/task/task.h"
printf '#include "core/error.h"\n' > "$scratch/src/extra/extra.cc"

set +e
out=$(python3 "$checker" "$scratch")
status=$?
set -e
expected='src/extra/: expected a row `extra/` in docs/architecture.md
src/task/task.h:3: #include "render/image.h": render is not in the row of task/ in docs/architecture.md (core, physics)
docs/architecture.md:7: `render/` lists core, which no file of src/render/ includes
docs/architecture.md:7: `render/` lists task, whose row is below it (dependencies point one way: up the table)
docs/architecture.md:8: `task/` lists physics, which no file of src/task/ includes
docs/architecture.md:9: `gone/`: expected a folder src/gone/
5 folders, 4 folder dependencies, 6 mismatches'
if [[ $status -ne 1 || "$out" != "$expected" ]]; then
  echo "on the scratch tree, expected exit 1 and:"; echo "$expected"
  echo "got exit $status and:"; echo "$out"
  exit 1
fi

python3 "$checker" "$source_dir"
