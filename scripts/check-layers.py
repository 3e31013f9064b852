#!/usr/bin/env python3
"""Checks that docs/architecture.md's table of src/ folders matches the includes.

    scripts/check-layers.py [ROOT]

Reads the table of docs/architecture.md under ROOT (default: the repository): one row per
folder of src/, `| `FOLDER/` | what it holds | DEPENDENCIES |`, the dependencies a comma-
separated list of folder names, or "—" for none. Then scans every file of src/FOLDER/ for
`#include "OTHER/..."` where OTHER is another folder of src/, and checks that
  - every such include names a folder the row of FOLDER lists,
  - every folder a row lists is included by some file of that folder,
  - every folder of src/ has a row and every row a folder,
  - a row lists only folders of rows above it, so that dependencies point one way.
Prints one line per mismatch, FILE:LINE: what is wrong, and exits 1 if there is any.
"""
import pathlib
import re
import sys

ROW = re.compile(r"^\|\s*`([a-z0-9_]+)/`\s*\|.*\|\s*([^|]*?)\s*\|\s*$")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"/]+)/[^"]*"')
TABLE = "docs/architecture.md"


def read_table(path):
    """{folder: (line, [dependencies])}, in the table's order."""
    rows = {}
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = ROW.match(line)
        if not m:
            continue
        cell = m.group(2)
        deps = [] if cell in ("—", "-", "") else [d.strip().strip("`").rstrip("/") for d in cell.split(",")]
        rows[m.group(1)] = (number, deps)
    return rows


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    src = root / "src"
    rows = read_table(root / TABLE)
    folders = sorted(p.name for p in src.iterdir() if p.is_dir())
    problems = []
    if not rows:
        problems.append(f"{TABLE}: expected a table of src/ folders (| `FOLDER/` | what | depends on |)")

    used = {folder: set() for folder in folders}
    for folder in folders:
        if folder not in rows:
            problems.append(f"src/{folder}/: expected a row `{folder}/` in {TABLE}")
            continue
        listed = rows[folder][1]
        for path in sorted(p for p in (src / folder).iterdir() if p.is_file()):
            for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
                m = INCLUDE.match(line)
                if not m or m.group(1) == folder or m.group(1) not in used:
                    continue
                used[folder].add(m.group(1))
                if m.group(1) not in listed:
                    problems.append(f"{path.relative_to(root)}:{number}: #include \"{line.split(chr(34))[1]}\": "
                                    f"{m.group(1)} is not in the row of {folder}/ in {TABLE} "
                                    f"({', '.join(listed) or '—'})")

    order = list(rows)
    for folder, (number, listed) in rows.items():
        if folder not in used:
            problems.append(f"{TABLE}:{number}: `{folder}/`: expected a folder src/{folder}/")
            continue
        for dep in listed:
            if dep not in rows:
                problems.append(f"{TABLE}:{number}: `{folder}/` lists {dep}, which has no row")
            elif dep not in used[folder]:
                problems.append(f"{TABLE}:{number}: `{folder}/` lists {dep}, which no file of src/{folder}/ includes")
            elif order.index(dep) > order.index(folder):
                problems.append(f"{TABLE}:{number}: `{folder}/` lists {dep}, whose row is below it "
                                f"(dependencies point one way: up the table)")

    for problem in problems:
        print(problem)
    includes = sum(len(deps) for deps in used.values())
    print(f"{len(folders)} folders, {includes} folder dependencies, {len(problems)} mismatches")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
