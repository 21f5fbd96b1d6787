"""Check, and with --fix repair, the relative links of the Markdown docs.

Usage: python scripts/docs_links.py [--fix]

Scans README.md, fixtures/README.md and docs/**/*.md for `[text](target)` links to local files.
A link whose target is missing is an error; with --fix, a missing target that exactly one file
under docs/ ends with (the same name, or the same folder and name) is rewritten to point there.
That is what a page moved under docs/results/archive/ needs: the pages that link to it, and
its own links to pages that stayed, are repaired by one run. Exits 1 if a link stays broken.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"(\]\()([^)\s]+)(\))")


def pages(root: Path) -> list[Path]:
    found = [root / "README.md", root / "fixtures" / "README.md", *sorted((root / "docs").rglob("*.md"))]
    return [p for p in found if p.is_file()]


def local(target: str) -> str | None:
    """The file part of a link to a local file, or None for URLs and in-page anchors."""
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
        return None
    return target.split("#", 1)[0] or None


def candidates(root: Path, path: str) -> list[Path]:
    """Files under docs/ (or the repo root's README.md) whose path ends with the link's path."""
    parts = [p for p in Path(path).parts if p not in ("..", ".")]
    found: list[Path] = []
    for depth in range(len(parts), 0, -1):
        tail = Path(*parts[-depth:])
        found = [p for p in (root / "docs").rglob(tail.name) if p.as_posix().endswith(tail.as_posix())]
        if root.joinpath(tail).exists() and depth == len(parts):
            found.append(root / tail)
        if found:
            return found
    return found


def check(root: Path, fix: bool) -> list[str]:
    broken: list[str] = []
    for page in pages(root):
        text = page.read_text()

        def repair(m: re.Match[str], page: Path = page) -> str:
            path = local(m.group(2))
            if path is None or (page.parent / path).exists():
                return m.group(0)
            found = candidates(root, path) if fix else []
            if len(found) != 1:
                broken.append(f"{page.relative_to(root)}: {m.group(2)}")
                return m.group(0)
            new = os.path.relpath(found[0], page.parent) + m.group(2)[len(path):]
            return m.group(1) + Path(new).as_posix() + m.group(3)

        new_text = LINK.sub(repair, text)
        if fix and new_text != text:
            page.write_text(new_text)
    return broken


def main(argv: list[str]) -> int:
    broken = check(ROOT, fix="--fix" in argv)
    for line in broken:
        print(f"broken link: {line}", file=sys.stderr)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
