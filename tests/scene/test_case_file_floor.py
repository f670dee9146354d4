"""The case file's reader sits on the boundary floor: it imports nothing of the model, and
its one exact-arithmetic refusal (a denominator vanishing on the whole sphere) agrees with
the model's sphere normal form, an independent route."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
import sympy as sp

from chargedesign.model.case import mu_from_l as model_mu_from_l
from chargedesign.model.case_file import case_ring
from chargedesign.model.certificate import sphere_normal_form
from chargedesign.scene.case_file import GAMMA, mu_from_l, vanishes_on_sphere
from chargedesign.scene.expressions import g1, g2, g3, p, q, r

FLOOR = Path(__file__).resolve().parents[2] / "chargedesign" / "scene"


@pytest.mark.parametrize("name", ["case_file.py", "expressions.py"])
def test_the_case_reader_imports_nothing_of_the_model(name: str) -> None:
    tree = ast.parse((FLOOR / name).read_text(encoding="utf-8"))
    imported = [
        node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
    ] + [a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names]
    above = [
        m
        for m in imported
        if m.startswith("chargedesign.")
        and m.split(".")[1] not in ("errors", "readers", "scene", "validation", "vocabulary")
    ]
    assert imported and above == []


def test_the_floor_symbols_are_the_models() -> None:
    from chargedesign.model import case

    assert (p, q, r, g1, g2, g3) == case.STATE_SYMBOLS
    assert model_mu_from_l is mu_from_l  # one home for (mu)
    assert mu_from_l(GAMMA) == -GAMMA  # grad |gamma|^2 - (div gamma) gamma = 2 gamma - 3 gamma


@pytest.mark.parametrize(
    "expr",
    [
        g1**2 + g2**2 + g3**2 - 1,
        (g1**2 + g2**2 + g3**2 - 1) * (p * g1 + 3 * q - r**2),
        (g1**2 + g2**2 + g3**2 - 1) ** 2 * g3,
        g1**2 + g2**2 + g3**2,
        g1**2 - 1,
        g3,
        g1**4 - (1 - g2**2 - g3**2) ** 2,
        sp.Rational(1, 3) * g1 * g2 * (g1**2 + g2**2 + g3**2 - 1) + p,
    ],
)
def test_vanishing_on_the_sphere_agrees_with_the_model_normal_form(expr: sp.Expr) -> None:
    normal, _ = sphere_normal_form(case_ring().from_expr(sp.expand(expr)))
    assert vanishes_on_sphere(expr) == (normal == 0)
