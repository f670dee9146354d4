"""Checks of a built documentation site beyond mkdocs' own (``make docs`` runs it after
``mkdocs build --strict``): the API reference is generated from the docstrings, and the
gallery shows its pictures.

Usage: ``python tools/check_site.py SITE_DIR`` (exit 1 naming what is missing).
"""

from __future__ import annotations

import sys
from pathlib import Path

#: the gallery page shows at least this many pictures
GALLERY_PICTURES = 5


def site_problems(site: Path) -> list[str]:
    """What the built site at ``site`` lacks (empty: nothing)."""
    problems = []
    api = site / "api" / "viz" / "index.html"
    if not api.is_file() or "design_blocks" not in api.read_text("utf-8"):
        problems.append(f"{api}: the API reference of chargedesign.viz lacks design_blocks")
    gallery = site / "gallery" / "index.html"
    shown = gallery.read_text("utf-8").count("<img") if gallery.is_file() else 0
    if shown < GALLERY_PICTURES:
        problems.append(f"{gallery}: {shown} pictures, expected at least {GALLERY_PICTURES}")
    return problems


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python tools/check_site.py SITE_DIR", file=sys.stderr)
        return 2
    problems = site_problems(Path(argv[0]))
    for problem in problems:
        print(problem, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
