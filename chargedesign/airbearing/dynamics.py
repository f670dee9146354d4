"""The platform with reaction wheels: plant, command law and a fixed-step DOP853 stepper.

State per run ``x = (omega, gamma, h)`` (body axes): angular velocity (rad/s), the space
vertical Z (unit vector) and the wheels' stored angular momentum (N m s). With the total
inertia J about the bearing's centre O (wheels included, their spin excluded), the plant is
(B. Wie, Space Vehicle Dynamics and Control, 2nd ed., AIAA 2008, sec. 7.2)

    J omega' + omega x (J omega + h) = -h' + tau_ext,    gamma' = gamma x omega,

with ``h'`` the wheels' motor torques (body axes) and ``tau_ext`` the bearing's drag and the
weight's torque. The theorem wants ``omega' = f(omega, gamma) = I^-1 (gamma x dV/dgamma -
omega x (I omega + mu))`` with ``I = diag(2C, 2C, C)``; the command that gives it is

    h' = -J f - omega x (J omega + h),

which for J = I is the issue's ``-omega x h + omega x mu - gamma x dV/dgamma``. Arrays are
batched: ``(m, 9)`` for m runs at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _dop853

from chargedesign.model import evaluators
from chargedesign.params import Parameters

#: the 12 stages of Dormand and Prince's 8th-order method (scipy's DOP853 tableau), used
#: with a fixed step between control samples (the held command makes the right-hand side
#: smooth there; no step-size control is needed at steps well inside its radius)
_STAGES = _dop853.N_STAGES
_A = _dop853.A[:_STAGES, :_STAGES]
_B = _dop853.B
_C = _dop853.C[:_STAGES]


_NEXT = np.array([1, 2, 0])
_LAST = np.array([2, 0, 1])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (m, 3) arrays (faster than numpy's for small m)."""
    return a.take(_NEXT, axis=1) * b.take(_LAST, axis=1) - a.take(_LAST, axis=1) * b.take(
        _NEXT, axis=1
    )


#: the largest degree in gamma of dV/dgamma and mu fitted as polynomials
POLY_DEGREE = 4
_EXPONENTS = np.array(
    [(a, b, c) for a in range(5) for b in range(5) for c in range(5) if a + b + c <= POLY_DEGREE]
)

#: columns of each monomial's factors in the powers table of :func:`monomials`
_FLAT = [_EXPONENTS[:, i] + i * (POLY_DEGREE + 1) for i in range(3)]


def monomials(gamma: np.ndarray) -> np.ndarray:
    """All monomials of gamma (m, 3) of degree <= POLY_DEGREE, (m, K)."""
    powers = np.ones((len(gamma), 3 * (POLY_DEGREE + 1)))  # (m, [g1^k..., g2^k..., g3^k...])
    for k in range(1, POLY_DEGREE + 1):
        powers[:, k :: POLY_DEGREE + 1] = powers[:, k - 1 :: POLY_DEGREE + 1][:, :3] * gamma
    return (
        powers.take(_FLAT[0], axis=1)
        * powers.take(_FLAT[1], axis=1)
        * powers.take(_FLAT[2], axis=1)
    )


@cache
def polynomial_terms(params: Parameters) -> np.ndarray | None:
    """Coefficients (K, 6) of ``(dV/dgamma, mu)`` on :func:`monomials`, or None.

    With lambda = rho = 0 both are polynomials in gamma (model/case.py); their coefficients
    are recovered exactly by least squares from the compiled evaluators at 4 K points
    (checked to 1e-12 at fresh points). The singular case is not polynomial: None.
    """
    if params.singular:
        return None
    rng = np.random.default_rng(20261126)
    fit, check = rng.standard_normal((4 * len(_EXPONENTS), 3)), rng.standard_normal((64, 3))

    def values(g: np.ndarray) -> np.ndarray:
        return np.hstack(
            [evaluators.potential_gradient(g, params), evaluators.gyroscopic(g, params)]
        )

    coef = np.linalg.lstsq(monomials(fit), values(fit), rcond=None)[0]
    want = values(check)
    if np.abs(monomials(check) @ coef - want).max() > 1e-12 * max(1.0, np.abs(want).max()):
        return None
    return coef


@dataclass(frozen=True)
class Plant:
    """The theorem's model and the platform's inertia.

    Attributes
    ----------
    params : Parameters
    inertia : ndarray, shape (3, 3)
        The platform's true inertia about O, kg m^2.
    model_inertia : ndarray, shape (3, 3)
        The inertia the controller assumes (the designed total), kg m^2.
    """

    params: Parameters
    inertia: np.ndarray
    model_inertia: np.ndarray
    inverse: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "inverse", np.linalg.inv(self.inertia))

    @property
    def theorem_inertia(self) -> np.ndarray:
        C = self.params.C
        return np.array([2.0 * C, 2.0 * C, C])

    def terms(self, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """dV/dgamma and mu at ``gamma`` (m, 3) each."""
        coef = polynomial_terms(self.params)
        if coef is not None:
            both = monomials(gamma) @ coef
            return both[:, 0:3], both[:, 3:6]
        pt = evaluators.parameter_tuple(self.params)
        singular = self.params.singular
        grad = evaluators.compiled("potential_gradient", singular, "numpy")(*gamma.T, *pt)
        mu = evaluators.compiled("gyroscopic", singular, "numpy")(*gamma.T, *pt)
        return _columns(grad, len(gamma)), _columns(mu, len(gamma))

    def theorem_acceleration(self, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        """``f = I^-1 (gamma x dV/dgamma - omega x (I omega + mu))``, (m, 3)."""
        grad, mu = self.terms(gamma)
        inertia = self.theorem_inertia
        return (cross(gamma, grad) - cross(omega, omega * inertia + mu)) / inertia

    def command(self, x: np.ndarray) -> np.ndarray:
        """The wheels' torque ``h' = -J f - omega x (J omega + h)`` (m, 3), J the model's."""
        omega, gamma, h = x[:, 0:3], x[:, 3:6], x[:, 6:9]
        J = self.model_inertia
        f = self.theorem_acceleration(omega, gamma)
        return -(f @ J) - cross(omega, omega @ J + h)

    def rates(self, x: np.ndarray, torque: np.ndarray, external: np.ndarray | None) -> np.ndarray:
        """``x'`` (m, 9) under wheel torque ``h' = torque`` and external torque (m, 3)."""
        omega, gamma, h = x[:, 0:3], x[:, 3:6], x[:, 6:9]
        J = self.inertia
        rhs = -cross(omega, omega @ J + h) - torque
        if external is not None:
            rhs = rhs + external
        out = np.empty_like(x)
        out[:, 0:3] = rhs @ self.inverse  # J is symmetric
        out[:, 3:6] = cross(gamma, omega)
        out[:, 6:9] = torque
        return out

    def ideal_rates(self, x: np.ndarray) -> np.ndarray:
        """The continuous, noise-free closed loop (the model's own prediction)."""
        return self.rates(x, self.command(x), None)


def _columns(outputs: list, m: int) -> np.ndarray:
    out = np.empty((m, 3))
    for k, column in enumerate(outputs):
        out[:, k] = column  # broadcasts outputs that do not depend on gamma
    return out


def dop853_step(f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, h: float) -> np.ndarray:
    """One fixed step of DOP853 (8th order) of ``x' = f(x)`` from x by h."""
    k = np.empty((_STAGES, x.size))  # stage derivatives, flattened: one matmul per stage
    flat = x.reshape(-1)
    k[0] = f(x).reshape(-1)
    for s in range(1, _STAGES):
        k[s] = f((flat + h * (_A[s, :s] @ k[:s])).reshape(x.shape)).reshape(-1)
    return (flat + h * (_B @ k)).reshape(x.shape)


#: pieces up to this fraction of a step are taken by one RK4 step (see :func:`advance`)
SHORT_PIECE = 0.1


def rk4_step(f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, h: float) -> np.ndarray:
    """One classical Runge-Kutta step (4th order) of ``x' = f(x)``."""
    k1 = f(x)
    k2 = f(x + 0.5 * h * k1)
    k3 = f(x + 0.5 * h * k2)
    k4 = f(x + h * k3)
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def advance(
    f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, dt: float, max_step: float
) -> np.ndarray:
    """``x`` advanced by dt in equal fixed DOP853 steps no longer than ``max_step``; a piece
    shorter than :data:`SHORT_PIECE` of a step (the delay: dt times the motion's rate below
    5e-3 with the loop's steps) takes one classical Runge-Kutta step instead, whose local
    error ``(dt rate)^5 / 120 < 3e-14`` is below the long steps'."""
    if dt <= 0.0:
        return x
    if dt <= SHORT_PIECE * max_step:
        return rk4_step(f, x, dt)
    n = max(1, int(np.ceil(dt / max_step - 1e-12)))
    h = dt / n
    for _ in range(n):
        x = dop853_step(f, x, h)
    return x


#: directions at which the model's own rates are read (fixed: the same every run)
_PROBES = np.random.default_rng(7).standard_normal((64, 3))
_PROBES /= np.linalg.norm(_PROBES, axis=1, keepdims=True)


def rate_terms(params: Parameters, omega0: np.ndarray) -> dict[str, float]:
    """The rates (1/s) the motion may reach, by source: the start's ``|omega0|``, the
    gyroscopic ``max |mu| / C`` and the potential's ``sqrt(max |dV/dgamma| / C)`` over the
    sphere, and n, K, sqrt(|kappa|)."""
    C = params.C
    rest = params.replace(n=0.0)  # n's own rate is |n| (Larmor): the other terms without it
    mu = evaluators.gyroscopic(_PROBES, rest)
    grad = evaluators.potential_gradient(_PROBES, rest)
    return {
        "the start (initial_gamma, initial_p, initial_q)": float(np.linalg.norm(omega0)),
        "parameters n": abs(params.n),
        "parameters K, c, d (gyroscopic)": max(abs(params.K), float(np.abs(mu).max()) / C),
        "parameters kappa, K, c, d (potential)": max(
            abs(params.kappa), float(np.abs(grad).max()) / C
        )
        ** 0.5,
    }


def motion_rate(params: Parameters, omega0: np.ndarray) -> float:
    """The fastest rate of the motion, 1/s: the largest of :func:`rate_terms`, at least
    1e-12."""
    return max(max(rate_terms(params, omega0).values()), 1e-12)


__all__ = ["Plant", "advance", "cross", "dop853_step", "motion_rate", "rate_terms"]
