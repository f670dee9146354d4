"""Audit of the printed formulas: the computed verdicts, and each difference re-checked by a
second route (the difference added back to the derived formula gives the printed one on
the sphere, via the rational parametrisation of the sphere)."""

from __future__ import annotations

import pytest
import sympy as sp

from chargedesign.model import audit, printed
from chargedesign.model.case import (
    PARAMETER_SYMBOLS,
    C,
    K,
    c,
    d,
    g1,
    g2,
    g3,
    mu_from_l,
    n,
    p,
    r,
    symbolic_case,
)
from chargedesign.model.equations import equations_of_motion

s, t = sp.symbols("s t", real=True)
_w = 1 + s**2 + t**2
#: stereographic parametrisation of the unit sphere (rational, covers it but one point)
SPHERE = {g1: 2 * s / _w, g2: 2 * t / _w, g3: (1 - s**2 - t**2) / _w}


def zero_on_sphere(expr: sp.Expr) -> bool:
    numerator, _ = sp.fraction(sp.together(expr.xreplace(SPHERE)))
    return sp.expand(numerator) == 0


@pytest.fixture(scope="module")
def entries() -> dict[str, audit.AuditEntry]:
    return {e.name: e for e in audit.audit_printed()}


def test_entries_and_computed_verdicts(entries: dict[str, audit.AuditEntry]) -> None:
    assert list(entries) == list(audit.ENTRY_NAMES)
    verdicts = {name: e.agrees for name, e in entries.items()}
    assert verdicts == {
        "mu_from_l": True,
        "eom_p": False,
        "eom_q": False,
        "eom_r": True,
        "eom_gamma": True,
        "I3": False,
        "I3_level": False,
        "I4": True,
    }
    for e in entries.values():
        assert (e.difference == "0") == e.agrees
        assert e.note
        assert set(e.to_dict()) == {"name", "agrees", "difference", "note"}


def test_the_misprints_exactly(entries: dict[str, audit.AuditEntry]) -> None:
    diff_p = audit.parse_difference(entries["eom_p"].difference)
    # printed p' has 2K(c g1 + d g2) where the derived one has 2K g3 (c g1 + d g2)
    assert sp.expand(diff_p - K * r * (1 - g3) * (c * g1 + d * g2)) == 0
    diff_q = audit.parse_difference(entries["eom_q"].difference)
    expected_q = (
        sp.Rational(3, 2) * n * g3 * p  # the p bracket lost its -3 n g3
        - K * r * (1 - g3) * (c * g2 - d * g1)  # the r bracket lost its factor g3
        - 2 * K**2 * c * d * g2 * g3 * (3 * g1**2 - g2**2)  # sign of the cd K^2 term
    )
    assert sp.expand(diff_q - expected_q) == 0
    assert audit.parse_difference(entries["I3"].difference) == -2 * C * n
    assert audit.parse_difference(entries["I3_level"].difference) == 2 * C * n


@pytest.mark.parametrize("index, name", [(0, "eom_p"), (1, "eom_q"), (2, "eom_r")])
def test_difference_added_to_derived_gives_printed_equation(
    entries: dict[str, audit.AuditEntry], index: int, name: str
) -> None:
    derived = equations_of_motion()[index]
    difference = audit.parse_difference(entries[name].difference)
    assert zero_on_sphere(derived + difference - printed.printed_equations()[index])
    if not entries[name].agrees:
        # and the difference is not itself zero on the sphere
        assert not zero_on_sphere(difference)


def test_I3_difference_added_to_derived_gives_printed(
    entries: dict[str, audit.AuditEntry],
) -> None:
    difference = audit.parse_difference(entries["I3"].difference)
    assert zero_on_sphere(symbolic_case().I3 + difference - C * printed.printed_I3())


def test_printed_zero_level_is_the_derived_level_2Cn(
    entries: dict[str, audit.AuditEntry],
) -> None:
    level = audit.parse_difference(entries["I3_level"].difference)
    # on printed I3 = 0 (solve it for r), the derived I3 equals the reported level
    r_printed = sp.solve(printed.printed_I3(), r)[0]
    assert zero_on_sphere(symbolic_case().I3.xreplace({r: r_printed}) - level)
    assert "non-zero terms" in entries["I3_level"].note


def test_mu_and_gamma_agree_identically() -> None:
    assert sp.expand(printed.printed_mu() - mu_from_l(printed.printed_l())) == sp.zeros(3, 1)
    assert sp.expand(printed.printed_mu() - symbolic_case().mu) == sp.zeros(3, 1)
    assert printed.printed_gamma_dot() - equations_of_motion()[3:, 0] == sp.zeros(3, 1)


def test_two_transcriptions_of_I4_agree() -> None:
    assert sp.expand(printed.printed_I4() - symbolic_case().I4) == 0


def test_canonical_form_is_unique_on_the_sphere() -> None:
    sphere = g1**2 + g2**2 + g3**2 - 1
    base = K * r * (1 - g3) * (c * g1 + d * g2) + g1 * g2 / g3**3
    shifted = base + sphere * (p * g1**3 - n / g3**2 + c)
    assert audit.sphere_canonical(base) == audit.sphere_canonical(shifted)
    assert zero_on_sphere(audit.sphere_canonical(base) - base)
    assert audit.sphere_canonical(sphere * (g1 + 1 / g3**5)) == 0
    # gamma3 appears at most linearly in the numerator
    numerator, _ = sp.fraction(sp.together(audit.sphere_canonical(g3**4 * p + c / g3**2)))
    assert sp.degree(numerator, g3) <= 1


def test_parse_difference_reads_lambda() -> None:
    lam = PARAMETER_SYMBOLS[6]
    assert (
        audit.parse_difference("2*lambda/gamma3**3 + rho") == 2 * lam / g3**3 + PARAMETER_SYMBOLS[7]
    )


def test_p6_entry_comes_from_the_conditions_engine() -> None:
    """verify joins the model's entries and the conditions engine's (p6), in that order."""
    from chargedesign import verification
    from chargedesign.moment_conditions import audit as conditions_audit

    model_entries = audit.audit_printed()
    assert [e.name for e in model_entries] == list(audit.ENTRY_NAMES)
    expected = conditions_audit.audit_p6()
    assert expected.name == "p6" and isinstance(expected.agrees, bool) and expected.difference
    printed = [e.to_dict() for e in [*model_entries, expected]]
    assert verification.collect()["printed"] == printed


def test_printed_p6_conditions_as_data() -> None:
    eqs = printed.printed_p6()
    m = printed.moment_symbol
    assert sp.Eq(6 * printed.a2 * m("xyz"), c * C * K) in eqs
    assert sp.Eq(m("xx"), -C * n / printed.a1) in eqs
    assert len(eqs) == 16
    assert {str(x)[2:] for e in eqs for x in e.lhs.free_symbols if str(x).startswith("I_")} <= set(
        printed.P6_KEYS
    )
