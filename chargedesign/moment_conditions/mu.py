"""mu: the charges' gyroscopic vector matched with the theorem's on the sphere.

``mu = -sum q (r . B) r`` (``B = -grad Phi_m`` in body axes) is expanded with the charge
moments as unknowns, reduced on ``|gamma| = 1`` and matched coefficient by coefficient with
the theorem's mu in the harmonic basis; the linear system is solved exactly (rationals), or
symbolically for generic field coefficients (:func:`symbolic_mu_solution`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from typing import Any

from chargedesign.errors import InfeasibleError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.limits import MAX_FIELD_DEGREE
from chargedesign.moment_conditions.algebra import ConditionRow, SourceSystem, key_rank
from chargedesign.moment_conditions.context import DerivationContext
from chargedesign.moment_conditions.harmonics import (
    ParamPoly,
    body_coordinates,
    cartesian_split,
    field_symbols,
    gamma_poly,
    project_on_harmonics,
    real_solid_harmonics,
    sympy_symbols,
    zonal_solid_harmonic,
)
from chargedesign.moment_conditions.table_data import fraction_text, shipped_table
from chargedesign.moments import moment_keys
from chargedesign.validation import input_error


@dataclass(frozen=True)
class _MuEquation:
    """``sum_key (sum_k f_k coefficients[key][k]) I_key = rhs(params)`` for one harmonic of one
    component of mu, from coefficient matching on the sphere."""

    component: int
    harmonic: str
    coefficients: dict[str, dict[int, Fraction]]
    rhs: ParamPoly
    label: str

    def to_json(self) -> dict[str, Any]:
        """The equation as a row of the shipped table (exact fractions as text)."""
        return {
            "component": self.component,
            "harmonic": self.harmonic,
            "coefficients": {
                key: {str(k): fraction_text(c) for k, c in per_k.items()}
                for key, per_k in self.coefficients.items()
            },
            "rhs": self.rhs.to_json(),
            "label": self.label,
        }

    @classmethod
    def from_json(cls, row: Mapping[str, Any]) -> _MuEquation:
        """The equation of a row of the shipped table (:meth:`to_json`)."""
        coefficients = {
            key: {int(k): Fraction(c) for k, c in per_k.items()}
            for key, per_k in row["coefficients"].items()
        }
        rhs = ParamPoly.from_json(row["rhs"])
        return cls(row["component"], row["harmonic"], coefficients, rhs, row["label"])


@cache
def physical_mu_rows(
    degree: int, kmax: int
) -> tuple[dict[str, dict[str, dict[int, Fraction]]], ...]:
    """The charges' ``mu = -sum q (r . B) r`` on the sphere in the harmonic basis up to
    ``kmax``, per component: ``{harmonic label: {moment key: {k: coefficient of f_k}}}``
    (symbolic field coefficients f_1..f_degree; cached)."""
    import sympy as sp

    x, y, z, Z, S = body_coordinates()
    fs = field_symbols(degree)
    phi = sum(f * zonal_solid_harmonic(k, Z, S) for k, f in enumerate(fs, start=1))
    B = [-sp.diff(phi, v) for v in (x, y, z)]
    r_dot_B = x * B[0] + y * B[1] + z * B[2]
    out = []
    for ra in (x, y, z):
        physical = cartesian_split(-r_dot_B * ra)
        rows: dict[str, dict[str, dict[int, Fraction]]] = {}
        for key, per_k in physical.items():
            for k, gpoly in per_k.items():
                for label, coef in project_on_harmonics(gpoly, kmax).items():
                    rows.setdefault(label, {}).setdefault(key, {})[k] = coef
        out.append(rows)
    return tuple(out)


@cache
def mu_system(degree: int) -> tuple[_MuEquation, ...]:
    """The coefficient-matching equations of the charges' mu for a magnetic field of
    ``degree`` (symbolic field coefficients f_1..f_degree; cached per degree).

    Read from the shipped table up to ``MAX_FIELD_DEGREE`` (the same as
    :func:`derive_mu_system`, which the tests check exactly), derived otherwise.
    """
    table = shipped_table("mu_system")
    if table is not None and str(degree) in table:
        return tuple(_MuEquation.from_json(row) for row in table[str(degree)])
    return derive_mu_system(degree)


@cache
def derive_mu_system(degree: int) -> tuple[_MuEquation, ...]:
    """The equations of :func:`mu_system`, derived with sympy (the shipped table's source).

    ``mu = -sum q (r . B) r`` with ``B = -grad Phi``, ``Phi = sum_k f_k R^k P_k(r . gamma / R)``
    in body axes; the moments ``I_key = sum q x^i y^j z^l`` are the unknowns. Both sides are
    reduced on ``|gamma| = 1`` and written in the harmonic basis (an invertible change of
    basis of the reduced monomials, which separates the equations by moment order).
    """
    import sympy as sp

    from chargedesign.model.case import symbolic_case

    kmax = max(degree, 2)
    target = symbolic_case().mu
    equations = []
    for a, rows in enumerate(physical_mu_rows(degree, kmax)):
        theorem = project_on_harmonics(gamma_poly(target[a]), kmax)
        harmonics = {h.label: h for kk in range(kmax + 1) for h in real_solid_harmonics(kk)}
        for label in [h.label for kk in range(kmax + 1) for h in real_solid_harmonics(kk)]:
            if label not in rows and label not in theorem:
                continue
            rhs = ParamPoly.from_sympy(theorem.get(label, sp.Integer(0)))
            h = harmonics[label]
            text = (
                f"mu_{a + 1}: coefficient of the degree-{h.degree} harmonic {h.text} "
                f"(theorem: {rhs.text})"
            )
            equations.append(_MuEquation(a, label, rows.get(label, {}), rhs, text))
    return tuple(equations)


def charges_for_mu(ctx: DerivationContext) -> None:
    """Add the charges' mu conditions for the magnetic field in use (exact, reported reduced)."""
    magnetic = ctx.fields.get("magnetic", [])
    # the n terms need charges in the uniform field a1, the K terms in the quadrupole a2
    for name, k, where in (("n", 1, "a uniform magnetic field"), ("K", 2, "a magnetic quadrupole")):
        value = getattr(ctx.params, name)
        if value != 0 and ctx.coefficient("magnetic", k) == 0:
            raise InfeasibleError(
                f"fields.magnetic: a{k} = 0 while {name} = {fmt(value, PLAIN)} != 0: the {name} "
                f"terms of mu need charges in {where} (a{k} != 0)"
            )
    degree = max(len(magnetic), 1)
    system = ctx.systems["charges"]
    rows = (
        (field_weighted(eq.coefficients, magnetic), eq.rhs(ctx.P), eq.label)
        for eq in mu_system(degree)
    )
    solve_mu(system, rows, "mu cannot be realised by charges in this magnetic field: ")
    ctx.notes.append(
        f"charges: mu matched on |gamma| = 1 for a magnetic field of degree {degree}: "
        f"{len(system.pivots)} independent conditions on the moments of orders 2..{degree + 1}"
    )
    ctx.notes.append(
        "charges: their canonical angular momentum about Z, sum q psi (natural axisymmetric "
        "gauge), then equals the theorem's l . gamma on |gamma| = 1, constant 2 n C included "
        "(l_dot_gamma_residual)"
    )


def field_weighted(
    coefficients: Mapping[str, Mapping[int, Fraction]], magnetic: Sequence[Fraction]
) -> dict[str, Fraction]:
    """Each moment's coefficient in a mu equation for the magnetic field in use: ``sum_k f_k
    c_k`` over the degrees k the field has (``coefficients``: moment key -> {k: c_k})."""
    return {
        key: sum((magnetic[k - 1] * c for k, c in per_k.items() if k <= len(magnetic)), Fraction(0))
        for key, per_k in coefficients.items()
    }


def solve_mu(
    system: SourceSystem, rows: Iterable[tuple[dict[str, Fraction], Fraction, str]], refusal: str
) -> None:
    """Add the mu equations ``(coefficients, value, provenance)`` to the charges' exact
    system, then display its reduced rows; an equation inconsistent with those before it is
    refused (``refusal`` and the combination of equations that shows it)."""
    for coeffs, rhs, text in rows:
        status, combo = system.add(coeffs, rhs, text)
        if status == "inconsistent":
            raise InfeasibleError(refusal + system._describe(combo))
    for pivot in sorted(system.pivots, key=key_rank):
        row, rhs, combo = system.pivots[pivot]
        system.display.append(ConditionRow(dict(row), rhs, system._describe(combo)))


def moment_symbol(key: str) -> Any:
    """The charge moment ``I_key`` as a real sympy symbol (``I_xyz``)."""
    import sympy as sp

    return sp.Symbol(f"I_{key}", real=True)


def check_mu_degree(degree: Any) -> int:
    """The field degree of the symbolic mu solution: an integer in 2..MAX_FIELD_DEGREE
    (degree 1 cannot give the K terms of mu: they need a magnetic quadrupole)."""
    if (
        isinstance(degree, bool)
        or not isinstance(degree, int)
        or not 2 <= degree <= MAX_FIELD_DEGREE
    ):
        raise input_error("degree", f"an integer in 2..{MAX_FIELD_DEGREE}", degree)
    return degree


def symbolic_mu_solution(degree: int = 2) -> dict[str, Any]:
    """The charges' moments that realise mu, for symbolic parameters and field coefficients.

    Solves the coefficient-matching equations of :func:`mu_system` with ``sympy.linsolve``
    for generic (non-zero) ``f_1 .. f_degree`` (symbols ``f1, f2, ...``), degree >= 2 (a
    field of degree 1 cannot give the K terms). Moments left free appear as themselves.

    Returns
    -------
    dict[str, sympy.Expr]
        ``{moment key: expression}`` for every moment of orders 2..degree+1.
    """

    return dict(_symbolic_mu_solution(check_mu_degree(degree)))


@cache
def _symbolic_mu_solution(degree: int) -> tuple[tuple[str, Any], ...]:
    import sympy as sp

    fs = field_symbols(degree)
    params = sympy_symbols()["params"]
    keys = [k for order in range(2, degree + 2) for k in moment_keys(order)]
    symbols = [moment_symbol(k) for k in keys]
    equations = []
    for eq in mu_system(degree):
        lhs = sum(
            sum(fs[k - 1] * sp.Rational(c.numerator, c.denominator) for k, c in per_k.items())
            * moment_symbol(key)
            for key, per_k in eq.coefficients.items()
        )
        rhs = sum(
            sp.Rational(c.numerator, c.denominator)
            * sp.Mul(*[p**e for p, e in zip(params, exps, strict=True)])
            for exps, c in eq.rhs.terms
        )
        equations.append(sp.expand(lhs - rhs))
    solutions = sp.linsolve(equations, symbols)
    if not solutions:  # pragma: no cover - mu is always realisable for generic fields
        raise InfeasibleError("mu has no symbolic solution")
    (solution,) = list(solutions)
    return tuple((key, sp.factor(value)) for key, value in zip(keys, solution, strict=True))
