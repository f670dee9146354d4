"""Route ad hoc number formats in f-strings through ``chargedesign.formatting.fmt``.

    python tools/route_formats.py FILE.py [FILE.py ...]

A one-off refactoring aid (issue 21, "one way to print a quantity"): every ``{expr:.3g}``,
``{expr:.4g}``, ``{expr:g}``, ... inside an f-string becomes ``{fmt(expr, KIND)}`` with the
kind that prints the same digits (:data:`chargedesign.formatting.KINDS`), an alignment such as
``{x:>10.3e}`` becomes ``{fmt(x, ERROR):>10}``, and the file gains the import. The text the
code prints does not change. Formats with no kind (``.0f``, ``.2f``, ``3d``: timings,
progress bars, counts) are left alone. Lines that grow past the line length are listed so they
can be wrapped by hand (ruff reports them too).
"""

from __future__ import annotations

import ast
import io
import re
import sys
import tokenize
from pathlib import Path

#: format specification -> kind constant of chargedesign.formatting (None: the default kind)
SPECS = {
    ".3g": None,
    ".4g": "PRECISE",
    ".2g": "ROUGH",
    ".1g": "ORDER",
    ".0e": "ORDER_SCI",
    "g": "PLAIN",
    ".6g": "CELL",
    ".12g": "FULL",
    ".17g": "EXACT",
    ".3e": "ERROR",
    ".1e": "FLOOR",
    ".2e": "AGREEMENT",
    "+.4f": "DIRECTION",
}
FIELD = re.compile(r"\{([^{}]+)\}")
ALIGN = re.compile(r"^([<>^]?\d*)(.*)$")
LINE_LENGTH = 100


def _field(inner: str, used: set[str]) -> str | None:
    """The replacement of one replacement field's text (None: leave it)."""
    if "!" in inner or ":" not in inner:
        return None
    expr, spec = inner.rsplit(":", 1)
    align, core = ALIGN.match(spec).groups()  # type: ignore[union-attr]
    if spec == "g":
        align, core = "", "g"
    if core not in SPECS or not expr.strip():
        return None
    kind = SPECS[core]
    used.add("fmt")
    if kind:
        used.add(kind)
    call = f"fmt({expr.strip()}{', ' + kind if kind else ''})"
    return "{" + call + (":" + align if align else "") + "}"


def convert_fstring(token: str, used: set[str]) -> str:
    """One string token with its number formats routed through ``fmt``."""
    prefix, body = re.match(r"([rRbBuUfF]*)(.*)", token, re.S).groups()  # type: ignore[union-attr]
    if "f" not in prefix.lower():
        return token
    parts = re.split(r"(\{\{|\}\})", body)  # doubled braces are literal text
    return prefix + "".join(
        part
        if part in ("{{", "}}")
        else FIELD.sub(lambda m: _field(m.group(1), used) or m.group(0), part)
        for part in parts
    )


def convert_source(src: str) -> tuple[str, set[str]]:
    """The converted source and the names it needs from chargedesign.formatting."""
    used: set[str] = set()
    offsets = [0]
    for line in src.splitlines(keepends=True):
        offsets.append(offsets[-1] + len(line))
    edits = []
    for tok in tokenize.generate_tokens(io.StringIO(src).readline):
        if tok.type == tokenize.STRING:
            new = convert_fstring(tok.string, used)
            if new != tok.string:
                start = offsets[tok.start[0] - 1] + tok.start[1]
                end = offsets[tok.end[0] - 1] + tok.end[1]
                edits.append((start, end, new))
    for start, end, new in reversed(edits):
        src = src[:start] + new + src[end:]
    if used:
        line = f"from chargedesign.formatting import {', '.join(sorted(used))}"
        tree = ast.parse(src)
        imports = [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))]
        lines = src.split("\n")
        lines.insert(imports[-1].end_lineno if imports else 0, line)
        src = "\n".join(lines)
    ast.parse(src)
    return src, used


def main(paths: list[str]) -> int:
    for name in paths:
        path = Path(name)
        src, used = convert_source(path.read_text())
        path.write_text(src)
        long = [i + 1 for i, line in enumerate(src.split("\n")) if len(line) > LINE_LENGTH]
        print(
            f"{path}: {', '.join(sorted(used)) or 'nothing to route'}"
            + (f"; wrap lines {long}" if long else "")
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
