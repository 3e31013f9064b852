#!/usr/bin/env bash
# scripts/check-doc-commands.py: first on a scratch README whose wrong commands are known (a
# subcommand the tool does not have, an option `run` does not have, one inside an indented
# block), which it must name line by line, leaving alone a bibtex block and prose; then on
# the repository's README.md and docs/guide/.
set -euo pipefail
tool=$1
source_dir=$2
checker=$source_dir/scripts/check-doc-commands.py
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

mkdir -p "$scratch/docs/guide"
cat > "$scratch/README.md" <<'PAGE'
# Demo

```sh
./build/diverse run backflip --seed 2 --threads 2   # fine
./build/diverse frobnicate runs/x
mpirun -n 2 ./build/diverse run --no-such-flag
```

```bibtex
@software{diverse, author = {{The diverse authors}}}
```

Prose may say diverse things --freely.

    diverse export RUN --bvh --gif
PAGE

set +e
out=$(python3 "$checker" "$tool" "$scratch")
status=$?
set -e
# The list of subcommands in the first line follows the tool; the rest is fixed.
subcommands=$("$tool" --help | awk '/^Subcommands:/{on=1; next} on && /^$/{exit} on {print $1}' | LC_ALL=C sort | paste -sd, - | sed 's/,/, /g')
expected="README.md:5: diverse frobnicate: expected a subcommand ($subcommands)
README.md:6: diverse run --no-such-flag: expected an option of \`diverse run --help\`
README.md:15: diverse export --gif: expected an option of \`diverse export --help\`
1 pages, 4 diverse commands, 3 problems"
if [[ $status -ne 1 || "$out" != "$expected" ]]; then
  echo "on the scratch page, expected exit 1 and:"; echo "$expected"
  echo "got exit $status and:"; echo "$out"
  exit 1
fi

python3 "$checker" "$tool" "$source_dir"
