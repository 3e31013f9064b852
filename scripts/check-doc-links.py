#!/usr/bin/env python3
"""Checks every relative link and image of the Markdown documentation.

    scripts/check-doc-links.py [ROOT]

Reads README.md, CHANGELOG.md and docs/**/*.md under ROOT (default: the repository). A link
or image whose target is a path must name a file or directory that exists; a link with a
#fragment into a Markdown file must name one of that file's headings, as GitHub makes
heading anchors (lower case, punctuation dropped, spaces to hyphens, -1, -2 for repeats).
Every page under docs/guide/, docs/reference/ and docs/notes/ must be linked from the index,
docs/README.md, so that a reader finds it.
Links to other sites (http:, https:, mailto:) are not fetched. Code blocks and inline code
are skipped. Prints one line per broken link, FILE:LINE: TARGET: what is wrong, and exits 1
if there is any.
"""
import pathlib
import re
import sys
import urllib.parse

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_SRC = re.compile(r"<(?:img|a)\b[^>]*\b(?:src|href)=\"([^\"]+)\"", re.IGNORECASE)
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def strip_code(lines):
    """The lines with fenced code blocks blanked and inline code spans removed."""
    out, fence = [], None
    for line in lines:
        marker = re.match(r"^\s*(```+|~~~+)", line)
        if fence:
            if marker and marker.group(1)[0] == fence[0] and len(marker.group(1)) >= len(fence):
                fence = None
            out.append("")
            continue
        if marker:
            fence = marker.group(1)
            out.append("")
            continue
        out.append(re.sub(r"(`+)(?:(?!\1).)+?\1", "", line))
    return out


def slug(text):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link's text only
    text = re.sub(r"<[^>]+>", "", text).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        seen, found = {}, set()
        for line in strip_code(path.read_text(encoding="utf-8").splitlines()):
            m = HEADING.match(line)
            if not m:
                continue
            base = slug(m.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
        cache[path] = found
    return cache[path]


def check(root):
    pages = [p for p in [root / "README.md", root / "CHANGELOG.md"] if p.exists()]
    pages += sorted((root / "docs").rglob("*.md"))
    problems, links = [], 0
    for page in pages:
        lines = strip_code(page.read_text(encoding="utf-8").splitlines())
        for number, line in enumerate(lines, 1):
            for m in list(LINK.finditer(line)) + list(HTML_SRC.finditer(line)):
                target = m.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE):
                    continue  # another site or scheme
                links += 1
                where = f"{page.relative_to(root)}:{number}: {target}"
                path_part, _, fragment = target.partition("#")
                path_part = urllib.parse.unquote(path_part)
                dest = page if not path_part else (page.parent / path_part).resolve()
                if not dest.exists():
                    problems.append(f"{where}: expected an existing file")
                    continue
                if fragment and dest.suffix == ".md":
                    if urllib.parse.unquote(fragment).lower() not in anchors(dest):
                        problems.append(f"{where}: expected a heading #{fragment} in "
                                        f"{dest.relative_to(root) if dest.is_relative_to(root) else dest}")
    index = root / "docs" / "README.md"
    if index.exists():
        listed = set()
        for line in strip_code(index.read_text(encoding="utf-8").splitlines()):
            for m in LINK.finditer(line):
                listed.add((index.parent / m.group(1).partition("#")[0]).resolve())
        for part in ("guide", "reference", "notes"):
            for page in sorted((root / "docs" / part).glob("*.md")):
                if page.resolve() not in listed and page.name != "README.md":
                    problems.append(f"{page.relative_to(root)}: expected a link to it in docs/README.md")
    return pages, links, problems


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
    root = root.resolve()
    pages, links, problems = check(root)
    for line in problems:
        print(line)
    print(f"{len(pages)} pages, {links} relative links and images, {len(problems)} broken")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
