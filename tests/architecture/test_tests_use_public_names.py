"""Tests read no private names of the package: what a test needs is public (issue 21)."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def private_reads(source: str) -> list[str]:
    """``from chargedesign... import _x`` and ``module._x`` on an imported package module."""
    tree = ast.parse(source)
    names: set[str] = set()
    found: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("chargedesign"):
            for alias in node.names:
                if _private(alias.name):
                    found.append(f"{node.lineno}: import {alias.name}")
                names.add(alias.asname or alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("chargedesign"):
                    names.add(alias.asname or alias.name.split(".")[0])
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in names:
                found.append(f"{node.lineno}: {ast.unparse(node)}")
    return found


def test_the_checker_finds_private_reads() -> None:
    source = (
        "from chargedesign.viz import _hidden, shown\n"
        "import chargedesign.report as report\n"
        "report._lines(1)\nshown.ok\n"
    )
    assert private_reads(source) == ["1: import _hidden", "3: report._lines"]


def test_no_test_reads_a_private_name() -> None:
    offenders = [
        f"{path.relative_to(TESTS)}:{hit}"
        for path in sorted(TESTS.rglob("*.py"))
        for hit in private_reads(path.read_text(encoding="utf-8"))
    ]
    assert offenders == []
