"""A case of (ep) -> linear moment conditions: the engine opened to any polynomial V and mu.

The theorem's derivation (:func:`~chargedesign.moment_conditions.derive_conditions`) matches
the theorem's mu and V in the harmonic basis on ``|gamma| = 1``. Here the targets are a case's
own (:class:`chargedesign.scene.case_file.Case`): its ``V``, its ``mu`` (from ``l`` by (mu))
and its inertia ``diag(A, B, C)``, exact rationals. The same steps run on the same exact
systems:

- **mu** (charges in the magnetic field, ``mu = -sum q (r . B) r``): the degree-k field term
  ``f_k R^k P_k`` gives ``mu_a`` the pure degree-k harmonic ``k f_k sum_m w_km (sum q r_a
  H_km(r)) H_km(gamma)``: every degree k >= 1 of mu needs ``f_k != 0`` and fixes moments of
  order k + 1. A constant (degree-0) part of mu (a gyrostat's rotor) has no such source.
- **V**: degree k of V is ``sum_m w_km W_km H_km(gamma)`` times ``f_k`` of the field the source
  feels (addition theorem): charges ``q Phi_e`` (electric ``e_k``), dipoles ``-sigma . B``
  (magnetic ``f_k``, order-(k-1) dipole moments), masses ``m Phi_g`` (gravity ``g_k``). Degree 1
  prefers masses in uniform gravity, degree 2 masses in a gravity gradient (when the inertia's
  second moments give it), then dipoles in the magnetic quadrupole, then charges in an
  electric quadrupole; degrees 3 and 4 charges in electric ``e_k`` (strength forced by mu, or
  chosen for the body's size), then dipoles, then masses.
- **inertia**: masses with ``M_xx = (B + C - A)/2`` (cyclic), products zero.

Bounded: V and mu of degree at most :data:`CASE_MAX_DEGREE` in gamma. Refused in one line, with
the term named: a singular (rational) term, a degree above the bound, a constant mu, a term
no field in use produces.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.errors import InfeasibleError
from chargedesign.moment_conditions.algebra import SourceSystem
from chargedesign.moment_conditions.context import DerivationContext, decimal_text
from chargedesign.moment_conditions.derive import close_derivation, open_derivation
from chargedesign.moment_conditions.harmonics import (
    gamma_poly,
    project_on_harmonics,
    real_solid_harmonics,
)
from chargedesign.moment_conditions.mu import field_weighted, physical_mu_rows, solve_mu
from chargedesign.moment_conditions.potential import proportionality, realise_degree
from chargedesign.moment_conditions.types import LinearConditions
from chargedesign.params import Parameters
from chargedesign.scene.case_refusals import refuse_free_symbol

#: highest degree in gamma of a case's V and of each component of its mu that the engine takes
#: (degree 4 in mu needs a magnetic hexadecapole f4; the exact derivation grows like degree^3)
CASE_MAX_DEGREE = 4
#: the magnetic strength derived for each degree of mu a case needs (T / m^(k-1)), and for the
#: dipoles' quadrupole when V's degree 2 needs it (legendre f2 = 1 T/m: a2 = 0.5 T/m)
CASE_MAGNETIC_STRENGTH = 1.0
#: which source realises each degree of V of a case, in order of preference
CASE_PREFERENCE: dict[int, tuple[str, ...]] = {
    1: ("masses", "charges", "dipoles"),
    2: ("masses", "dipoles", "charges"),
}


@dataclass(frozen=True)
class CaseTarget:
    """A case's targets on the sphere, exact: V and each component of mu in the harmonic
    basis (label -> coefficient), the inertia, and the degrees."""

    name: str
    inertia: tuple[Fraction, Fraction, Fraction]
    v: dict[str, Fraction]
    mu: tuple[dict[str, Fraction], dict[str, Fraction], dict[str, Fraction]]
    v_degree: int
    mu_degree: int

    @property
    def has_mu(self) -> bool:
        return any(self.mu)

    def v_harmonics(self, k: int) -> list[Fraction]:
        return [self.v.get(h.label, Fraction(0)) for h in real_solid_harmonics(k)]


def _fraction(value: Any) -> Fraction:
    import sympy as sp

    rational = sp.Rational(value)
    return Fraction(int(rational.p), int(rational.q))


def _polynomial_part(expr: Any, what: str, name: str) -> tuple[Any, int]:
    """``expr`` as a polynomial in gamma with rational coefficients and its degree, or the
    one-line refusal naming the first term that is not (singular, or too high a degree)."""
    import sympy as sp

    from chargedesign.model.case import GAMMA

    expanded = sp.expand(expr)
    for term in sp.Add.make_args(expanded):
        if not term.is_polynomial(*GAMMA):
            raise InfeasibleError(
                f"case {name}: {what} has the singular term {sp.sstr(term)[:60]}: no "
                "gravitational, electric or magnetic field realises it (finite charges, dipoles "
                "and masses give a polynomial in gamma)"
            )
        if term.free_symbols - set(GAMMA):
            refuse_free_symbol(name, what, sp.sstr(term))
    if expanded == 0:
        return expanded, 0
    poly = sp.Poly(expanded, *GAMMA)
    for monomial, coef in poly.terms():
        if sum(monomial) > CASE_MAX_DEGREE:
            term = coef * sp.Mul(*[g**e for g, e in zip(GAMMA, monomial, strict=True)])
            raise InfeasibleError(
                f"case {name}: {what} has the term {sp.sstr(term)[:60]} of degree "
                f"{sum(monomial)} in gamma; designs take degree <= {CASE_MAX_DEGREE}"
            )
    return expanded, poly.total_degree()


def _on_sphere(expanded: Any, degree: int) -> dict[str, Fraction]:
    """A polynomial in gamma of ``degree`` on the sphere in the harmonic basis (label ->
    exact coefficient); a constant is the degree-0 harmonic ``0,0c``."""
    if not degree:
        return {"0,0c": _fraction(expanded)} if expanded != 0 else {}
    projected = project_on_harmonics(gamma_poly(expanded), degree)
    return {label: _fraction(c) for label, c in projected.items()}


def case_target(case: Any) -> CaseTarget:
    """The exact targets of a case (:class:`chargedesign.scene.case_file.Case`), or a one-line
    refusal of a singular term or a degree above :data:`CASE_MAX_DEGREE`."""
    V, v_degree = _polynomial_part(case.V, "V", case.name)
    mus = []
    mu_degree = 0
    for a, component in enumerate(case.mu):
        expanded, degree = _polynomial_part(component, f"mu_{a + 1}", case.name)
        mu_degree = max(mu_degree, degree)
        mus.append(_on_sphere(expanded, degree))
    v = _on_sphere(V, v_degree) if v_degree else {}  # a constant V acts on nothing
    inertia = tuple(_fraction(m) for m in case.inertia)
    return CaseTarget(
        name=case.name,
        inertia=(inertia[0], inertia[1], inertia[2]),
        v=v,
        mu=(mus[0], mus[1], mus[2]),
        v_degree=v_degree,
        mu_degree=mu_degree,
    )


def _mu_degrees(target: CaseTarget) -> set[int]:
    return {int(label.split(",")[0]) for component in target.mu for label in component}


def _masses_second_moments(target: CaseTarget) -> dict[str, Fraction]:
    A, B, C = target.inertia
    return {"xx": (B + C - A) / 2, "yy": (C + A - B) / 2, "zz": (A + B - C) / 2}


def _masses_give_degree_two(target: CaseTarget) -> bool:
    """Whether the inertia's second moments, in a gravity gradient, give V's degree-2 part
    (the masses' degree-2 harmonic moments proportional to it)."""
    second = _masses_second_moments(target)
    fixed = [
        sum((c * second.get(key, Fraction(0)) for key, c in h.moments().items()), Fraction(0))
        for h in real_solid_harmonics(2)
    ]
    wanted = [
        v / h.weight for v, h in zip(target.v_harmonics(2), real_solid_harmonics(2), strict=True)
    ]
    if not any(fixed):
        return not any(wanted)
    return proportionality(fixed, wanted) is not None


def _derived_magnetic(target: CaseTarget) -> list[Fraction]:
    degrees = _mu_degrees(target) - {0}
    if any(target.v_harmonics(2)) and not _masses_give_degree_two(target):
        degrees.add(2)  # dipoles in the quadrupole (they feel no Lorentz force)
    strength = Fraction(CASE_MAGNETIC_STRENGTH)
    return [
        strength if k in degrees else Fraction(0) for k in range(1, max(degrees, default=0) + 1)
    ]


def _charges_for_case_mu(ctx: DerivationContext, target: CaseTarget) -> None:
    """The charges' mu conditions: the case's mu matched harmonic by harmonic (exact)."""
    magnetic = ctx.fields.get("magnetic", [])
    degree = max(len(magnetic), 1)
    system = ctx.systems["charges"]
    refusal = f"case {target.name}: mu cannot be realised by charges in this magnetic field: "
    solve_mu(system, _case_mu_rows(target, magnetic, degree), refusal)
    ctx.notes.append(
        f"charges: the case's mu matched on |gamma| = 1 for a magnetic field of degree "
        f"{degree}: {len(system.pivots)} independent conditions"
    )


def _case_mu_rows(
    target: CaseTarget, magnetic: list[Fraction], degree: int
) -> Iterator[tuple[dict[str, Fraction], Fraction, str]]:
    """The case's mu equations, harmonic by harmonic: a term no charge in the field gives is
    refused (one line naming it)."""
    kmax = max(degree, target.mu_degree, 2)
    harmonics = [h for kk in range(kmax + 1) for h in real_solid_harmonics(kk)]
    for a, rows in enumerate(physical_mu_rows(degree, kmax)):
        wanted = target.mu[a]
        for h in harmonics:
            if h.label not in rows and h.label not in wanted:
                continue
            coeffs = field_weighted(rows.get(h.label, {}), magnetic)
            rhs = wanted.get(h.label, Fraction(0))
            if rhs != 0 and not any(coeffs.values()):
                raise InfeasibleError(
                    f"case {target.name}: mu_{a + 1} has the degree-{h.degree} term "
                    f"{decimal_text(rhs)} * ({h.text}), which charges in fields.magnetic "
                    "cannot give: "
                    + (
                        "a constant mu is a gyrostat's rotor (stored angular momentum), not a "
                        "field's force"
                        if h.degree == 0
                        else f"it needs a magnetic term of degree {h.degree} (legendre["
                        f"{h.degree - 1}] != 0)"
                    )
                )
            text = (
                f"mu_{a + 1}: coefficient of the degree-{h.degree} harmonic {h.text} (case: {rhs})"
            )
            yield coeffs, rhs, text


def _masses_for_case_inertia(ctx: DerivationContext, target: CaseTarget) -> None:
    system = ctx.systems["masses"]
    A, B, C = target.inertia
    second = _masses_second_moments(target)
    formula = {"xx": "(B + C - A)/2", "yy": "(C + A - B)/2", "zz": "(A + B - C)/2"}
    for key, value in second.items():
        if value < 0:
            raise InfeasibleError(
                f"case {target.name}: inertia {A}, {B}, {C} breaks a triangle inequality "
                f"(M_{key} = {value} < 0): no masses have it"
            )
        system.add_display(
            {key: Fraction(1)}, value, f"inertia: M_{key} = {formula[key]} = {value}"
        )
    for key in ("xy", "xz", "yz"):
        system.add_display(
            {key: Fraction(1)}, Fraction(0), f"inertia: product of inertia {key} is zero"
        )
    ctx.notes.append(
        "masses: nonnegative values are the design stage's job (not a linear condition)"
    )


def derive_case_conditions(
    case: Any,
    fields: Mapping[str, Sequence[float]] | None = None,
    *,
    length: float | None = None,
) -> LinearConditions:
    """Linear moment conditions that realise a case's mu, V and inertia (exact).

    Parameters
    ----------
    case : chargedesign.scene.case_file.Case
        Its V and mu polynomial in gamma of degree <= :data:`CASE_MAX_DEGREE`.
    fields : mapping, optional
        Given fields (``legendre`` per kind, read as the decimals they print as). A kind
        not given is derived: magnetic ``f_k = 1`` for each degree k of mu (and f2 for the
        dipoles when V's degree 2 needs them), gravity standard ``g`` when V has a linear
        part and a gradient when the inertia's second moments give V's degree 2, electric
        forced by mu or chosen for the body's ``length`` (m).

    Raises
    ------
    InfeasibleError
        A singular term, a degree above the bound, a constant mu, or a term no field in use
        produces (one line naming it).
    InputError
        Malformed fields or length.
    """
    target = case_target(case)
    for a, component in enumerate(target.mu):
        if "0,0c" in component:
            raise InfeasibleError(
                f"case {target.name}: mu_{a + 1} has the constant term "
                f"{component['0,0c']}: a constant mu is a gyrostat's rotor (stored angular "
                "momentum); charges in a static field give mu of degree >= 1 in gamma only"
            )
    given, ctx = open_derivation(
        Parameters.from_mapping({"C": float(target.inertia[2])}, "case.inertia[2]"),
        [],
        fields,
        length,
        exact=True,
        v_target={label: (value, str(value)) for label, value in target.v.items()},
        preference=CASE_PREFERENCE,
    )
    if "magnetic" not in given:
        ctx.fields["magnetic"] = _derived_magnetic(target)
    if "gravity" not in given and any(target.v_harmonics(1)):
        ctx.fields["gravity"] = [Fraction(repr(STANDARD_GRAVITY))]
    # charges: for mu, for V's degrees 3 and 4, and as the last resort for its degree 2
    needs_charges = (
        target.has_mu
        or target.v_degree >= 3
        or bool(given.get("electric"))
        or (any(target.v_harmonics(2)) and not _masses_give_degree_two(target))
    )
    if needs_charges:
        ctx.systems["charges"] = SourceSystem()
    if any(ctx.fields["magnetic"]):
        ctx.systems["dipoles"] = SourceSystem()
    ctx.systems["masses"] = SourceSystem()
    if target.has_mu:
        if not any(ctx.fields["magnetic"]):
            raise InfeasibleError(
                f"case {target.name}: mu is not zero but fields.magnetic is: charges need a "
                "magnetic field for gyroscopic forces"
            )
        _charges_for_case_mu(ctx, target)
    _masses_for_case_inertia(ctx, target)
    kmax = max(
        target.v_degree,
        len(ctx.fields["magnetic"]),
        len(ctx.fields["electric"]),
        len(ctx.fields["gravity"]),
    )
    for k in range(1, kmax + 1):
        ctx.derivable = {"electric"} if "electric" not in given and needs_charges else set()
        if k >= 2 and "gravity" not in given:
            ctx.derivable.add("gravity")
        realise_degree(ctx, k)
    realise = ("mu", "V", "inertia") if target.has_mu else ("V", "inertia")
    return close_derivation(ctx, realise, functools.partial(derive_case_conditions, case, fields))


__all__ = [
    "CASE_MAGNETIC_STRENGTH",
    "CASE_MAX_DEGREE",
    "CASE_PREFERENCE",
    "CaseTarget",
    "case_target",
    "derive_case_conditions",
]
