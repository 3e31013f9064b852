#!/usr/bin/env bash
# Writes docs/reference/commands.md from the tool's own definitions: `diverse --help` and
# every subcommand's `--help`, in the order `diverse --help` lists them. The page is never
# edited by hand; the test docs_commands_reference fails when it and the tool differ.
#
#   scripts/commands-doc.sh [DIVERSE [OUT]]      write the page (defaults: build/diverse,
#                                                docs/reference/commands.md)
#   scripts/commands-doc.sh --check DIVERSE PAGE  exit 1 if PAGE differs from what DIVERSE gives
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
check=0
if [[ ${1:-} == --check ]]; then check=1; shift; fi
tool=${1:-$root/build/diverse}
page=${2:-$root/docs/reference/commands.md}
[[ -x $tool ]] || { echo "commands-doc.sh: $tool: expected the built diverse tool" >&2; exit 2; }

# The usage line names the program as it was called; the page names it `diverse`.
help_of() { "$tool" "$@" --help | sed -E '2s|^Usage: [^ ]+|Usage: diverse|'; }

subcommands=$(help_of | awk '/^Subcommands:/{on=1; next} on && /^$/{exit} on && /^  [a-z]/{print $1}')

# Every help ends with at least one example line (CLI11 footer "Example:" or "Examples:").
for sub in "" $subcommands; do
  if ! help_of $sub | grep -E '^Examples?:$' >/dev/null; then
    echo "commands-doc.sh: diverse $sub --help: expected an \"Example:\" footer" >&2
    exit 1
  fi
done

generate() {
  echo "# Commands"
  echo
  echo "Every \`diverse\` subcommand with its options, as its \`--help\` prints them. This page is"
  echo "generated from the tool; do not edit it. After changing a subcommand or its help text, run"
  echo "\`./scripts/commands-doc.sh\` from the repository root (it reads \`build/diverse\`)."
  echo
  echo "| command | what it does |"
  echo "|---|---|"
  help_of | awk '/^Subcommands:/{on=1; next} on && /^$/{exit} on && /^  [a-z]/{name=$1; $1=""; sub(/^ +/, ""); printf "| [`diverse %s`](#diverse-%s) | %s |\n", name, name, $0}'
  echo
  echo "## diverse"
  echo
  echo '```text'
  help_of
  echo '```'
  for sub in $subcommands; do
    echo
    echo "## diverse $sub"
    echo
    echo '```text'
    help_of "$sub"
    echo '```'
  done
}

if (( check )); then
  if ! diff -u "$page" <(generate) >&2; then
    echo "$page differs from the help of $tool; regenerate it with: ./scripts/commands-doc.sh" >&2
    exit 1
  fi
else
  mkdir -p "$(dirname "$page")"
  generate > "$page"
fi
