"""The docs' key tables, generated from the scene's key declarations
(:mod:`chargedesign.scene.keys`), written between markers in the docs pages:

    python tools/docs_tables.py          # rewrite every generated block
    python tools/docs_tables.py --check  # exit 1 when a page differs (tests/docs does this)

A block is ``<!-- keys:TABLE -->`` ... ``<!-- /keys -->``; its text is
:func:`chargedesign.schemas.keys_markdown` of TABLE.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"(<!-- keys:(\w+) -->\n)(.*?)(<!-- /keys -->)", re.S)


def generated(text: str) -> str:
    """``text`` with every key block replaced by its generated table."""
    from chargedesign.schemas import keys_markdown

    return BLOCK.sub(lambda m: m.group(1) + keys_markdown(m.group(2)) + m.group(4), text)


def pages() -> list[Path]:
    """The docs pages that hold at least one key block."""
    return [p for p in sorted((ROOT / "docs").glob("*.md")) if BLOCK.search(p.read_text("utf-8"))]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only report pages that differ")
    args = parser.parse_args(argv)
    stale = []
    for page in pages():
        text = page.read_text("utf-8")
        new = generated(text)
        if new != text:
            stale.append(page)
            if not args.check:
                page.write_text(new, "utf-8")
    for page in stale:
        print(f"{page.relative_to(ROOT)}: {'differs' if args.check else 'rewritten'}")
    return 1 if stale and args.check else 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
