#!/usr/bin/env bash
# scripts/check-doc-links.py: first on a small tree of pages whose broken links are known
# (a missing file, a missing image, a missing heading, a heading made twice, a note the
# index does not list), which it must name line by line; then on the repository's README.md, CHANGELOG.md and docs/.
set -euo pipefail
source_dir=$1
checker=$source_dir/scripts/check-doc-links.py
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

mkdir -p "$scratch/docs/guide" "$scratch/docs/images" "$scratch/docs/notes"
printf '# Index\n\n- [start](guide/start.md)\n' > "$scratch/docs/README.md"
printf '# A note\n\n**Conclusion.** None.\n' > "$scratch/docs/notes/2026-01-01-unlisted.md"
touch "$scratch/docs/images/strip.png"
cat > "$scratch/README.md" <<'PAGE'
# Demo

![strip](docs/images/strip.png) and ![gone](docs/images/gone.png)
See [the guide](docs/guide/start.md#first-run), [twice](docs/guide/start.md#notes-1),
[nowhere](docs/guide/start.md#no-such-heading), [missing](docs/missing.md) and
[the web](https://example.org/x.md).

```sh
cat [not a link](docs/none.md)
```
and `[inline](docs/none.md)` is code too.
PAGE
cat > "$scratch/docs/guide/start.md" <<'PAGE'
# Start
## First run
## Notes
## Notes
[up](../../README.md#demo) [self](#first-run) [bad self](#second-run)
PAGE

set +e
out=$(python3 "$checker" "$scratch")
status=$?
set -e
expected="README.md:3: docs/images/gone.png: expected an existing file
README.md:5: docs/guide/start.md#no-such-heading: expected a heading #no-such-heading in docs/guide/start.md
README.md:5: docs/missing.md: expected an existing file
docs/guide/start.md:5: #second-run: expected a heading #second-run in docs/guide/start.md
docs/notes/2026-01-01-unlisted.md: expected a link to it in docs/README.md
4 pages, 10 relative links and images, 5 broken"
if [[ $status -ne 1 || "$out" != "$expected" ]]; then
  echo "on the scratch pages, expected exit 1 and:"; echo "$expected"
  echo "got exit $status and:"; echo "$out"
  exit 1
fi

python3 "$checker" "$source_dir"
