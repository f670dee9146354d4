"""Exact certificate of the theorem: which functions are integrals of the derived equations.

Method (exact rational arithmetic throughout; no floating-point number enters the proof):

1. Everything lives in the sparse polynomial ring ``QQ[p, q, r, gamma1, gamma2, gamma3, u,
   C, c, d, n, K, kappa, lambda, rho]`` with ``u`` standing for ``1/gamma3`` (the potential's
   singular terms make the model a Laurent polynomial in gamma3). After every product the
   pair ``gamma3 * u`` is cancelled (:func:`laurent_normal`), so each element has a unique
   Laurent form.
2. ``dF/dt = sum_k dF/dx_k x_k'`` along the derived equations
   (:func:`chargedesign.model.equations.equations_of_motion`), with
   ``d/dgamma3 = del/del gamma3 - u^2 del/del u``.
3. ``dI1/dt``, ``d|gamma|^2/dt`` and ``dI3/dt`` must vanish identically.
4. ``dI4/dt`` must vanish on ``I3 = 0``, ``|gamma| = 1``. ``I3 / C = gamma3 (r - a)`` with ``a``
   free of r, so dividing ``dI4/dt`` (cubic in r) by ``r - a`` gives
   ``dI4/dt = Q (r - a) + R``, ``R = dI4/dt|_{r = a}``. Eliminating ``gamma1^2`` by
   ``gamma1^2 = s + E`` (``s = 1 - gamma2^2 - gamma3^2``, ``E = |gamma|^2 - 1``) gives
   ``R = N E + R0`` with ``R0`` of degree <= 1 in gamma1: the unique normal form of ``R``
   modulo ``E`` in the Laurent ring. The claim is ``R0 = 0``; the certificate also checks the
   resulting identity ``dI4/dt = M (I3 / C) + N (|gamma|^2 - 1)``, ``M = Q u``, by expanding
   it (a witness anyone can re-multiply).
5. ``I4`` is functionally independent of ``I1, I2, I3``: the 4 x 6 Jacobian has exact rank 4
   at a rational point of the level ``I3 = 0`` on the unit sphere.

The special cases of the paper's table are the same computation with parameters set to 0.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import sympy as sp
from sympy.polys.rings import PolyElement, PolyRing

from chargedesign.model.case import (
    GAMMA,
    OMEGA,
    PARAMETER_SYMBOLS,
    C,
    K,
    g1,
    g2,
    g3,
    lam,
    n,
    p,
    q,
    r,
    rho,
    symbolic_case,
)
from chargedesign.model.equations import equations_of_motion
from chargedesign.model.printed import printed_I3

#: ``u`` stands for ``1 / gamma3`` inside the ring
U = sp.Symbol("u_inv_gamma3")
RING_SYMBOLS = (p, q, r, g1, g2, g3, U, *PARAMETER_SYMBOLS)
_IP, _IQ, _IR, _IG1, _IG2, G3_INDEX, U_INDEX = range(7)

#: the paper's table: each special case as parameters set to zero
CASES: dict[str, tuple[sp.Symbol, ...]] = {
    "general": (),
    "yehia2003": (K,),
    "goriachev": (K, n, rho),
    "chaplygin": (K, n, rho, lam),
}


@lru_cache(maxsize=1)
def laurent_ring() -> PolyRing:
    """The ring ``QQ[p, q, r, gamma1, gamma2, gamma3, u, C, c, d, n, K, kappa, lambda, rho]``."""
    ring, *_ = sp.ring(RING_SYMBOLS, sp.QQ)
    return ring


def to_ring(expr: sp.Expr) -> PolyElement:
    """A sympy Laurent polynomial in gamma3 (polynomial in the rest) as a ring element."""
    expanded = sp.expand(expr)
    inverse_powers = {
        pw: U ** (-pw.exp)
        for pw in expanded.atoms(sp.Pow)
        if pw.base == g3 and pw.exp.is_Integer and pw.exp < 0
    }
    return laurent_normal(laurent_ring().from_expr(expanded.xreplace(inverse_powers)))


def to_sympy(element: PolyElement) -> sp.Expr:
    """The ring element back as a sympy expression (``u`` replaced by ``1/gamma3``)."""
    return element.as_expr().xreplace({U: 1 / g3})


def laurent_normal(element: PolyElement) -> PolyElement:
    """Cancel ``gamma3 * u = 1`` in every monomial: the unique Laurent form.

    Works in any ring whose first seven generators are ``p, q, r, gamma1, gamma2, gamma3, u``
    (the theorem's :func:`laurent_ring`, or a case's ring: :mod:`chargedesign.model.case_file`).
    """
    ring = element.ring
    terms: dict[tuple[int, ...], Any] = {}
    for monom, coeff in element.items():
        e = monom[G3_INDEX] - monom[U_INDEX]
        m = list(monom)
        m[G3_INDEX], m[U_INDEX] = max(e, 0), max(-e, 0)
        key = tuple(m)
        terms[key] = terms.get(key, 0) + coeff
    return ring.from_dict({k: v for k, v in terms.items() if v})


@lru_cache(maxsize=8)
def _ring_equations(zeroed: tuple[sp.Symbol, ...]) -> tuple[PolyElement, ...]:
    rhs = equations_of_motion()
    zero = dict.fromkeys(zeroed, 0)
    return tuple(to_ring(e.xreplace(zero)) for e in rhs)


def _partial(element: PolyElement, k: int) -> PolyElement:
    """``d element / d x_k`` for the state's k-th generator (``d/dgamma3 = del/del gamma3 -
    u^2 del/del u``: u = 1/gamma3 depends on gamma3)."""
    gens = laurent_ring().gens
    partial = element.diff(gens[k])
    if k == G3_INDEX:
        partial = partial - gens[U_INDEX] ** 2 * element.diff(gens[U_INDEX])
    return partial


def time_derivative_ring(element: PolyElement, zeroed: tuple[sp.Symbol, ...] = ()) -> PolyElement:
    """``d/dt`` of a ring element along the derived equations (parameters in ``zeroed`` = 0)."""
    rhs = _ring_equations(zeroed)
    total = laurent_ring().zero
    for k in range(6):
        total += _partial(element, k) * rhs[k]
    return laurent_normal(total)


def split_by_power(element: PolyElement, index: int, step: int) -> dict[int, PolyElement]:
    """``element = sum_k x^(step k) B_k`` with ``B_k`` of degree < step in ``x``."""
    ring = element.ring
    parts: dict[int, dict[tuple[int, ...], Any]] = {}
    for monom, coeff in element.items():
        k, rest = divmod(monom[index], step)
        m = list(monom)
        m[index] = rest
        parts.setdefault(k, {})[tuple(m)] = coeff
    return {k: ring.from_dict(v) for k, v in parts.items()}


def divide_by_linear_in_r(
    element: PolyElement, root: PolyElement
) -> tuple[PolyElement, PolyElement]:
    """``element = Q (r - root) + R`` with ``R = element(r = root)``; returns ``(Q, R)``.

    ``root`` must be free of r. Exact: ``r^k - a^k = (r - a) sum_{j<k} r^j a^(k-1-j)``.
    """
    ring = laurent_ring()
    r_gen = ring.gens[_IR]
    quotient, remainder = ring.zero, ring.zero
    for k, coeff in split_by_power(element, _IR, 1).items():
        remainder += coeff * root**k
        quotient += coeff * sum((r_gen**j * root ** (k - 1 - j) for j in range(k)), start=ring.zero)
    return laurent_normal(quotient), laurent_normal(remainder)


def sphere_normal_form(element: PolyElement) -> tuple[PolyElement, PolyElement]:
    """``element = N (|gamma|^2 - 1) + R0`` with ``R0`` of degree <= 1 in gamma1.

    ``R0`` is the unique normal form modulo the sphere in the Laurent ring (gamma1^2 is
    replaced by ``1 - gamma2^2 - gamma3^2``; gamma3 may carry negative powers).
    Returns ``(R0, N)``. Any ring laid out as :func:`laurent_normal` says.
    """
    ring = element.ring
    gens = ring.gens
    g1_sq = gens[_IG1] ** 2
    s = 1 - gens[_IG2] ** 2 - gens[G3_INDEX] ** 2
    normal, multiplier = ring.zero, ring.zero
    for k, coeff in split_by_power(element, _IG1, 2).items():
        normal += coeff * s**k
        multiplier += coeff * sum((g1_sq**j * s ** (k - 1 - j) for j in range(k)), start=ring.zero)
    return laurent_normal(normal), laurent_normal(multiplier)


def _zeroed(element: PolyElement, zeroed: tuple[sp.Symbol, ...]) -> PolyElement:
    ring = laurent_ring()
    for sym in zeroed:
        element = element.compose(ring.gens[RING_SYMBOLS.index(sym)], ring.zero)
    return element


@lru_cache(maxsize=1)
def _ring_integrals() -> dict[str, PolyElement]:
    case = symbolic_case()
    return {
        "I1": to_ring(case.I1),
        "I2": to_ring(case.I2),
        "I3": to_ring(case.I3),
        "I3_over_C": to_ring(sp.expand(case.I3 / C)),
        "I4": to_ring(case.I4),
    }


def r_on_level(level: sp.Expr | int = 0) -> PolyElement:
    """The root ``a`` of ``I3 = level`` in r, as a ring element (Laurent in gamma3).

    ``level`` must be a multiple of C (I3 carries a factor C), e.g. ``0`` or ``2*C*n``.
    """
    ring = laurent_ring()
    over_c = sp.expand(sp.sympify(level) / C)
    if over_c.has(C):
        raise ValueError(f"level: expected a multiple of C, got {level}")
    without_r = _ring_integrals()["I3_over_C"].compose(ring.gens[_IR], ring.zero)
    # I3/C = gamma3 r + without_r  =>  r = (level/C - without_r) / gamma3
    return laurent_normal((to_ring(over_c) - without_r) * ring.gens[U_INDEX])


def reduced_dI4_dt(
    level: sp.Expr | int = 0,
    zeroed: tuple[sp.Symbol, ...] = (),
    integral: sp.Expr | None = None,
) -> PolyElement:
    """Normal form of ``dI4/dt`` on ``I3 = level``, ``|gamma| = 1`` (zero iff conserved there).

    Parameters
    ----------
    level : sympy.Expr
        The level of the derived ``I3`` (a multiple of C).
    zeroed : tuple of sympy.Symbol
        Parameters set to zero.
    integral : sympy.Expr, optional
        The function to differentiate instead of the model's I4 (e.g. the printed one).
    """
    return _split_dI4_dt(zeroed, level, integral)[1]


def _split_dI4_dt(
    zeroed: tuple[sp.Symbol, ...], level: sp.Expr | int = 0, integral: sp.Expr | None = None
) -> tuple[PolyElement, PolyElement, PolyElement, PolyElement]:
    """``(dI4/dt, R0, M, N)``: ``dI4/dt = M (I3 - level) / C + N (|gamma|^2 - 1) + R0``
    (``M = Q u`` of ``dI4/dt = Q (r - a) + R``, ``r = a`` on the level), the arguments as
    :func:`reduced_dI4_dt` takes them."""
    i4 = _ring_integrals()["I4"] if integral is None else to_ring(integral)
    d_i4 = time_derivative_ring(_zeroed(i4, zeroed), zeroed)
    quotient, on_level = divide_by_linear_in_r(d_i4, _zeroed(r_on_level(level), zeroed))
    normal, sphere_multiplier = sphere_normal_form(on_level)
    level_multiplier = laurent_normal(quotient * laurent_ring().gens[U_INDEX])
    return d_i4, normal, level_multiplier, sphere_multiplier


@dataclass(frozen=True)
class CertificateResult:
    """Outcome of :func:`certify` for one case.

    ``checks`` maps each exact check to its verdict; ``holds`` is their conjunction;
    ``seconds`` the wall time of the whole case.
    """

    case: str
    holds: bool
    checks: dict[str, bool]
    seconds: float
    zeroed: tuple[str, ...] = field(default=())

    def to_dict(self) -> dict[str, object]:
        return {
            "case": self.case,
            "holds": self.holds,
            "checks": dict(self.checks),
            "seconds": self.seconds,
            "zeroed": list(self.zeroed),
        }


#: rational parameter values (all non-zero) for the exact point checks
POINT_PARAMETERS: dict[sp.Symbol, sp.Rational] = dict(
    zip(
        PARAMETER_SYMBOLS,
        (
            sp.Rational(3, 2),  # C
            sp.Rational(1, 3),  # c
            sp.Rational(-2, 5),  # d
            sp.Rational(3, 4),  # n
            sp.Rational(1, 2),  # K
            sp.Rational(5, 7),  # kappa
            sp.Rational(1, 11),  # lambda
            sp.Rational(2, 13),  # rho
        ),
        strict=True,
    )
)
#: a rational point on the unit sphere (2^2 + 3^2 + 6^2 = 7^2)
POINT_GAMMA = (sp.Rational(2, 7), sp.Rational(3, 7), sp.Rational(6, 7))
POINT_PQ = (sp.Rational(1, 3), sp.Rational(-1, 2))


def rational_level_point(
    level: sp.Expr, zeroed: tuple[sp.Symbol, ...]
) -> dict[sp.Symbol, sp.Rational]:
    """An exact rational state on ``I3 = level`` and the unit sphere, with its parameters."""
    values: dict[sp.Symbol, Any] = dict(POINT_PARAMETERS)
    values.update(dict.fromkeys(zeroed, sp.Integer(0)))
    values.update({g1: POINT_GAMMA[0], g2: POINT_GAMMA[1], g3: POINT_GAMMA[2]})
    values.update({p: POINT_PQ[0], q: POINT_PQ[1]})
    values[r] = sp.Rational(to_sympy(r_on_level(level)).xreplace(values))
    return values


def _evaluate(element: PolyElement, values: Mapping[sp.Symbol, sp.Rational]) -> sp.Rational:
    full = dict(values)
    full[U] = 1 / values[g3]
    ring = laurent_ring()
    pairs = [(ring.gens[i], ring.domain.from_sympy(full[s])) for i, s in enumerate(RING_SYMBOLS)]
    return sp.Rational(ring.domain.to_sympy(element.evaluate(pairs)))


def _independent(zeroed: tuple[sp.Symbol, ...]) -> bool:
    """Exact rank of d(I1, I2, I3, I4)/d(state) at a rational point of the level I3 = 0."""
    values = rational_level_point(sp.Integer(0), zeroed)
    integrals = _ring_integrals()
    rows = []
    for name in ("I1", "I2", "I3", "I4"):
        element = _zeroed(integrals[name], zeroed)
        rows.append([_evaluate(_partial(element, k), values) for k in range(6)])
    return bool(sp.Matrix(rows).rank() == 4)


def _case_zeroed(case: str) -> tuple[sp.Symbol, ...]:
    """The parameters ``case`` (one of :data:`CASES`) sets to zero."""
    if case not in CASES:
        raise ValueError(f"case: expected one of {', '.join(CASES)}, got {case!r}")
    return CASES[case]


def certify(case: str = "general") -> CertificateResult:
    """Run the exact certificate for ``case`` (one of :data:`CASES`).

    Parameters
    ----------
    case : str
        ``"general"`` (all parameters free) or a special case of the paper's table:
        ``"yehia2003"`` (K = 0), ``"goriachev"`` (K = n = rho = 0), ``"chaplygin"``
        (K = n = rho = lambda = 0).
    """
    zeroed = _case_zeroed(case)
    start = time.perf_counter()
    integrals = {k: _zeroed(v, zeroed) for k, v in _ring_integrals().items()}
    checks: dict[str, bool] = {}
    for name in ("I1", "I2", "I3"):
        checks[f"{name}_conserved"] = time_derivative_ring(integrals[name], zeroed) == 0

    d_i4, normal, level_multiplier, sphere_multiplier = _split_dI4_dt(zeroed)
    checks["I4_conserved_on_level"] = normal == 0
    witness = laurent_normal(
        d_i4 - level_multiplier * integrals["I3_over_C"] - sphere_multiplier * (integrals["I2"] - 1)
    )
    checks["I4_multiplier_identity"] = witness == 0
    checks["I4_independent"] = _independent(zeroed)
    seconds = time.perf_counter() - start
    return CertificateResult(
        case=case,
        holds=all(checks.values()),
        checks=checks,
        seconds=seconds,
        zeroed=tuple(str(s) for s in zeroed),
    )


def certificate() -> dict[str, bool]:
    """``{case: holds}`` for the four cases of the paper's table (the contract's keys)."""
    return {case: certify(case).holds for case in CASES}


def multipliers(case: str = "general") -> tuple[sp.Expr, sp.Expr]:
    """The witness ``(M, N)`` of ``dI4/dt = M (I3 / C) + N (|gamma|^2 - 1)``, as sympy.

    Both are Laurent polynomials in gamma3 with rational coefficients.
    """
    _, _, level_multiplier, sphere_multiplier = _split_dI4_dt(_case_zeroed(case))
    return to_sympy(level_multiplier), to_sympy(sphere_multiplier)


def counterexample() -> dict[str, object]:
    """An exact rational point off the level ``I3 = 0`` where ``dI4/dt != 0``.

    The point lies on the *printed* zero level (printed I3 = 0, i.e. derived I3 = 2 C n) and
    on the unit sphere ``gamma = (2/7, 3/7, 6/7)``, with all parameters non-zero rationals.
    Returns strings of exact rationals (and one float for reading).
    """

    level = 2 * C * n
    values = rational_level_point(level, ())
    d_i4 = time_derivative_ring(_ring_integrals()["I4"])
    value = _evaluate(d_i4, values)
    i3 = _evaluate(_ring_integrals()["I3"], values)
    sphere = sum(values[s] ** 2 for s in GAMMA)
    names = {lam: "lambda"}
    return {
        "parameters": {names.get(s, str(s)): str(values[s]) for s in PARAMETER_SYMBOLS},
        "state": {str(s): str(values[s]) for s in (*OMEGA, *GAMMA)},
        "gamma_norm_squared": str(sphere),
        "I3": str(i3),
        "I3_printed": str(sp.Rational(printed_I3().xreplace(values))),
        "dI4_dt": str(value),
        "dI4_dt_float": float(value),
        "nonzero": value != 0,
    }
