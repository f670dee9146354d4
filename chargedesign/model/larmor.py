"""Exact Larmor certificate: the n-system is the n = 0 system read in turning axes.

Claim (the theorem's K, c, d, kappa, lambda, rho kept; only n changes). With

    omega = omega0 - n gamma,            gamma unchanged,

(the body's angular velocity relative to axes turning at rate n about the space Z axis,
whose own angular velocity is ``n Z = n gamma`` in body axes):

1. **equations**: the derived right-hand sides with n at ``(omega0 - n gamma, gamma)`` equal
   the time derivative of ``omega0 - n gamma`` along the n = 0 equations,
   ``f_n(omega0 - n gamma) = f_0(omega0) - n gamma'_0(omega0)``, and gamma's equation is the
   same. Checked identically in the state (not only on ``|gamma| = 1``).
2. **I3 level**: ``I3_n(omega0 - n gamma) = I3_0(omega0)``, identically: ``I3 = 0`` maps to
   ``I3 = 0``.
3. **I4 map**: ``I4_n(omega0 - n gamma) = I4_0(omega0)``, identically (I4 holds n only in
   ``p + n gamma1, q + n gamma2, r + n gamma3``).
4. **Lagrangian**: ``L = 1/2 omega . I omega + l . omega - V`` generates the derived equations
   (Euler-Poincare form ``d/dt dL/domega = dL/domega x omega + dL/dgamma x gamma``,
   ``gamma' = gamma x omega``), and ``L_n(omega) - L_0(omega + n gamma)`` is a function of
   ``|gamma|^2`` alone, a constant on the sphere (its value is computed and reported).
5. **energy**: ``H_n(omega0 - n gamma) - H_0(omega0) + n I3_0(omega0)`` is a function of gamma
   whose normal form on the sphere is a constant (computed); on ``I3 = 0``, ``|gamma| = 1``
   the energy shift ``H_n(omega0 - n gamma) - H_0(omega0)`` is that constant.

Every check is an exact identity in the Laurent ring of :mod:`.certificate` (rational
coefficients, ``u = 1/gamma3``): an element is zero iff its unique normal form is zero. No
floating-point number enters. :func:`certify_larmor` with ``map_sign=+1`` runs the same
checks on the wrong map ``omega0 + n gamma`` (they fail: the certificate can fail).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import sympy as sp

from chargedesign.model.case import GAMMA, OMEGA, n, omega_shift, r, symbolic_case
from chargedesign.model.certificate import (
    RING_SYMBOLS,
    laurent_normal,
    laurent_ring,
    r_on_level,
    sphere_normal_form,
    to_ring,
    to_sympy,
)
from chargedesign.model.equations import equations_of_motion

#: the map the certificate proves, as text
LARMOR_MAP = "omega = omega0 - n gamma (gamma unchanged): axes turning at n about Z"

#: the checks, in the order they are reported
LARMOR_CHECKS = (
    "equations_omega",
    "equations_gamma",
    "I3_level",
    "I4_map",
    "lagrangian_generates_equations",
    "lagrangian_difference_on_sphere_constant",
    "energy_on_sphere_constant",
    "energy_shift_on_level_constant",
)


def lagrangian(case: Any = None) -> sp.Expr:
    """``L = 1/2 omega . I omega + l . omega - V`` of the case (J), in body axes."""
    case = symbolic_case() if case is None else case
    return sp.Rational(1, 2) * OMEGA.dot(case.inertia * OMEGA) + case.l.dot(OMEGA) - case.V


def euler_poincare_residuals() -> list[sp.Expr]:
    """``I omega' - (dL/domega x omega + dL/dgamma x gamma - d(dL/domega)/dgamma gamma')``
    with ``omega'`` the derived equations and ``gamma' = gamma x omega``; shape (3,).

    Zero iff the Lagrangian generates the derived equations.
    """
    case = symbolic_case()
    L = lagrangian(case)
    dl_domega = sp.Matrix([sp.diff(L, x) for x in OMEGA])
    dl_dgamma = sp.Matrix([sp.diff(L, x) for x in GAMMA])
    gamma_dot = GAMMA.cross(OMEGA)
    # d/dt dL/domega = I omega' + (d dL/domega / d gamma) gamma'
    momentum_rate = dl_domega.cross(OMEGA) + dl_dgamma.cross(GAMMA)
    chain = dl_domega.jacobian(GAMMA) * gamma_dot
    rhs = equations_of_motion()
    return [case.inertia[i, i] * rhs[i] - (momentum_rate[i] - chain[i]) for i in range(3)]


def _n0(expr: sp.Expr) -> sp.Expr:
    return expr.xreplace({n: 0})


def _is_constant(element: Any) -> bool:
    """True when a ring element has no state generator (a function of the parameters only)."""
    return all(not any(m[:7]) for m in element.monoms())


@dataclass(frozen=True)
class LarmorCertificate:
    """Outcome of :func:`certify_larmor`.

    Attributes
    ----------
    holds : bool
        Every check holds.
    checks : dict[str, bool]
        Each exact identity (:data:`LARMOR_CHECKS`).
    identities : dict[str, str]
        What was computed, as sympy text: the Lagrangian difference, its value on the sphere,
        the energy identity's remainder and the energy shift on ``I3 = 0``.
    map : str
        The map checked.
    seconds : float
        Wall time, s.
    notes : list of str
    expressions : dict[str, sympy.Expr]
        ``identities`` as sympy expressions.
    """

    holds: bool
    checks: dict[str, bool]
    identities: dict[str, str]
    map: str
    seconds: float
    notes: list[str] = field(default_factory=list)
    #: the same identities as sympy expressions (not in :meth:`to_dict`)
    expressions: dict[str, sp.Expr] = field(default_factory=dict, compare=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "holds": self.holds,
            "map": self.map,
            "checks": dict(self.checks),
            "identities": dict(self.identities),
            "seconds": self.seconds,
            "notes": list(self.notes),
        }


def certify_larmor(map_sign: int = -1) -> LarmorCertificate:
    """Prove exactly that the n-system is the n = 0 system in axes turning at n about Z.

    Parameters
    ----------
    map_sign : {-1, +1}
        -1 checks the Larmor map ``omega = omega0 - n gamma``; +1 the wrong map
        ``omega0 + n gamma`` (a control: its checks fail).

    Returns
    -------
    LarmorCertificate
    """
    if map_sign not in (-1, 1):
        raise ValueError(f"map_sign: expected -1 or +1, got {map_sign!r}")
    return _certify(map_sign)


@lru_cache(maxsize=2)
def _certify(sign: int) -> LarmorCertificate:
    start = time.perf_counter()
    case = symbolic_case()
    rhs = equations_of_motion()
    shift = omega_shift(n, sign)
    checks: dict[str, bool] = {}

    # 1. equations: f_n(omega0 + s n gamma) = f_0(omega0) + s n gamma'_0(omega0)
    omega_ok = all(
        to_ring(rhs[i].xreplace(shift) - (_n0(rhs[i]) + sign * n * _n0(rhs[3 + i]))) == 0
        for i in range(3)
    )
    gamma_ok = all(to_ring(rhs[3 + i].xreplace(shift) - _n0(rhs[3 + i])) == 0 for i in range(3))
    checks["equations_omega"] = omega_ok
    checks["equations_gamma"] = gamma_ok

    # 2, 3. I3 keeps its level, I4 maps
    i3_0 = _n0(case.I3)
    checks["I3_level"] = to_ring(case.I3.xreplace(shift) - i3_0) == 0
    checks["I4_map"] = to_ring(case.I4.xreplace(shift) - _n0(case.I4)) == 0

    # 4. the Lagrangian: generates the equations; differs by a function of |gamma|^2
    checks["lagrangian_generates_equations"] = all(
        to_ring(e) == 0 for e in euler_poincare_residuals()
    )
    L = lagrangian(case)
    # L_n(omega) - L_0(omega - s n gamma): the n-Lagrangian against the n = 0 one at the
    # angular velocity the map assigns
    l_difference = to_ring(L - _n0(L).xreplace(omega_shift(n, -sign)))
    l_on_sphere, _ = sphere_normal_form(l_difference)
    checks["lagrangian_difference_on_sphere_constant"] = _is_constant(l_on_sphere)

    # 5. the energy: H_n(omega0 + s n gamma) - H_0(omega0) + s ... on the sphere and on I3 = 0
    h = case.I1
    h_remainder = to_ring(h.xreplace(shift) - _n0(h) - sign * n * i3_0)
    h_on_sphere, _ = sphere_normal_form(h_remainder)
    checks["energy_on_sphere_constant"] = _is_constant(h_on_sphere)
    ring = laurent_ring()
    h_shift = to_ring(h.xreplace(shift) - _n0(h))
    # on the n = 0 system's level I3_0 = 0: r = a(gamma, p, q) (I3 is linear in r)
    root = r_on_level(0).compose(ring.gens[RING_SYMBOLS.index(n)], ring.zero)
    on_level = laurent_normal(h_shift.compose(ring.gens[RING_SYMBOLS.index(r)], root))
    shift_on_level, _ = sphere_normal_form(on_level)
    checks["energy_shift_on_level_constant"] = _is_constant(shift_on_level)

    expressions = {
        "lagrangian_difference": sp.factor(to_sympy(l_difference)),
        "lagrangian_difference_on_sphere": sp.factor(to_sympy(l_on_sphere)),
        "energy_remainder": sp.factor(to_sympy(h_remainder)),
        "energy_remainder_on_sphere": sp.factor(to_sympy(h_on_sphere)),
        "energy_shift_on_level": sp.factor(to_sympy(shift_on_level)),
    }
    identities = {k: str(v) for k, v in expressions.items()}
    word = "-" if sign < 0 else "+"
    notes = [
        f"energy: H_n(omega0 {word} n gamma) = H_0(omega0) "
        f"{'+' if sign > 0 else '-'} n I3_0(omega0) + ({identities['energy_remainder']})",
    ]
    return LarmorCertificate(
        holds=all(checks.values()),
        checks=checks,
        identities=identities,
        map=LARMOR_MAP if sign < 0 else "omega = omega0 + n gamma (the wrong sign: a control)",
        seconds=time.perf_counter() - start,
        notes=notes,
        expressions=expressions,
    )


#: what each check states, for the text
_CHECK_TEXT = {
    "equations_omega": "omega' equations map (identically in the state)",
    "equations_gamma": "gamma' equation unchanged",
    "I3_level": "I3_n(mapped) = I3_0(omega0)",
    "I4_map": "I4_n(mapped) = I4_0(omega0)",
    "lagrangian_generates_equations": "L = T + l . omega - V gives the equations",
    "lagrangian_difference_on_sphere_constant": (
        "L_n(omega) - L_0(omega + n gamma) constant on |gamma| = 1"
    ),
    "energy_on_sphere_constant": "H_n(mapped) - H_0 + n I3_0 constant on |gamma| = 1",
    "energy_shift_on_level_constant": "H_n(mapped) - H_0 constant on I3 = 0",
}


def format_larmor(data: dict[str, Any]) -> list[str]:
    """The text lines ``chargedesign verify`` prints for a :meth:`LarmorCertificate.to_dict`."""
    ids = data["identities"]
    checks = data["checks"]
    passed = sum(bool(v) for v in checks.values())
    lines = [
        "Larmor certificate (exact): the n-system is the n = 0 system in turning axes",
        f"  map: {data['map']}",
        f"  holds: {'yes' if data['holds'] else 'NO'} ({passed}/{len(checks)} checks, "
        f"{data['seconds']:.3f} s)",
    ]
    width = max(len(_CHECK_TEXT.get(k, k)) for k in checks)
    for name, ok in checks.items():
        lines.append(f"    {_CHECK_TEXT.get(name, name):<{width}} {'yes' if ok else 'NO'}")
    lines += [
        f"  L_n(omega) - L_0(omega + n gamma) = {ids['lagrangian_difference']}",
        f"    = {ids['lagrangian_difference_on_sphere']} on |gamma| = 1",
        f"  H_n(omega0 - n gamma) - H_0(omega0) + n I3_0(omega0) = {ids['energy_remainder']}",
        f"  on I3 = 0, |gamma| = 1: H_n(omega0 - n gamma) = H_0(omega0) + "
        f"{ids['energy_shift_on_level']}",
    ]
    return lines


__all__ = [
    "LARMOR_CHECKS",
    "LARMOR_MAP",
    "LarmorCertificate",
    "certify_larmor",
    "euler_poincare_residuals",
    "format_larmor",
    "lagrangian",
]
