"""Symbols and the defining functions of the Yehia-Elmandouh case.

Only V, l and the integral I4 are taken from the theorem's statement (they *are* the claim);
mu, the equations of motion and I1..I3 are derived here from the general Euler-Poisson form
``omega' I + omega x (omega I + mu) = gamma x dV/dgamma``, ``gamma' + omega x gamma = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

# the paper's (mu), as a case file's l means, and the state's symbols the boundary makes
from chargedesign.scene.case_file import GAMMA, OMEGA, mu_from_l
from chargedesign.scene.expressions import g1, g2, g3, p, q, r

c, d, n, K = sp.symbols("c d n K", real=True)
kappa, lam, rho = sp.symbols("kappa lambda rho", real=True)
C = sp.symbols("C", positive=True)

STATE_SYMBOLS = (p, q, r, g1, g2, g3)
#: order of the parameter arguments of every compiled evaluator
PARAMETER_SYMBOLS = (C, c, d, n, K, kappa, lam, rho)


def omega_shift(rate: sp.Expr, sign: int = 1) -> dict[sp.Symbol, sp.Expr]:
    """``omega -> omega + sign rate gamma`` as a substitution: the frame reading's map (axes
    turning at ``rate``) and, with sign -1 and the theorem's n, Larmor's."""
    return {p: p + sign * rate * g1, q: q + sign * rate * g2, r: r + sign * rate * g3}


@dataclass(frozen=True)
class SymbolicCase:
    """The case's symbolic objects (all in body axes)."""

    inertia: sp.Matrix  # diag(2C, 2C, C)
    V: sp.Expr
    l: sp.Matrix
    mu: sp.Matrix  # derived from l
    I1: sp.Expr  # Jacobi: 1/2 omega I . omega + V
    I2: sp.Expr  # |gamma|^2
    I3: sp.Expr  # (omega I + l) . gamma
    I4: sp.Expr  # the quartic integral, valid on I3 = 0


def quadratic_f() -> sp.Expr:
    """The recurring quadratic ``d (gamma2^2 - gamma1^2) + 2 c gamma1 gamma2``."""
    return d * (g2**2 - g1**2) + 2 * c * g1 * g2


@lru_cache(maxsize=1)
def symbolic_case() -> SymbolicCase:
    f = quadratic_f()
    V = C * (
        kappa * (2 * d * g1 * g2 + c * (g1**2 - g2**2))
        + sp.Rational(1, 2) * n**2 * g3**2
        - n * K * g3 * f
        + K**2
        * (
            2 * c * d * g1 * g2 * (g1**2 - g2**2)
            + d**2 / 2 * (g3**4 + 4 * g1**2 * g2**2)
            - c**2 * (g3**2 * (g1**2 + g2**2) + 2 * g1**2 * g2**2)
        )
        + lam / g3**2
        + rho * (1 / g3**4 - 1 / g3**6)
    )
    l_vec = C * sp.Matrix([2 * n * g1, 2 * n * g2, n * g3 + K * f])
    inertia = sp.diag(2 * C, 2 * C, C)
    mu = mu_from_l(l_vec)

    P = p + n * g1
    Q = q + n * g2
    R = r + n * g3
    s = c * (g1**2 - g2**2) + 2 * d * g1 * g2
    F1 = (
        P**2
        - Q**2
        + c * kappa * g3**2
        + g3**2 * (K * d * R + c * K**2 * s)
        - lam * (g1**2 - g2**2) / g3**2
    )
    F2 = (
        2 * P * Q
        + d * kappa * g3**2
        + (d * K**2 * s - K * c * R) * g3**2
        - 2 * lam * g1 * g2 / g3**2
    )
    G = (
        2 * (g3**2 - 1) / g3**6 * (P**2 + Q**2)
        - 2 * K * R * (2 * c * g1 * g2 + d * (g2**2 - g1**2)) / g3**4
        + (1 - g3**2) ** 2 / g3**12 * (rho - 2 * lam * g3**4)
        + K**2
        * (
            2 * c**2 * (1 / g3**4 - 2 / g3**2)
            + 8 * ((d**2 - c**2) * g1**2 * g2**2 + c * d * g1 * g2 * (g1**2 - g2**2)) / g3**4
        )
        + 2 * kappa / g3**4 * s
    )
    I4 = F1**2 + F2**2 + rho * G
    return SymbolicCase(
        inertia=inertia,
        V=V,
        l=l_vec,
        mu=mu,
        I1=sp.Rational(1, 2) * OMEGA.dot(inertia * OMEGA) + V,
        I2=GAMMA.dot(GAMMA),
        I3=(inertia * OMEGA + l_vec).dot(GAMMA),
        I4=I4,
    )
