#!/usr/bin/env python3
"""Checks the diverse commands shown in the README's and the guide's code blocks against the tool.

    scripts/check-doc-commands.py DIVERSE [ROOT]

Every line of a shell code block in README.md and docs/guide/*.md (fenced as ```sh, ```bash
or without a language, or indented by four spaces) that calls the tool (`./build/diverse
SUB ...`, `diverse SUB ...`, also after `mpirun -n R` or `nice`) must name a
subcommand that `DIVERSE --help` lists, and every `--option` on it must be one that
`DIVERSE SUB --help` lists. This does not run the commands (several take minutes); it
keeps the documentation's commands from naming what the tool does not have. Prints one line
per problem, FILE:LINE: what is wrong, and exits 1 if there is any.
"""
import pathlib
import re
import subprocess
import sys


def help_text(tool, *args):
    return subprocess.run([tool, *args, "--help"], capture_output=True, text=True, check=True).stdout


def main():
    tool = sys.argv[1]
    root = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else pathlib.Path(__file__).parent.parent)
    top = help_text(tool)
    subs = set(re.findall(r"^  ([a-z][a-z-]*) ", top.split("Subcommands:")[1].split("\n\n")[0], re.M))
    options = {}
    problems, checked = [], 0
    pages = [root / "README.md"] + sorted((root / "docs" / "guide").glob("*.md"))
    for page in pages:
        fence, shell = False, False
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            marker = re.match(r"^\s*(?:```|~~~)\s*(\w*)", line)
            if marker:
                fence = not fence
                shell = fence and marker.group(1) in ("", "sh", "bash", "shell", "console")
                continue
            if not (shell or (not fence and line.startswith("    "))):
                continue
            command = line.split("#", 1)[0]
            m = re.search(r"(?:^|[\s;&|(])(?:\./build/|build/)?diverse\s+([a-z][a-z-]*)(.*)", command)
            if not m:
                continue
            checked += 1
            where = f"{page.relative_to(root)}:{number}"
            sub = m.group(1)
            if sub not in subs:
                problems.append(f"{where}: diverse {sub}: expected a subcommand ({', '.join(sorted(subs))})")
                continue
            if sub not in options:
                options[sub] = set(re.findall(r"(--[a-z][a-z0-9-]*)", help_text(tool, sub)))
            for flag in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", m.group(2)):
                if flag not in options[sub]:
                    problems.append(f"{where}: diverse {sub} {flag}: expected an option of `diverse {sub} --help`")
    for line in problems:
        print(line)
    print(f"{len(pages)} pages, {checked} diverse commands, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
