"""A body of point masses for a case of (ep) that masses in uniform gravity realise.

The first step of designing any case (the workbench issue, item 4): a case whose ``l`` is zero
and whose ``V`` is linear in gamma, ``V = v0 + a . gamma`` (the heavy top: Euler, Lagrange,
Kowalevski, Goriachev-Chaplygin), is realised by masses alone in the uniform gravity
``Phi_g = g Z`` (contract: ``legendre = [g]``). A mass m at body point x has energy
``m g Z = m g (x . gamma)``, so the body's potential is ``g M x_cm . gamma`` and its inertia
about O is ``sum m (|x|^2 delta - x x^T)``. The linear conditions on the masses' moments:

- first moments ``sum m x = a / g`` (the centre of mass gives exactly the case's V, up to the
  constant v0);
- second moments ``sum m x_i x_j = S_ij`` with ``S = tr(S) delta - I``, i.e.
  ``S_xx = (B + C - A)/2`` (and cyclic), products zero (principal axes).

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
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.model.case import GAMMA
from chargedesign.model.case_file import Case
from chargedesign.moment_conditions import LinearCondition, LinearConditions
from chargedesign.results import Result
from chargedesign.scene.design import DesignOptions
from chargedesign.validation import as_finite_float


def linear_potential(case: Case) -> tuple[sp.Rational, ...]:
    """``a`` of ``V = v0 + a . gamma`` (exact), or a one-line refusal naming why masses in
    uniform gravity cannot realise the case."""
    if case.l is None or any(sp.expand(component) != 0 for component in case.l):
        raise InputError(
            f"case {case.name}: l is not zero; masses realise no gyroscopic forces (charges in "
            "a magnetic field would: not derived for a general case yet)"
        )
    V = sp.expand(case.V)
    if not V.is_polynomial(*GAMMA):
        raise InputError(
            f"case {case.name}: V is singular ({sp.sstr(V)[:60]}); no field realises it"
        )
    degree = sp.Poly(V, *GAMMA).total_degree() if V.free_symbols else 0
    if degree > 1:
        raise InputError(
            f"case {case.name}: V has degree {degree} in gamma; masses in uniform gravity "
            "realise degree 1 only (higher degrees need fields of that degree: not yet)"
        )
    return tuple(sp.Rational(V.coeff(x, 1)) for x in GAMMA)


def mass_conditions(case: Case, g: float = STANDARD_GRAVITY) -> LinearConditions:
    """The masses' linear conditions for ``case`` in uniform gravity ``g`` (m/s^2).

    Raises
    ------
    InputError
        The case is not one masses realise (:func:`linear_potential`), or ``g`` is not > 0.
    InfeasibleError
        The inertia breaks a triangle inequality (a second moment would be negative).
    """
    g = as_finite_float(g, "g", positive=True)
    a = linear_potential(case)
    A, B, C = case.inertia
    second = {"xx": (B + C - A) / 2, "yy": (C + A - B) / 2, "zz": (A + B - C) / 2}
    for key, value in second.items():
        if value < 0:
            raise InfeasibleError(
                f"case {case.name}: inertia {A}, {B}, {C} breaks a triangle inequality "
                f"(M_{key} = {value} < 0): no masses have it"
            )
    rows = [
        LinearCondition(
            "masses",
            {axis: 1.0},
            float(Fraction(str(value)) / Fraction(repr(g))),
            f"V: g M x_cm . gamma = a . gamma gives M_{axis} = a_{axis} / g",
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
    return LinearConditions(
        conditions=rows,
        fields={"gravity": (g,)},
        notes=[f"case {case.name}: masses in uniform gravity g = {g} m/s^2 realise V and I"],
        realise=("V", "inertia"),
        field_origin={"gravity": "given"},
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
    g : float
        m/s^2.
    inertia : ndarray, shape (3, 3)
        ``sum m (|x|^2 delta - x x^T)`` recomputed from the masses, kg m^2.
    potential : ndarray, shape (3,)
        ``g sum m x`` recomputed: the body's ``a`` of ``V = a . gamma``, J.
    target_inertia, target_potential : ndarray
        The case's.
    """

    name: str
    positions: np.ndarray
    masses: np.ndarray
    g: float
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
            "g": self.g,
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
    """Design point masses on ``candidates`` (m) that realise ``case`` in uniform gravity.

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
    g_value = conditions.fields["gravity"][0]
    return CaseMassBody(
        name=case.name,
        positions=positions,
        masses=masses,
        g=g_value,
        inertia=inertia_of(positions, masses),
        potential=g_value * masses @ positions,
        target_inertia=np.diag([float(m) for m in case.inertia]),
        target_potential=np.array([float(x) for x in linear_potential(case)]),
    )


__all__ = [
    "CaseMassBody",
    "design_case_masses",
    "inertia_of",
    "linear_potential",
    "mass_conditions",
]
