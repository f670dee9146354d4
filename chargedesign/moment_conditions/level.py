"""The level of I3: the charges' canonical angular momentum about Z against the theorem's.

With the mu conditions met, ``sum q psi(r; gamma)`` (``psi = rho A_phi``, the flux function
in the natural axisymmetric gauge) equals the theorem's ``l . gamma`` on ``|gamma| = 1``,
constant included (:func:`l_dot_gamma_residual`, symbolic); :func:`physical_l_dot_gamma`
evaluates it for given charges.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache
from typing import Any

import numpy as np

from chargedesign.fields import AxisymmetricField
from chargedesign.moment_conditions.algebra import sphere_reduce
from chargedesign.moment_conditions.harmonics import (
    body_coordinates,
    cartesian_split,
    field_symbols,
    gamma_poly,
    in_z_and_s,
    sympy_symbols,
)
from chargedesign.moment_conditions.mu import moment_symbol, symbolic_mu_solution
from chargedesign.validation import as_points, as_weights


def _flux_factor(k: int, Z: Any, S: Any) -> Any:
    """``R^(k-1) P_k'(Z/R)`` as a polynomial in Z and S (sympy); see :func:`_flux_moments`."""
    import sympy as sp

    u = sp.Symbol("u")
    poly = sp.Poly(sp.diff(sp.legendre(k, u), u), u)
    return sp.expand(in_z_and_s(poly, k - 1, Z, S))


@cache
def _flux_moments(degree: int) -> Any:
    """``sum_j q_j psi(r_j; gamma)`` in charge moments, symbolic field of ``degree``.

    ``psi = rho A_phi = -(R^2 - Z^2) sum_k f_k R^(k-1) P_k'(Z/R) / (k + 1)`` (natural
    axisymmetric gauge; ``B = curl(psi / rho e_phi) = -grad Phi``), ``Z = r . gamma``.
    """
    import sympy as sp

    _, _, _, Z, S = body_coordinates()
    g1, g2, g3 = sympy_symbols()["gammas"]
    fs = field_symbols(degree)
    g = sum(f * _flux_factor(k, Z, S) / (k + 1) for k, f in enumerate(fs, start=1))
    psi = sp.expand(-(S - Z**2) * g)
    total = 0
    for key, per_k in cartesian_split(psi).items():
        for k, gpoly in per_k.items():
            for (a, b, e), c in gpoly.items():
                total += (
                    fs[k - 1]
                    * sp.Rational(c.numerator, c.denominator)
                    * g1**a
                    * g2**b
                    * g3**e
                    * moment_symbol(key)
                )
    return total


def l_dot_gamma_residual(degree: int = 2) -> Any:
    """The I3-level check: physical ``l . gamma`` minus the theorem's, reduced on the sphere.

    The charges' canonical angular momentum about the space axis Z in the natural axisymmetric
    gauge is ``sum_j q_j psi(r_j; gamma)`` (``psi = rho A_phi``, the flux function). With the
    moments of any charge set that satisfies the mu conditions
    (:func:`symbolic_mu_solution`, generic field of ``degree``), this is compared with the
    theorem's ``l . gamma = C (2 n g1^2 + 2 n g2^2 + n g3^2 + K f g3)``.

    Returns
    -------
    sympy.Expr
        The reduced difference: ``0`` means the charges realise l . gamma exactly,
        including its constant ``2 n C`` on the sphere (so ``(omega I + l) . gamma`` is the
        charges' conserved canonical angular momentum with no offset).
    """
    import sympy as sp

    from chargedesign.model.case import GAMMA, symbolic_case

    solution = symbolic_mu_solution(degree)
    subs = {moment_symbol(k): v for k, v in solution.items()}
    physical = sp.expand(_flux_moments(degree).xreplace(subs))
    theorem = symbolic_case().l.dot(GAMMA)
    reduced = sphere_reduce(gamma_poly(sp.expand(physical - theorem)))
    g1, g2, g3 = sympy_symbols()["gammas"]
    total = sum(sp.factor(sp.cancel(c)) * g1**a * g2**b * g3**e for (a, b, e), c in reduced.items())
    return sp.simplify(total)


def physical_l_dot_gamma(
    positions: Any, charges: Any, magnetic: Sequence[float], gammas: Any
) -> np.ndarray:
    """The charges' canonical angular momentum about Z, ``sum_j q_j psi(r_j; gamma)``.

    Parameters
    ----------
    positions : array_like, shape (n, 3)
        Charge positions in body axes, m.
    charges : array_like, shape (n,)
        Charges in C.
    magnetic : sequence of float
        Legendre coefficients of the magnetic scalar potential (T m / m^k).
    gammas : array_like, shape (m, 3)
        Unit vectors of the space Z axis in body axes.

    Returns
    -------
    ndarray, shape (m,)
        ``l . gamma`` in kg m^2 / s (compare with the theorem's ``l . gamma``).
    """

    pts = as_points(positions, "positions")
    q = as_weights(charges, "charges", len(pts))
    psi = AxisymmetricField(tuple(magnetic)).flux_function_body(pts, gammas)
    return np.asarray(psi @ q)
