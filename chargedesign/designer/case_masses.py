"""A body of point masses for a case of (ep) that masses in uniform gravity realise.

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
the masses are designed by the designer's own problem (:func:`design_source`, ``m >= 0``,
polished). Other cases (a non-zero ``l``, a V of higher degree, singular terms) are refused
with the reason: they need charges, dipoles and fields of higher degree, which this module
does not derive yet.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp

from chargedesign.candidates import CandidateSet, candidates_from_points
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.designer.pipeline import design_source
from chargedesign.errors import InfeasibleError
from chargedesign.model.case import GAMMA
from chargedesign.moment_conditions import LinearCondition, LinearConditions
from chargedesign.results import Result
from chargedesign.scene.case_file import Case
from chargedesign.scene.case_refusals import (
    refuse_gyroscopic,
    refuse_mass_degree,
    refuse_quadratic_mismatch,
    refuse_singular_v,
)
from chargedesign.scene.design import DesignOptions
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


@dataclass(repr=False)
class CaseMassBody(Result):
    """Masses that realise a case in uniform gravity, with what they realise recomputed.

    Attributes
    ----------
    name : str
    positions : ndarray, shape (n, 3)
        m, body axes.
    masses : ndarray, shape (n,)
        kg, each > 0.
    gravity : tuple of float
        The gravity field's ``legendre`` coefficients (f1 in m/s^2, f2 in 1/s^2).
    inertia : ndarray, shape (3, 3)
        ``sum m (|x|^2 delta - x x^T)`` recomputed from the masses, kg m^2.
    potential : ndarray, shape (3,)
        ``f1 sum m x`` recomputed: the body's ``a`` of ``V = a . gamma + ...``, J.
    target_inertia, target_potential : ndarray
        The case's.
    """

    name: str
    positions: np.ndarray
    masses: np.ndarray
    gravity: tuple[float, ...]
    inertia: np.ndarray
    potential: np.ndarray
    target_inertia: np.ndarray
    target_potential: np.ndarray

    @property
    def inertia_rel_err(self) -> float:
        scale = float(np.max(np.abs(self.target_inertia)))
        return float(np.max(np.abs(self.inertia - self.target_inertia))) / scale

    @property
    def potential_err(self) -> float:
        """Largest error of ``a`` relative to the largest component of the case's ``a``."""
        scale = max(float(np.max(np.abs(self.target_potential))), 1e-300)
        return float(np.max(np.abs(self.potential - self.target_potential))) / scale

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "fields": {"gravity": {"legendre": list(self.gravity)}},
            "masses": {"positions": self.positions.tolist(), "values": self.masses.tolist()},
            "inertia": self.inertia.tolist(),
            "potential_linear": self.potential.tolist(),
            "inertia_rel_err": self.inertia_rel_err,
            "potential_err": self.potential_err,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "n_masses": len(self.masses),
            "total_mass_kg": float(self.masses.sum()),
            "inertia_rel_err": self.inertia_rel_err,
            "potential_err": self.potential_err,
        }


def inertia_of(positions: np.ndarray, masses: np.ndarray) -> np.ndarray:
    """``sum m (|x|^2 delta - x x^T)`` about O, kg m^2, shape (3, 3)."""
    squared = np.einsum("i,ij,ij->", masses, positions, positions)
    return np.eye(3) * squared - np.einsum("i,ij,ik->jk", masses, positions, positions)


def design_case_masses(
    case: Case,
    candidates: CandidateSet | np.ndarray,
    g: float = STANDARD_GRAVITY,
    options: DesignOptions | None = None,
) -> CaseMassBody:
    """Design point masses on ``candidates`` (m) that realise ``case`` in gravity (the uniform
    part ``g``, m/s^2; the gradient derived: :func:`mass_conditions`).

    Raises
    ------
    InputError, InfeasibleError, SolverError
    """
    conditions = mass_conditions(case, g)
    cand = (
        candidates if isinstance(candidates, CandidateSet) else candidates_from_points(candidates)
    )
    weights, _ = design_source("masses", conditions, cand, options or DesignOptions())
    keep = weights > 0
    positions, masses = cand.points[keep], weights[keep]
    gravity = tuple(conditions.fields["gravity"])
    a, _ = quadratic_potential(case)
    return CaseMassBody(
        name=case.name,
        positions=positions,
        masses=masses,
        gravity=gravity,
        inertia=inertia_of(positions, masses),
        potential=gravity[0] * masses @ positions,
        target_inertia=np.diag([float(m) for m in case.inertia]),
        target_potential=np.array([float(x) for x in a]),
    )


__all__ = [
    "CaseMassBody",
    "design_case_masses",
    "gradient_strength",
    "inertia_of",
    "mass_conditions",
    "quadratic_potential",
    "second_moments",
]
