"""Audit of the paper's printed formulas against the derived ones.

Every entry compares a printed formula (:mod:`chargedesign.model.printed`) with its derived
counterpart and reports the exact difference ``printed - derived`` on the unit sphere.

Canonical form of a difference (so that "agrees" is a zero test and the text is unique):
the difference is first reduced to its unique normal form modulo ``|gamma|^2 = 1`` in the
ring of polynomials in gamma1, gamma2 and Laurent polynomials in gamma3
(:func:`chargedesign.model.certificate.sphere_normal_form`, which eliminates gamma1^2). It
is then rewritten as ``numerator / gamma3^k`` with the smallest such k, and the numerator
is reduced by ``gamma3^2 -> 1 - gamma1^2 - gamma2^2`` so that gamma3 appears in it at most
linearly. The text groups the terms by monomials in p, q, r, each coefficient factored.
"""

from __future__ import annotations

import re

import sympy as sp

from chargedesign.model import case
from chargedesign.model.audit_entry import AuditEntry
from chargedesign.model.case import STATE_SYMBOLS, C, g3, mu_from_l, p, q, r, symbolic_case
from chargedesign.model.certificate import (
    G3_INDEX,
    U_INDEX,
    laurent_normal,
    laurent_ring,
    reduced_dI4_dt,
    sphere_normal_form,
    split_by_power,
    to_ring,
    to_sympy,
)
from chargedesign.model.equations import equations_of_motion
from chargedesign.model.printed import (
    printed_equations,
    printed_gamma_dot,
    printed_I3,
    printed_I4,
    printed_l,
    printed_mu,
)

#: the entries :func:`audit_printed` returns, in order (the moment conditions (p6) are the
#: conditions engine's: :func:`chargedesign.moment_conditions.audit.audit_p6`)
ENTRY_NAMES = ("mu_from_l", "eom_p", "eom_q", "eom_r", "eom_gamma", "I3", "I3_level", "I4")


def sphere_canonical(expr: sp.Expr) -> sp.Expr:
    """The canonical representative of ``expr`` on ``|gamma| = 1`` (see the module doc).

    Parameters
    ----------
    expr : sympy.Expr
        Polynomial in p, q, r, gamma1, gamma2 and the parameters, Laurent in gamma3.
    """

    normal, _ = sphere_normal_form(to_ring(expr))
    if normal == 0:
        return sp.Integer(0)
    ring = laurent_ring()
    k = max(m[U_INDEX] for m in normal.monoms())
    numerator = laurent_normal(normal * ring.gens[G3_INDEX] ** k)
    s = 1 - ring.gens[3] ** 2 - ring.gens[4] ** 2
    reduced = ring.zero
    for j, coeff in split_by_power(numerator, G3_INDEX, 2).items():
        reduced += coeff * s**j
    if k > 0 and all(m[G3_INDEX] >= 1 for m in reduced.monoms()):
        reduced = laurent_normal(reduced * ring.gens[U_INDEX])
        k -= 1
    return to_sympy(reduced) / g3**k


def grouped_text(expr: sp.Expr) -> str:
    """``expr`` as text, grouped by monomials in p, q, r with factored coefficients."""

    if expr == 0:
        return "0"
    numerator, denominator = sp.fraction(sp.together(expr))
    terms = []
    for monom, coeff in sp.Poly(sp.expand(numerator), p, q, r).terms():
        velocity = sp.Mul(*[v**e for v, e in zip((p, q, r), monom, strict=True)])
        terms.append(velocity * sp.factor(coeff / denominator))
    return str(sp.Add(*terms))


def parse_difference(text: str) -> sp.Expr:
    """Parse an entry's ``difference`` back into sympy in the model's symbols.

    ``lambda`` is a Python keyword, so it is renamed before parsing.
    """

    names = {s.name: s for s in (*case.STATE_SYMBOLS, *case.PARAMETER_SYMBOLS)}
    names["lambda_"] = names.pop("lambda")
    return sp.parse_expr(re.sub(r"\blambda\b", "lambda_", text), local_dict=names)


def _vector_text(diffs: list[sp.Expr]) -> str:
    if all(e == 0 for e in diffs):
        return "0"
    return "[" + ", ".join(grouped_text(e) for e in diffs) + "]"


def _entry_mu_from_l() -> AuditEntry:

    # identically, not only on the sphere: (mu) is an identity in gamma
    diffs = [sp.expand(e) for e in printed_mu() - mu_from_l(printed_l())]
    return AuditEntry(
        "mu_from_l",
        all(e == 0 for e in diffs),
        _vector_text(diffs),
        "printed (muu) minus mu derived from the printed l by formula (mu); identically in "
        "gamma, not only on the sphere",
    )


def _entry_eom(index: int, name: str) -> AuditEntry:
    derived = equations_of_motion()[index]
    printed = printed_equations()[index]
    diff = sphere_canonical(printed - derived)
    label = ("p'", "q'", "r'")[index]
    return AuditEntry(
        name,
        diff == 0,
        grouped_text(diff),
        f"printed {label} minus {label} derived from the general Euler-Poisson form, "
        "canonical on |gamma| = 1",
    )


def _entry_eom_gamma() -> AuditEntry:
    derived = equations_of_motion()[3:, 0]
    diffs = [sp.expand(e) for e in printed_gamma_dot() - derived]
    return AuditEntry(
        "eom_gamma",
        all(e == 0 for e in diffs),
        _vector_text(diffs),
        "printed Poisson equations minus gamma' = gamma x omega; identically",
    )


def _derived_level_of_printed_zero() -> sp.Expr:
    """The derived I3 on the printed zero level, which must be a constant on the sphere."""

    level = sphere_canonical(symbolic_case().I3 - C * printed_I3())
    if level.free_symbols & set(STATE_SYMBOLS):
        raise AssertionError(f"C * printed I3 - derived I3 is not constant on the sphere: {level}")
    return level


def _entry_I3() -> AuditEntry:
    diff = sphere_canonical(C * printed_I3() - symbolic_case().I3)
    return AuditEntry(
        "I3",
        diff == 0,
        grouped_text(diff),
        "C * printed I3 minus derived (omega I + l) . gamma on |gamma| = 1 (the printed I3 "
        "lacks the overall factor C); a constant difference: the printed I3 is still a first "
        "integral, but its zero level is another level of the derived I3",
    )


def _entry_I3_level() -> AuditEntry:
    level = _derived_level_of_printed_zero()
    remainder = reduced_dI4_dt(level)
    agrees = bool(level == 0 or remainder == 0)
    note = (
        f"printed I3 = 0 is derived I3 = {level} on |gamma| = 1; I4 is conserved on derived "
        "I3 = 0 (the certificate)"
    )
    if not agrees:
        note += (
            f", and on the printed zero level dI4/dt reduced modulo |gamma| = 1 has "
            f"{len(remainder)} non-zero terms (see the counterexample); the two levels "
            "coincide only when n = 0"
        )
    return AuditEntry("I3_level", agrees, grouped_text(level), note)


def _entry_I4() -> AuditEntry:
    remainder = to_sympy(reduced_dI4_dt(integral=printed_I4()))
    same_as_model = sp.expand(printed_I4() - symbolic_case().I4) == 0
    return AuditEntry(
        "I4",
        remainder == 0,
        grouped_text(remainder),
        "d(printed I4)/dt along the derived equations, reduced on derived I3 = 0 and "
        "|gamma| = 1 (zero: the printed I4 is the integral the theorem claims); the printed "
        "I4 " + ("equals" if same_as_model else "differs from") + " the model's I4 term by term",
    )


def audit_printed() -> list[AuditEntry]:
    """Compare each printed formula of the model with its derived counterpart.

    Returns
    -------
    list of AuditEntry
        In the order of :data:`ENTRY_NAMES`. An entry that does not agree is a finding about
        the paper, not a failure of the model. The moment conditions (p6) are audited by the
        conditions engine (:func:`chargedesign.moment_conditions.audit.audit_p6`);
        :mod:`chargedesign.verification` joins both.
    """
    return [
        _entry_mu_from_l(),
        _entry_eom(0, "eom_p"),
        _entry_eom(1, "eom_q"),
        _entry_eom(2, "eom_r"),
        _entry_eom_gamma(),
        _entry_I3(),
        _entry_I3_level(),
        _entry_I4(),
    ]
