"""The frame reading of any case: axes turning at rate n about the space axis Z.

Theorem (exact; any inertia I, any V(gamma), any l(gamma)). Let axes turn at rate n about
the space axis Z; their angular velocity is ``n Z``, in body axes ``n gamma``. If
``(omega0, gamma)`` solves (ep) for ``(I, V, l)`` (in fixed axes), then the angular velocity
relative to the turning axes,

    omega = omega0 - n gamma,            gamma unchanged,

solves (ep) for

    (I,  V' = V - n^2 gamma.I gamma / 2 - n l.gamma,  l' = l + n I gamma).

Proof: the Lagrangian ``L = 1/2 omega.I omega + l.omega - V`` read at ``omega0 = omega + n
gamma`` is ``1/2 omega.I omega + (l + n I gamma).omega - (V - n^2 gamma.I gamma / 2 - n
l.gamma)``, and the Euler-Poincare equations of a Lagrangian in ``(omega, gamma)`` keep
their form in axes turning about Z (Z is fixed in both). :func:`prove_frame_reading`
checks the equations themselves, identically in the state, for symbolic I (diagonal and
full symmetric), V and l (undefined functions of gamma). Then

- ``I3' = (I omega + l').gamma = I3(omega0)`` identically: a level keeps its value;
- ``H' = H(omega0) - n I3(omega0)`` identically (H the energy ``1/2 omega.I omega + V``);
- a claimed integral F maps to ``F'(omega, gamma) = F(omega + n gamma, gamma)``.

The term ``- n l.gamma`` vanishes where ``l.gamma`` is constant on the sphere (``l = 0``, or
``l`` normal to gamma): there the reading is ``(I, V - n^2 gamma.I gamma / 2, l + n I
gamma)``. The theorem's n is this reading of its n = 0 case (:mod:`.larmor` certifies that
special case on the theorem's own equations; ``l.gamma = C K f gamma3`` there gives the
``- n K C gamma3 f`` of its V, and ``- n^2 C |gamma|^2`` is the constant on the sphere by
which the two V differ).

A case given by ``mu`` (no ``l``) is read the same way: ``mu' = mu + n (2 I gamma - tr(I)
gamma)`` (the formula (mu) of ``n I gamma``) and ``l.gamma`` is the case's own
``l_dot_gamma`` (a potential of mu on the sphere).

The time rate of any case (:func:`time_rescaled`; exact, any I, V, l). If ``(omega(t),
gamma(t))`` solves (ep) for ``(I, V, l)``, then ``omega_s(t) = s omega(s t)``,
``gamma_s(t) = gamma(s t)`` solves it for ``(I, s^2 V, s l)``: with ``tau = s t`` every term of
the momentum equation ``d/dt (I omega + l) = (I omega + l) x omega + gamma x dL/dgamma`` picks
up ``s^2`` (``dL/dgamma = (dl/dgamma)^T omega - dV/dgamma``: ``s . s`` and ``s^2``) and the
Poisson equation ``dgamma/dt = gamma x omega`` picks up ``s`` on both sides. A claimed integral
F maps to ``F(omega / s, gamma)``, and ``I3 = (I omega + l).gamma`` to ``s I3``: a level L to
``s L``. The theorem's rate family (n, K x s; kappa, lambda, rho x s^2: the frontier's) is
this map of its case (tested on the catalogue's case).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from fractions import Fraction
from functools import lru_cache
from typing import Any

import sympy as sp

from chargedesign.model.case import GAMMA, OMEGA, n, omega_shift
from chargedesign.model.case_file import case_equations
from chargedesign.results import Result
from chargedesign.scene.case_file import Case, mu_from_l

#: the map, as text
FRAME_MAP = (
    "omega = omega0 - n gamma (gamma unchanged): (I, V, l) -> "
    "(I, V - n^2 gamma.I gamma/2 - n l.gamma, l + n I gamma)"
)

#: the checks of :func:`certify_frame`, in the order they are reported
FRAME_CHECKS = ("equations_omega", "equations_gamma", "I3_level", "integral_map", "energy")

#: the symbol of the rate when none is given (the theorem's n): the certificate then holds
#: for every n
N = n


def _rate(n: Any) -> sp.Expr:
    """``n`` as an exact sympy number (a float by its decimal text) or a symbol."""
    if isinstance(n, sp.Basic):
        return n
    if isinstance(n, bool) or not isinstance(n, (int, float, Fraction)):
        raise ValueError(f"frame rate n: expected a number, got {n!r}")
    exact = Fraction(repr(n)) if isinstance(n, float) else Fraction(n)
    return sp.Rational(exact.numerator, exact.denominator)


def frame_reading(case: Case, n: Any) -> Case:
    """The case read in axes turning at rate ``n`` (1/s) about the space axis Z.

    Parameters
    ----------
    case : Case
    n : number or sympy expression
        The axes' rate about Z, 1/s (a float is read by its decimal text; a sympy symbol keeps
        the reading for every n).

    Returns
    -------
    Case
        ``(I, V - n^2 gamma.I gamma / 2 - n l.gamma, l + n I gamma)`` with the claimed
        integral ``F(omega + n gamma, gamma)`` and the same level (module docstring).
    """
    rate = _rate(n)
    inertia = sp.diag(*case.inertia)
    spin = inertia * GAMMA
    V = sp.expand(case.V - rate**2 * GAMMA.dot(spin) / 2 - rate * case.l_dot_gamma)
    l_new = None if case.l is None else (case.l + rate * spin).applyfunc(sp.expand)
    mu_new = (
        mu_from_l(l_new)
        if l_new is not None
        else (case.mu + rate * mu_from_l(spin)).applyfunc(sp.expand)
    )
    integral = sp.expand(case.integral.xreplace(omega_shift(rate, +1)))
    return _mapped(
        case,
        f"{case.name} in axes turning at n = {sp.sstr(rate)}",
        V,
        l_new,
        mu_new,
        integral,
        note=(f"{case.note} " if case.note else "") + f"frame reading: {FRAME_MAP}",
    )


def _mapped(
    case: Case,
    name: str,
    V: sp.Expr,
    l_new: sp.Matrix | None,
    mu_new: sp.Matrix,
    integral: sp.Expr,
    **changes: Any,
) -> Case:
    """``case`` with the mapped V, l (or mu) and integral, their texts and ``changes``, no
    free parameters (the map's own certificate speaks for every n or s)."""
    texts = dict(case.texts)
    texts.update({"V": sp.sstr(V), "integral": sp.sstr(integral)})
    if l_new is not None:
        texts["l"] = [sp.sstr(e) for e in l_new]
    else:
        texts["mu"] = [sp.sstr(e) for e in mu_new]
    return replace(
        case,
        name=name,
        V=V,
        l=l_new,
        mu=mu_new,
        integral=integral,
        texts=texts,
        free={},
        **changes,
    )


def time_rescaled(case: Case, s: Any) -> Case:
    """The case at time rate ``s``: ``(I, s^2 V, s l)`` (or ``s mu``), the claimed integral
    ``F(omega / s, gamma)`` and the level times ``s`` (module docstring). ``s`` a positive
    number, read by its decimal text as :func:`frame_reading` reads n."""
    rate = _rate(s)
    if not rate > 0:
        raise ValueError(f"time rate s: expected a positive number, got {s!r}")
    V = sp.expand(rate**2 * case.V)
    l_new = None if case.l is None else (rate * case.l).applyfunc(sp.expand)
    mu_new = (rate * case.mu).applyfunc(sp.expand)
    integral = sp.expand(case.integral.xreplace({w: w / rate for w in OMEGA}))
    return _mapped(
        case,
        f"{case.name} at time rate s = {sp.sstr(rate)}",
        V,
        l_new,
        mu_new,
        integral,
        level=None if case.level is None else rate * case.level,
    )


def _zero(expr: sp.Expr) -> bool:
    """True when ``expr`` vanishes identically (rational functions cancelled exactly)."""
    return sp.cancel(sp.together(sp.expand(expr))) == 0


@dataclass(frozen=True, repr=False)
class FrameCertificate(Result):
    """Outcome of :func:`certify_frame`: the frame reading of one case, checked exactly.

    Attributes
    ----------
    case : str
        The case's name.
    rate : str
        The rate n checked (``n``: every n).
    holds : bool
        Every check holds.
    checks : dict[str, bool]
        Each exact identity (:data:`FRAME_CHECKS`), identically in the state.
    map : str
    seconds : float
        Wall time, s.
    """

    case: str
    rate: str
    holds: bool
    checks: dict[str, bool]
    map: str = FRAME_MAP
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "case": self.case,
            "rate": self.rate,
            "holds": self.holds,
            "map": self.map,
            "checks": dict(self.checks),
            "seconds": self.seconds,
            "notes": list(self.notes),
        }

    def _summary(self) -> dict[str, Any]:
        return {"case": self.case, "rate": self.rate, "holds": self.holds}

    def _text(self) -> str:
        lines = [
            f"Frame reading of {self.case} at n = {self.rate} (exact): "
            f"{'holds' if self.holds else 'does NOT hold'}",
            f"  map: {self.map}",
        ]
        lines += [f"    {name}: {'yes' if ok else 'NO'}" for name, ok in self.checks.items()]
        return "\n".join(lines + [f"  {note}" for note in self.notes])


def certify_frame(case: Case, n: Any = N) -> FrameCertificate:
    """Check exactly that :func:`frame_reading` of ``case`` at ``n`` is the case's motion
    read in turning axes (default: a symbol n, every rate at once).

    The checks, each an identity in ``(p, q, r, gamma)`` (not only on ``|gamma| = 1``), with
    ``f`` the case's right-hand sides, ``f'`` the read case's and ``omega0`` the state:
    ``f'_omega(omega0 - n gamma) = f_omega(omega0) - n f_gamma(omega0)``,
    ``f'_gamma(omega0 - n gamma) = f_gamma(omega0)``, ``I3'(omega0 - n gamma) = I3(omega0)``,
    ``F'(omega0 - n gamma) = F(omega0)`` and ``H'(omega0 - n gamma) = H(omega0) - n
    I3(omega0)``.
    """
    start = time.perf_counter()
    rate = _rate(n)
    read = frame_reading(case, rate)
    back = omega_shift(rate, -1)
    old, new = case_equations(case), case_equations(read)
    checks = {
        "equations_omega": all(
            _zero(new[i].xreplace(back) - (old[i] - rate * old[3 + i])) for i in range(3)
        ),
        "equations_gamma": all(_zero(new[3 + i].xreplace(back) - old[3 + i]) for i in range(3)),
        "I3_level": _zero(read.I3.xreplace(back) - case.I3),
        "integral_map": _zero(read.integral.xreplace(back) - case.integral),
        "energy": _zero(read.I1.xreplace(back) - (case.I1 - rate * case.I3)),
    }
    return FrameCertificate(
        case=case.name,
        rate=sp.sstr(rate),
        holds=all(checks.values()),
        checks=checks,
        seconds=time.perf_counter() - start,
    )


def _ep_torque(inertia: sp.Matrix, V: sp.Expr, mu: sp.Matrix, omega: sp.Matrix) -> sp.Matrix:
    """``I omega'`` of (ep): ``gamma x dV/dgamma - omega x (I omega + mu)`` (any symmetric I)."""
    gradient = sp.Matrix([sp.diff(V, x) for x in GAMMA])
    return GAMMA.cross(gradient) - omega.cross(inertia * omega + mu)


@lru_cache(maxsize=1)
def prove_frame_reading() -> dict[str, bool]:
    """The theorem for any case: symbolic inertia, ``V`` and ``l`` (undefined functions of
    gamma), exactly.

    Returns ``{"diagonal": bool, "symmetric": bool, "without_l_gamma_term": bool}``: the
    map's omega equations hold identically for a diagonal ``diag(A, B, C)`` and for a full
    symmetric inertia; the last is the control without ``- n l.gamma`` (False: that term is
    needed when ``l.gamma`` is not constant on the sphere). gamma's equation,
    ``gamma x (omega0 - n gamma) = gamma x omega0``, holds trivially.
    """
    V = sp.Function("V")(*GAMMA)
    l_vec = sp.Matrix([sp.Function(f"l{i}")(*GAMMA) for i in (1, 2, 3)])
    A, B, C = sp.symbols("A B C", positive=True)
    a = sp.symbols("I11 I12 I13 I22 I23 I33")
    inertias = {
        "diagonal": sp.diag(A, B, C),
        "symmetric": sp.Matrix([[a[0], a[1], a[2]], [a[1], a[3], a[4]], [a[2], a[4], a[5]]]),
    }

    def holds(inertia: sp.Matrix, with_term: bool) -> bool:
        spin = inertia * GAMMA
        V_new = V - N**2 * GAMMA.dot(spin) / 2 - (N * l_vec.dot(GAMMA) if with_term else 0)
        lhs = _ep_torque(inertia, V_new, mu_from_l(l_vec + N * spin), OMEGA - N * GAMMA)
        rhs = _ep_torque(inertia, V, mu_from_l(l_vec), OMEGA) - N * inertia * GAMMA.cross(OMEGA)
        return all(sp.expand((lhs[i] - rhs[i]).doit()) == 0 for i in range(3))

    return {
        "diagonal": holds(inertias["diagonal"], True),
        "symmetric": holds(inertias["symmetric"], True),
        "without_l_gamma_term": holds(inertias["diagonal"], False),
    }


__all__ = [
    "FRAME_CHECKS",
    "FRAME_MAP",
    "FrameCertificate",
    "certify_frame",
    "frame_reading",
    "prove_frame_reading",
    "time_rescaled",
]
