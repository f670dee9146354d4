"""The conditions of a case of (ep) that point masses in uniform gravity realise.

The first step of designing any case (the workbench issue, item 4): a case whose ``l`` is zero
and whose ``V`` is at most quadratic in gamma, ``V = v0 + a . gamma + gamma Q gamma``, is
realised by masses alone in the gravity ``Phi_g = f1 Z + f2 (3 Z^2 - R^2)/2`` (contract:
``legendre = [f1, f2]``; f1 = g is uniform gravity, f2 a gravity gradient). A mass m at body
point x has energy ``m Phi_g`` with ``Z = x . gamma``, ``R^2 = |x|^2``, so the body's potential
is ``f1 sum m x . gamma + (3 f2 / 2) gamma S gamma`` up to a constant, ``S = sum m x x^T`` its
second moments, and its inertia about O is ``tr(S) delta - S``. The linear conditions:

- first moments ``sum m x = a / f1`` (the centre of mass gives exactly the linear part);
- second moments ``S = tr(S) delta - I``: ``S_xx = (B + C - A)/2`` (and cyclic), products zero.

The second moments are fixed by the inertia, so the quadratic part is realised only when
``Q`` is ``(3 f2 / 2) S`` up to a multiple of the identity (a constant on the sphere); f2 is
then derived. Clebsch's case (``Q = eps/2 I``) is so: a body in the gradient ``f2 = -eps/3``.
The heavy tops (Euler, Lagrange, Kowalevski, Goriachev-Chaplygin) have ``Q = 0`` and f2 = 0.

They are the conditions engine's :class:`~chargedesign.moment_conditions.LinearConditions`, and
the masses are designed by the one design program (:func:`chargedesign.designer.pipeline.
design_body`, ``m >= 0``, polished). Other cases (a non-zero ``l``, a V of higher degree,
singular terms) go to the general conditions engine
(:func:`chargedesign.moment_conditions.case.derive_case_conditions`).
"""

from __future__ import annotations

from fractions import Fraction

import sympy as sp

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.errors import InfeasibleError
from chargedesign.model.case import GAMMA
from chargedesign.moment_conditions import LinearCondition, LinearConditions
from chargedesign.scene.case_file import Case
from chargedesign.scene.case_refusals import (
    refuse_gyroscopic,
    refuse_mass_degree,
    refuse_quadratic_mismatch,
    refuse_singular_v,
)
from chargedesign.validation import as_finite_float


def quadratic_potential(case: Case) -> tuple[tuple[sp.Rational, ...], sp.Matrix]:
    """``(a, Q)`` of ``V = v0 + a . gamma + gamma Q gamma`` (exact, Q symmetric), or a one-line
    refusal naming why masses in a gravity field cannot realise the case."""
    if case.l is None or any(sp.expand(component) != 0 for component in case.l):
        refuse_gyroscopic(case.name)
    V = sp.expand(case.V)
    if not V.is_polynomial(*GAMMA):
        refuse_singular_v(case.name, sp.sstr(V))
    degree = sp.Poly(V, *GAMMA).total_degree() if V.free_symbols else 0
    refuse_mass_degree(case.name, degree)
    a = tuple(sp.Rational(sp.diff(V, x).xreplace(dict.fromkeys(GAMMA, 0))) for x in GAMMA)
    Q = sp.Matrix(3, 3, lambda i, j: sp.Rational(sp.diff(V, GAMMA[i], GAMMA[j])) / 2)
    return a, Q


def second_moments(case: Case) -> sp.Matrix:
    """``S = sum m x x^T`` of any masses with the case's inertia: ``tr(S) delta - I``."""
    inertia = sp.diag(*case.inertia)
    return sp.eye(3) * inertia.trace() / 2 - inertia


def gradient_strength(case: Case) -> sp.Rational:
    """The f2 whose gradient field ``f2 (3 Z^2 - R^2)/2`` turns the case's second moments into
    its quadratic V: ``Q = (3 f2 / 2) S + c delta``; a one-line refusal when none does."""
    _, Q = quadratic_potential(case)
    S = second_moments(case)
    traceless_q = Q - sp.eye(3) * Q.trace() / 3
    traceless_s = S - sp.eye(3) * S.trace() / 3
    if traceless_q == sp.zeros(3, 3):
        return sp.Integer(0)
    ratios = {traceless_q[k] / traceless_s[k] for k in range(9) if traceless_s[k] != 0}
    if len(ratios) != 1 or traceless_q - next(iter(ratios)) * traceless_s != sp.zeros(3, 3):
        refuse_quadratic_mismatch(case.name)
    return sp.Rational(2, 3) * next(iter(ratios))


def mass_conditions(case: Case, g: float = STANDARD_GRAVITY) -> LinearConditions:
    """The masses' linear conditions for ``case`` in gravity ``legendre = [g, f2]``.

    ``g`` (m/s^2) is the uniform part, used when V has a linear part; f2 (1/s^2) is derived
    (:func:`gradient_strength`). The fields are in ``conditions.fields["gravity"]``.

    Raises
    ------
    InputError
        The case is not one masses realise (:func:`quadratic_potential`,
        :func:`gradient_strength`), or ``g`` is not > 0.
    InfeasibleError
        The inertia breaks a triangle inequality (a second moment would be negative).
    """
    g = as_finite_float(g, "g", positive=True)
    a, _ = quadratic_potential(case)
    f2 = gradient_strength(case)
    S = second_moments(case)
    second = {"xx": S[0, 0], "yy": S[1, 1], "zz": S[2, 2]}
    for key, value in second.items():
        if value < 0:
            raise InfeasibleError(
                f"case {case.name}: inertia {', '.join(map(str, case.inertia))} breaks a "
                f"triangle inequality (M_{key} = {value} < 0): no masses have it"
            )
    uniform = Fraction(repr(g)) if any(a) else Fraction(0)
    rows = [
        LinearCondition(
            "masses",
            {axis: 1.0},
            float(Fraction(str(value)) / uniform) if uniform else 0.0,
            f"V: f1 M x_cm . gamma = a . gamma gives M_{axis} = a_{axis} / f1",
        )
        for axis, value in zip("xyz", a, strict=True)
    ]
    rows += [
        LinearCondition("masses", {key: 1.0}, float(value), f"inertia: M_{key} = {value}")
        for key, value in second.items()
    ]
    rows += [
        LinearCondition("masses", {key: 1.0}, 0.0, f"inertia: product {key} is zero")
        for key in ("xy", "xz", "yz")
    ]
    legendre = (float(uniform), float(f2)) if f2 else (float(uniform),)
    return LinearConditions(
        conditions=rows,
        fields={"gravity": legendre},
        notes=[
            f"case {case.name}: masses in gravity legendre = {list(legendre)} realise V and "
            "the inertia" + (f" (f2 = {f2} from V's quadratic part)" if f2 else "")
        ],
        realise=("V", "inertia"),
        field_origin={"gravity": "derived"},
    )


__all__ = [
    "gradient_strength",
    "mass_conditions",
    "quadratic_potential",
    "second_moments",
]
