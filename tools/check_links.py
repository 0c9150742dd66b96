#!/usr/bin/env python3
"""Check that every relative link in README.md and docs/**/*.md resolves: the file exists and,
for `file.md#anchor`, the anchor is one of the file's headings (GitHub's slugs).

Run from anywhere: `python3 tools/check_links.py`. Prints each broken link and exits 1 if any.
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~)")


def slug(heading: str) -> str:
    s = heading.strip().lower()
    s = re.sub(r"[`*_]", "", s)
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


def anchors(path: pathlib.Path) -> set:
    out, fenced, seen = set(), False, {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced and line.startswith("#"):
            base = slug(line.lstrip("#"))
            n = seen.get(base, 0)
            seen[base] = n + 1
            out.add(base if n == 0 else f"{base}-{n}")
    return out


def links(path: pathlib.Path):
    fenced = False
    for no, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if fenced:
            continue
        for m in LINK.finditer(line):
            yield no, m.group(1) or m.group(2)


def main() -> int:
    files = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    bad = 0
    for f in files:
        for no, target in links(f):
            if re.match(r"^[a-z]+:", target):
                continue  # http:, https:, mailto:
            name, _, frag = target.partition("#")
            dest = (f.parent / name).resolve() if name else f
            where = f"{f.relative_to(ROOT)}:{no}: {target}"
            if not dest.exists():
                print(f"missing file   {where}")
                bad += 1
            elif frag and dest.suffix == ".md" and frag not in anchors(dest):
                print(f"missing anchor {where}")
                bad += 1
    print(f"{len(files)} files checked, {bad} broken links")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
