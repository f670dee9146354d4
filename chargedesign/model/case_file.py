"""Any case of the Euler-Poisson problem (ep), from a ``[case]`` table read and validated by
:mod:`chargedesign.scene.case_file`, and its exact certificate (``chargedesign verify
CASE.toml``).

A case is the inertia ``diag(A, B, C)``, the potential ``V(gamma)``, the vector potential
``l(gamma)`` (``mu`` follows by the paper's (mu), :func:`chargedesign.model.case.mu_from_l`)
or ``mu(gamma)`` itself, a claimed integral ``F(p, q, r, gamma)`` and the level on which it is
claimed: ``"general"`` or a value of ``I3 = (I omega + l) . gamma``. The equations are
:func:`chargedesign.model.equations.euler_poisson`, the theorem's, opened to any case.

The certificate (exact rational arithmetic; parameters enter as the exact rationals of
their decimal text):

1. Every function is a quotient of polynomials in ``QQ[p, q, r, gamma1, gamma2, gamma3]``
   (rational expressions such as Goriachev's ``1/gamma3**2`` are allowed). With
   ``F = N/D`` and the right-hand sides ``x_k' = a_k / b_k``, ``B = lcm(b_k)``,
   ``dF/dt = W / (D^2 B)``, ``W = sum_k (D dN/dx_k - N dD/dx_k) a_k B / b_k``.
2. On a level ``I3 = h``, ``r = s / t`` (I3 is linear in r, ``t = C gamma3`` times the
   denominator of ``l . gamma``) and ``P = t^m W(r = s/t)``; for a general claim ``P = W``.
3. ``P`` is reduced modulo the sphere, ``P = N_s (|gamma|^2 - 1) + R0`` with ``R0`` of degree
   <= 1 in gamma1 (:func:`chargedesign.model.certificate.sphere_normal_form`). The sphere's
   ideal is prime and its real points are Zariski-dense, so ``dF/dt`` vanishes on the
   sphere (and level) wherever it is defined iff ``R0 = 0``; the identity
   ``P = N_s (|gamma|^2 - 1)`` is re-multiplied as a witness.
4. When ``R0 != 0``: an exact rational state (gamma by the stereographic parametrisation,
   ``|gamma|^2 = 1`` exactly; r from the level) where ``dF/dt`` is not zero, with its value.
5. Independence: the exact rank of ``d(H, |gamma|^2, I3, F)/d(state)`` at rational points of
   the sphere (and level) is 4.
6. For all parameters: steps 1-3 again with every non-zero parameter kept as a symbol, the
   coefficients in the rational functions ``QQ(parameters)`` (zero parameters stay zero: they
   switch terms off, as the theorem's special cases do). ``R0 = 0`` there proves the claim
   for all parameter values where the expressions are defined.

Where the case is singular (the zero sets of its denominators) is reported, and a
denominator that vanishes on the whole sphere (or level) is refused.
"""

from __future__ import annotations

import os
import random
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import sympy as sp
from sympy.polys.rings import PolyElement, PolyRing

from chargedesign.formatting import CELL, fmt
from chargedesign.model.case import GAMMA, STATE_SYMBOLS, g1, g2, g3, p, q, r
from chargedesign.model.certificate import U, sphere_normal_form, split_by_power
from chargedesign.model.equations import euler_poisson
from chargedesign.results import Result
from chargedesign.scene.case_file import (
    Case,
    check_certificate_work,
    check_denominator_on_level,
    check_rational_points,
    read_case,
)

STATE = STATE_SYMBOLS
#: position of r among the ring's generators
_R_INDEX = 2


def case_equations(case: Case) -> sp.Matrix:
    """The right-hand sides of (ep), ``(p', q', r', gamma1', gamma2', gamma3')``."""
    return euler_poisson(sp.diag(*case.inertia), case.V, case.mu)


def verify_case_file(path: str | os.PathLike[str]) -> CaseCertificate:
    """Read ``path`` (its ``[case]`` table, :func:`chargedesign.scene.case_file.read_case`)
    and certify the claim."""
    return certify_case(read_case(path))


# ------------------------------------------------------------------- the exact arithmetic


@lru_cache(maxsize=16)
def case_ring(parameters: tuple[sp.Symbol, ...] = ()) -> PolyRing:
    """``K[p, q, r, gamma1, gamma2, gamma3, u]`` laid out as the theorem's ring (so the
    certificate's helpers apply), over ``K = QQ`` (parameters are exact numbers) or over the
    rational functions ``QQ(parameters)`` (parameters kept free)."""
    domain = sp.QQ.frac_field(*parameters) if parameters else sp.QQ
    ring, *_ = sp.ring((*STATE, U), domain)
    return ring


def ring_of(case: Case) -> PolyRing:
    """The ring of a case's expressions: over QQ, or over QQ(its free parameters)."""
    parts = [case.V, case.integral, *case.mu, *case.inertia]
    if case.level is not None:
        parts += [case.level, case.l_dot_gamma]
    symbols = set().union(*(sp.sympify(e).free_symbols for e in parts)) - set(STATE)
    return case_ring(tuple(sorted(symbols, key=str)))


def as_fraction(expr: sp.Expr, ring: PolyRing | None = None) -> tuple[PolyElement, PolyElement]:
    """``expr = N / D`` with ``N, D`` polynomials of ``ring`` (default :func:`case_ring`)."""
    numerator, denominator = sp.fraction(sp.together(sp.expand(expr)))
    ring = ring or case_ring()
    return ring.from_expr(sp.expand(numerator)), ring.from_expr(sp.expand(denominator))


@dataclass(frozen=True)
class _Flow:
    """The right-hand sides ``a_k / b_k`` and ``B = lcm(b_k)``."""

    numerators: tuple[PolyElement, ...]
    denominators: tuple[PolyElement, ...]
    common: PolyElement


def _flow(case: Case, ring: PolyRing) -> _Flow:
    pairs = [as_fraction(e, ring) for e in case_equations(case)]
    common = ring.one
    for _, b in pairs:
        common = common.lcm(b)
    return _Flow(tuple(a for a, _ in pairs), tuple(b for _, b in pairs), common)


def derivative_numerator(fraction: tuple[PolyElement, PolyElement], flow: _Flow) -> PolyElement:
    """``W`` with ``d(N/D)/dt = W / (D^2 B)`` along the flow (exact, in :func:`case_ring`)."""
    numerator, denominator = fraction
    gens = numerator.ring.gens
    total = numerator.ring.zero
    for k in range(6):
        slope = denominator * numerator.diff(gens[k]) - numerator * denominator.diff(gens[k])
        if slope:
            total += slope * flow.numerators[k] * flow.common.exquo(flow.denominators[k])
    return total


def _r_on_level(case: Case, ring: PolyRing) -> tuple[PolyElement, PolyElement]:
    """``r = s / t`` on ``I3 = level``: ``t = C gamma3 L_d``, ``l . gamma = L_n / L_d``."""
    assert case.level is not None
    ln, ld = as_fraction(case.l_dot_gamma, ring)
    A, B, C = (ring.domain.from_sympy(m) for m in case.inertia)
    level = ring.domain.from_sympy(case.level)
    P, Q, _, G1, G2, G3, _ = ring.gens
    s = ld * (level - A * P * G1 - B * Q * G2) - ln
    t = C * G3 * ld
    return s, t


def _substitute_r(element: PolyElement, s: PolyElement, t: PolyElement) -> PolyElement:
    """``t^m element(r = s/t)``, ``m`` the degree of ``element`` in r."""
    parts = split_by_power(element, _R_INDEX, 1)
    top = max(parts, default=0)
    return sum((c * s**k * t ** (top - k) for k, c in parts.items()), start=element.ring.zero)


def _evaluate(element: PolyElement, values: Mapping[sp.Symbol, Any]) -> sp.Rational:
    ring = case_ring()
    pairs = [(ring.gens[i], ring.domain.from_sympy(values[s])) for i, s in enumerate(STATE)]
    pairs.append((ring.gens[6], ring.domain.zero))
    return sp.Rational(ring.domain.to_sympy(element.evaluate(pairs)))


#: seed of the rational states tried (deterministic: the same case gives the same points)
STATE_SEED = 2026


def _small_rational(draw: random.Random) -> sp.Rational:
    return sp.Rational(draw.randint(-6, 6), draw.randint(1, 7))


def sphere_point(s1: sp.Rational, s2: sp.Rational) -> tuple[sp.Rational, ...]:
    """The stereographic point ``(2 s1, 2 s2, 1 - s1^2 - s2^2) / (1 + s1^2 + s2^2)``: exact,
    on the unit sphere."""
    norm = 1 + s1**2 + s2**2
    return (2 * s1 / norm, 2 * s2 / norm, (1 - s1**2 - s2**2) / norm)


def rational_states(case: Case, limit: int = 64) -> list[dict[sp.Symbol, sp.Rational]]:
    """Exact rational states on the unit sphere (and on the case's level), at most ``limit``,
    where every denominator of the case (and ``t`` of r on the level) is non-zero.

    gamma is the stereographic point of two small rationals, p, q (and r off a level) small
    rationals, drawn by a generator seeded with :data:`STATE_SEED`.
    """
    denominators = [as_fraction(e)[1] for e in (case.V, case.integral, *case_equations(case))]
    if case.level is not None:
        s, t = _r_on_level(case, case_ring())
    states: list[dict[sp.Symbol, sp.Rational]] = []
    draw = random.Random(STATE_SEED)
    for _ in range(50 * limit):
        gamma = sphere_point(_small_rational(draw), _small_rational(draw))
        values: dict[sp.Symbol, Any] = {g1: gamma[0], g2: gamma[1], g3: gamma[2]}
        values.update({p: _small_rational(draw), q: _small_rational(draw)})
        values[r] = _small_rational(draw)
        if case.level is not None:
            values[r] = sp.Integer(0)
            t_value = _evaluate(t, values)
            if t_value == 0:
                continue
            values[r] = _evaluate(s, values) / t_value
        if any(_evaluate(d, values) == 0 for d in denominators):
            continue
        states.append(values)
        if len(states) >= limit:
            break
    return states


# ------------------------------------------------------------------------ the certificate


@dataclass(repr=False)
class CaseCertificate(Result):
    """The exact certificate of one case (``chargedesign verify CASE.toml``).

    Attributes
    ----------
    name : str
    holds : bool
        ``dF/dt`` vanishes exactly on ``|gamma| = 1`` (and on the level), at the file's
        parameter values.
    holds_for_all_parameters : bool or None
        The same with every non-zero parameter free (coefficients in ``QQ(parameters)``):
        the claim holds for all parameter values where the expressions are defined. None
        when the case has no free parameter.
    level : str or sympy.Rational
        ``"general"`` or the I3 level.
    independent : bool
        ``d(H, |gamma|^2, I3, F)`` has rank 4 at a rational point (of the level).
    counterexample : dict or None
        An exact state where ``dF/dt != 0`` (strings of rationals), when the claim fails.
    checks : dict of str to bool
        ``H_conserved``, ``I3_conserved`` (identically: the equations' own integrals),
        ``F_conserved``, ``witness`` (the re-multiplied identity), ``independent``.
    singular : list of str
        Where the case's expressions are singular.
    seconds : float
    """

    name: str
    holds: bool
    level: Any
    independent: bool
    holds_for_all_parameters: bool | None
    counterexample: dict[str, Any] | None
    checks: dict[str, bool]
    singular: list[str]
    seconds: float
    source: str = ""
    rank_point: dict[str, str] | None = None

    def to_dict(self) -> dict[str, Any]:
        level: Any = "general"
        if self.level != "general":
            exact = sp.Rational(self.level)
            level = int(exact) if exact.q == 1 else float(exact)
        return {
            "case": {
                "name": self.name,
                "holds": self.holds,
                "level": level,
                "independent": self.independent,
                "counterexample": self.counterexample,
                "holds_for_all_parameters": self.holds_for_all_parameters,
                "level_exact": str(self.level),
                "checks": dict(self.checks),
                "singular": list(self.singular),
                "rank_point": self.rank_point,
                "source": self.source,
                "seconds": self.seconds,
            }
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "holds": self.holds,
            "level": str(self.level),
            "independent": self.independent,
            "seconds": self.seconds,
        }

    def _text(self) -> str:
        claim = "general" if self.level == "general" else f"on I3 = {self.level}"
        lines = [
            f"Case {self.name} ({claim}): exact certificate, rational arithmetic",
            "",
            f"  dF/dt = 0 on |gamma| = 1{'' if self.level == 'general' else ' and the level'}:"
            f" {'yes' if self.holds else 'NO'}",
            f"  independent of H, |gamma|^2, I3 (rank 4):      "
            f"{'yes' if self.independent else 'NO'}",
        ]
        if self.holds_for_all_parameters is not None:
            lines.insert(
                4,
                "  the same with every non-zero parameter free:   "
                + ("yes" if self.holds_for_all_parameters else "NO (only at these values)"),
            )
        for name, ok in self.checks.items():
            lines.append(f"    {name:<14} {'yes' if ok else 'NO'}")
        if self.singular:
            lines.append("  singular where: " + ", ".join(self.singular))
        ce = self.counterexample
        if ce is not None:
            state = ce["state"]
            lines += [
                "",
                "  Counterexample (exact, |gamma|^2 = 1"
                + ("" if self.level == "general" else f", I3 = {ce['I3']}")
                + "):",
                "    " + ", ".join(f"{k} = {v}" for k, v in state.items()),
                f"    dF/dt = {ce['dF_dt']} (~{fmt(ce['dF_dt_float'], CELL)})",
            ]
        if self.source:
            lines += ["", f"  source: {self.source}"]
        lines.append(f"  {self.seconds:.3f} s")
        return "\n".join(lines)


def _jacobian_rank(functions: Sequence[sp.Expr], values: Mapping[sp.Symbol, Any]) -> int:
    rows = [[sp.diff(f, x).xreplace(values) for x in STATE] for f in functions]
    return int(sp.Matrix(rows).rank())


def certify_case(case: Case) -> CaseCertificate:
    """Run the exact certificate of ``case`` (see the module docstring)."""
    start = time.perf_counter()
    ring = case_ring()
    flow = _flow(case, ring)
    checks: dict[str, bool] = {}
    energy, cyclic, integral = (as_fraction(f) for f in (case.I1, case.I3, case.integral))
    for name, fraction in (("H", energy), ("I3", cyclic), ("integral", integral)):
        _check_work(name, fraction, flow)
    checks["H_conserved"] = derivative_numerator(energy, flow) == 0
    checks["I3_conserved"] = derivative_numerator(cyclic, flow) == 0
    derivative = derivative_numerator(integral, flow)
    normal, witness = _reduced(case, derivative, integral)
    checks["F_conserved"] = normal == 0
    checks["witness"] = witness
    free = case.with_free_parameters()
    for_all: bool | None = None
    if free is not None:
        free_ring = ring_of(free)
        free_integral = as_fraction(free.integral, free_ring)
        free_derivative = derivative_numerator(free_integral, _flow(free, free_ring))
        free_normal, free_witness = _reduced(free, free_derivative, free_integral)
        for_all = free_normal == 0
        checks["F_conserved_for_all_parameters"] = for_all
        checks["witness_for_all_parameters"] = free_witness
    states = rational_states(case, limit=64)
    check_rational_points(case.name, len(states))
    functions = (case.I1, GAMMA.dot(GAMMA), case.I3, case.integral)
    rank_state = next((v for v in states[:6] if _jacobian_rank(functions, v) == 4), None)
    checks["independent"] = rank_state is not None
    counterexample = None
    if normal != 0:
        counterexample = _counterexample(case, flow, integral, derivative, states)
    return CaseCertificate(
        name=case.name,
        holds=normal == 0,
        holds_for_all_parameters=for_all,
        level="general" if case.level is None else case.level,
        independent=rank_state is not None,
        counterexample=counterexample,
        checks=checks,
        singular=case.singular(),
        seconds=time.perf_counter() - start,
        source=case.source,
        rank_point=None if rank_state is None else {str(k): str(v) for k, v in rank_state.items()},
    )


def _check_work(name: str, fraction: tuple[PolyElement, PolyElement], flow: _Flow) -> None:
    """Refuse, before the work, a function whose time derivative would cost too much."""
    numerator, denominator = fraction
    degree = max(numerator.degrees()[_R_INDEX], denominator.degrees()[_R_INDEX], 0)
    work = len(numerator) * len(denominator) * max(len(a) for a in flow.numerators) * (1 + degree)
    check_certificate_work(name, work)


def _reduced(
    case: Case, derivative: PolyElement, integral: tuple[PolyElement, PolyElement]
) -> tuple[PolyElement, bool]:
    """The normal form of ``dF/dt``'s numerator on the sphere (and level), and whether the
    identity ``P = N (|gamma|^2 - 1) + R0`` re-multiplies."""
    numerator = derivative
    if case.level is not None:
        s, t = _r_on_level(case, derivative.ring)
        numerator = _substitute_r(derivative, s, t)
        check_denominator_on_level(sphere_normal_form(_substitute_r(integral[1], s, t))[0] == 0)
    normal, multiplier = sphere_normal_form(numerator)
    gens = numerator.ring.gens
    sphere = gens[3] ** 2 + gens[4] ** 2 + gens[5] ** 2 - 1
    return normal, numerator - multiplier * sphere - normal == 0


def _counterexample(
    case: Case,
    flow: _Flow,
    integral: tuple[PolyElement, PolyElement],
    numerator: PolyElement,
    states: Sequence[Mapping[sp.Symbol, Any]],
) -> dict[str, Any]:
    """The first rational state where ``dF/dt = W / (D^2 B)`` (``numerator`` is W) is not
    zero."""
    for values in states:
        value = _evaluate(numerator, values)
        if value != 0:
            value = value / (_evaluate(integral[1], values) ** 2 * _evaluate(flow.common, values))
            return {
                "state": {str(s): str(values[s]) for s in STATE},
                "gamma_norm_squared": str(sum(values[x] ** 2 for x in GAMMA)),
                "I3": str(sp.Rational(case.I3.xreplace(values))),
                "dF_dt": str(value),
                "dF_dt_float": float(value),
            }
    # R0 != 0 is a non-zero polynomial on the sphere: a state is found among the trials
    raise AssertionError(f"case {case.name}: no counterexample among the rational states tried")


def conserved_combinations(case: Case, candidates: Sequence[sp.Expr]) -> list[sp.Expr]:
    """The combinations ``sum c_i f_i`` of ``candidates`` whose time derivative vanishes at
    enough exact rational states of the sphere (and level): how the catalogue's integrals
    were derived (docs/workbench.md). Each result is a candidate integral, not yet a proof:
    put it in a case file and let :func:`certify_case` decide.

    Parameters
    ----------
    case : Case
        Its ``integral`` is ignored.
    candidates : sequence of sympy.Expr
        Functions of the state (e.g. monomials).

    Returns
    -------
    list of sympy.Expr
        A basis of the combinations found (each scaled so its first coefficient is 1).
        Functions that vanish on the sphere or the level (``|gamma|^2 - 1``, ``I3 - h``)
        and the known integrals among the candidates appear too.
    """
    flow = _flow(case, case_ring())
    states = rational_states(case, limit=2 * len(candidates) + 16)
    columns = []
    for candidate in candidates:
        fraction = as_fraction(candidate)
        numerator = derivative_numerator(fraction, flow)
        columns.append(
            [
                _evaluate(numerator, v)
                / (_evaluate(fraction[1], v) ** 2 * _evaluate(flow.common, v))
                for v in states
            ]
        )
    found = []
    for vector in sp.Matrix(columns).T.nullspace():
        lead = next(x for x in vector if x != 0)
        found.append(sp.expand(sum(c / lead * f for c, f in zip(vector, candidates, strict=True))))
    return found


__all__ = [
    "CaseCertificate",
    "as_fraction",
    "case_equations",
    "case_ring",
    "certify_case",
    "conserved_combinations",
    "derivative_numerator",
    "rational_states",
    "ring_of",
    "sphere_point",
    "verify_case_file",
]
