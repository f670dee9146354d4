"""Euler-Poisson equations of the case, derived from the general form (never transcribed).

The paper's general equations (its eq. (ep)) are

``omega' I + omega x (omega I + mu) = gamma x dV/dgamma``,   ``gamma' + omega x gamma = 0``,

with ``I = diag(2C, 2C, C)``, ``V`` the theorem's potential and ``mu`` derived from the
vector potential ``l`` by the paper's formula (mu) (see :mod:`chargedesign.model.case`).
Solving the first for ``omega'`` (``I`` is diagonal) and the second for ``gamma'`` gives
the six right-hand sides used everywhere else: the certificate, the audit of the printed
equations and the compiled numeric evaluators.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from chargedesign.model.case import GAMMA, OMEGA, symbolic_case


def euler_poisson(inertia: sp.Matrix, V: sp.Expr, mu: sp.Matrix) -> sp.Matrix:
    """The right-hand sides of (ep) for any case: diagonal ``inertia``, ``V(gamma)``, ``mu(gamma)``.

    Parameters
    ----------
    inertia : sympy.Matrix, shape (3, 3)
        Diagonal (principal axes), each entry non-zero.
    V : sympy.Expr
        The potential, a function of ``gamma1, gamma2, gamma3`` (and parameters).
    mu : sympy.Matrix, shape (3, 1)
        The gyroscopic vector (e.g. :func:`chargedesign.model.case.mu_from_l` of ``l``).

    Returns
    -------
    sympy.Matrix, shape (6, 1)
        ``(p', q', r', gamma1', gamma2', gamma3')``, each entry expanded.
    """
    gradient = sp.Matrix([sp.diff(V, x) for x in GAMMA])
    torque = GAMMA.cross(gradient)
    gyro = OMEGA.cross(inertia * OMEGA + mu)
    omega_dot = [sp.expand((torque[i] - gyro[i]) / inertia[i, i]) for i in range(3)]
    # gamma' = -omega x gamma = gamma x omega
    gamma_dot = [sp.expand(e) for e in GAMMA.cross(OMEGA)]
    return sp.Matrix(omega_dot + gamma_dot)


@lru_cache(maxsize=1)
def equations_of_motion() -> sp.Matrix:
    """The derived right-hand sides ``(p', q', r', gamma1', gamma2', gamma3')``.

    Returns
    -------
    sympy.Matrix, shape (6, 1)
        Each entry expanded; ``p', q', r'`` in 1/s^2, ``gamma'`` in 1/s. Rational in
        gamma3 (the lambda and rho terms), polynomial in everything else. Do not mutate:
        the result is cached.
    """
    case = symbolic_case()
    return euler_poisson(case.inertia, case.V, case.mu)


def time_derivative(expr: sp.Expr) -> sp.Expr:
    """``d expr / dt`` along the derived equations (chain rule), not simplified.

    Parameters
    ----------
    expr : sympy.Expr
        A function of ``p, q, r, gamma1, gamma2, gamma3`` and the parameters.
    """
    rhs = equations_of_motion()
    variables = list(OMEGA) + list(GAMMA)
    return sp.Add(*[sp.diff(expr, x) * rhs[i] for i, x in enumerate(variables)])
