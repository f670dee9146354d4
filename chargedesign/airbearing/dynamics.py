"""The platform with reaction wheels: plant and command law (the integrator service steps it).

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

A case of (ep) (issue 34: ``[case]`` with inertia, V, l or mu, and its integral F) takes the
theorem's place through :class:`CaseModel`: the same ``f`` with the case's inertia, dV/dgamma
and mu, and F monitored in place of I4. :func:`case_model` builds it from the sympy objects
the whitelisted parser made (:mod:`chargedesign.model.case_file`): they are differentiated
(dV/dgamma, the right-hand sides of (ep), I1, I3) and turned into NumPy functions by
:func:`chargedesign.model.case_numeric.lambdified` (``sympy.lambdify``: the printed code is
sympy's own, of trees whose leaves are the state's names and rationals: no text from a file
reaches ``eval``). sympy is imported there, for a case only.

A case the testbed cannot fly is refused by the testbed's options
(:meth:`chargedesign.scene.testbed.TestbedOptions.check_case`, on the singular factors
:func:`case_singular_factors` finds), in one line naming why, before any work: an inertia the
platform's ballast cannot give, or a V or mu singular somewhere on the sphere (the wheels'
torque would be unbounded there).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cache
from typing import TYPE_CHECKING, Any

import numpy as np

from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.scene.testbed import case_refusal
from chargedesign.simulation.direct import cross

if TYPE_CHECKING:  # sympy: a case only
    from chargedesign.model.case_numeric import CaseFunctions
    from chargedesign.scene.case_file import Case


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


StateColumn = Callable[..., np.ndarray]


@dataclass(frozen=True)
class CaseModel:
    """A case of (ep) as numbers: what the plant needs in place of the theorem's parameters.

    Built from the case's sympy expressions by :func:`case_model`; this class holds NumPy
    functions only. ``time`` and ``mass`` scale the case as the feasibility window does (the motion
    ``time`` times faster, every inertia ``mass`` times larger): ``I -> mass I``,
    ``dV -> mass time^2 dV``, ``mu -> mass time mu``, so the scaled motion is
    ``omega(t) = time omega_1(time t)`` and ``F`` is read at ``omega / time``.

    Attributes
    ----------
    name : str
    inertia : ndarray, shape (3,)
        ``(A, B, C)`` of the unscaled case, kg m^2.
    level : float
        The I3 value the motions keep (the case's level; 0 for a general case).
    conditional : bool
        The integral is claimed on ``level`` only.
    functions : CaseFunctions
        The case's ``dV/dgamma``, ``mu`` and ``F`` (:func:`chargedesign.model.case_numeric.
        case_functions`, what the checker and the simulation read too).
    cyclic, energy : functions of (p, q, r, gamma1, gamma2, gamma3)
        ``I3`` and ``I1``. These and the equations take columns of shape (n,) and return
        shape (n,), constants broadcast (:func:`chargedesign.model.case_numeric.lambdified`).
    equations : tuple of 6 functions of the state
        The right-hand sides of (ep).
    time, mass : float
        The window's scaling (1: the case as written).
    record : dict
        testbed.json's ``case``: the case's name, source, inertia, V, l . gamma, integral
        and level as text.
    """

    name: str
    inertia: np.ndarray
    level: float
    conditional: bool
    functions: CaseFunctions
    cyclic: StateColumn
    energy: StateColumn
    equations: tuple[StateColumn, ...]
    time: float = 1.0
    mass: float = 1.0
    record: dict[str, Any] = field(default_factory=dict, compare=False)

    def scaled(self, time: float, mass: float) -> CaseModel:
        """The case flown ``time`` times faster with every inertia ``mass`` times larger."""
        return replace(self, time=self.time * time, mass=self.mass * mass)

    @property
    def moments(self) -> np.ndarray:
        """``(A, B, C)`` as flown, kg m^2."""
        return self.inertia * self.mass

    @property
    def level_value(self) -> float:
        """The I3 level as flown."""
        return self.level * self.mass * self.time

    def terms(self, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """dV/dgamma and mu at ``gamma`` (m, 3) each, as flown."""
        grad = self.functions.potential_gradient(gamma)
        mu = self.functions.gyroscopic(gamma)
        return self.mass * self.time**2 * grad, self.mass * self.time * mu

    def _unscaled(self, states: np.ndarray) -> list[np.ndarray]:
        flat = states.reshape(-1, 6)
        return [flat[:, 0] / self.time, flat[:, 1] / self.time, flat[:, 2] / self.time] + [
            flat[:, k] for k in (3, 4, 5)
        ]

    def invariants(self, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``I3 - level`` and ``F`` at ``states`` (..., 6), as flown."""
        columns, shape = self._unscaled(states), states.shape[:-1]
        I3 = self.cyclic(*columns) * self.mass * self.time
        F = self.functions.integral(np.stack(columns, axis=1))
        return (I3 - self.level_value).reshape(shape), F.reshape(shape)

    def energies(self, states: np.ndarray) -> np.ndarray:
        """``I1`` at ``states`` (n, 6), as flown, J."""
        return self.energy(*self._unscaled(states)) * self.mass * self.time**2

    def rhs(self, states: np.ndarray) -> np.ndarray:
        """The reduced model's ``(omega', gamma')`` at ``states`` (n, 6), as flown."""
        columns = self._unscaled(states)
        out = np.stack([f(*columns) for f in self.equations], axis=1)
        out[:, 0:3] *= self.time**2
        out[:, 3:6] *= self.time
        return out

    def rhs_function(self) -> Callable[[float, np.ndarray], np.ndarray]:
        """``rhs`` as ``solve_ivp`` takes it: ``f(t, y)`` for one state."""
        return lambda _t, y: self.rhs(np.asarray(y, float)[None])[0]

    def initial_state(self, gamma: np.ndarray, p: float, q: float) -> np.ndarray:
        """``(p, q, r, gamma)`` on the level: r solved from the linear ``I3 = level``."""
        g = np.asarray(gamma, float) / np.linalg.norm(gamma)
        C = self.moments[2]
        x = np.array([[p, q, 0.0, *g]])
        residual = float(self.invariants(x)[0][0])  # I3 - level at r = 0; dI3/dr = C gamma3
        return np.array([p, q, -residual / (C * g[2]), *g])

    def rate_terms(self, omega0: np.ndarray) -> dict[str, float]:
        """The rates (1/s) the motion may reach, as :func:`rate_terms` reads the theorem's:
        the start's, the gyroscopic ``max |mu| / min(I)`` and the potential's
        ``sqrt(max |dV/dgamma| / min(I))`` over the sphere."""
        grad, mu = self.terms(_PROBES)
        least = float(self.moments.min())
        return {
            "the start (initial_gamma, initial_p, initial_q)": float(np.linalg.norm(omega0)),
            f"case {self.name}: mu (gyroscopic)": float(np.abs(mu).max()) / least,
            f"case {self.name}: V (potential)": (float(np.abs(grad).max()) / least) ** 0.5,
        }


def case_singular_factors(case: Case) -> list[str]:
    """The factors (``"<factor> = 0"``) on which the case's V or mu is singular, sorted
    (:func:`chargedesign.model.case_numeric.singular_factors`)."""
    from chargedesign.model.case_numeric import singular_factors  # sympy: a case only

    return singular_factors([case.V, *case.mu])


def flight_refusal(case: Case) -> str | None:
    """Why the testbed cannot fly ``case`` (one line, :func:`~chargedesign.scene.testbed.
    case_refusal`), or None."""
    return case_refusal(case.name, case.inertia, case_singular_factors(case))


def case_model(case: Case) -> CaseModel:
    """The testbed's numeric model of ``case`` (refused first by :func:`flight_refusal`).

    The level is the case's I3 value for a conditional claim; a general case is flown on
    I3 = 0 (the area-zero level, as the theorem's motions are)."""
    # sympy: a case only
    import sympy as sp

    from chargedesign.model.case_file import STATE, case_equations
    from chargedesign.model.case_numeric import case_functions, lambdified

    reason = flight_refusal(case)
    if reason is not None:  # the testbed refuses it first (TestbedOptions.check_case)
        raise ValueError(reason)
    equations = case_equations(case)
    return CaseModel(
        name=case.name,
        inertia=np.array([float(m) for m in case.inertia]),
        level=0.0 if case.level is None else float(case.level),
        conditional=case.level is not None,
        functions=case_functions(case),
        cyclic=lambdified(case.I3, STATE),
        energy=lambdified(case.I1, STATE),
        equations=tuple(lambdified(e, STATE) for e in equations),
        record={
            "name": case.name,
            "source": case.source,
            "inertia_kg_m2": [float(m) for m in case.inertia],
            "V": sp.sstr(case.V),
            "l_dot_gamma": sp.sstr(case.l_dot_gamma),
            "integral": sp.sstr(case.integral),
            "level": "general" if case.level is None else str(case.level),
            "flown_on_I3": 0.0 if case.level is None else float(case.level),
            "monitored_integral": "F",
            "note": "the I4_* figures of results, requirements, tolerances and the verdict hold "
            "the relative drift of the case's F; the wheels apply the case's torque "
            "gamma x dV/dgamma - omega x mu (model/case_file.py's (ep))",
        },
    )


@dataclass(frozen=True)
class Plant:
    """The theorem's model and the platform's inertia.

    Attributes
    ----------
    params : Parameters
        The theorem's parameters (with a case: C only, the platform's scale).
    inertia : ndarray, shape (3, 3)
        The platform's true inertia about O, kg m^2.
    model_inertia : ndarray, shape (3, 3)
        The inertia the controller assumes (the designed total), kg m^2.
    case : CaseModel or None
        A case of (ep) flown instead of the theorem (None: the theorem's).
    """

    params: Parameters
    inertia: np.ndarray
    model_inertia: np.ndarray
    case: CaseModel | None = None
    inverse: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "inverse", np.linalg.inv(self.inertia))

    @property
    def theorem_inertia(self) -> np.ndarray:
        """The flown model's ``(A, B, C)``: the theorem's ``(2C, 2C, C)`` or the case's."""
        if self.case is not None:
            return self.case.moments
        C = self.params.C
        return np.array([2.0 * C, 2.0 * C, C])

    def invariants(self, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The level's integral and the monitored one at ``states`` (..., 6): the theorem's
        I3 and I4, or a case's ``I3 - level`` and F."""
        if self.case is not None:
            return self.case.invariants(states)
        return invariants(states, self.params)

    def reduced_rhs(self, states: np.ndarray) -> np.ndarray:
        """The reduced model's ``(omega', gamma')`` at ``states`` (n, 6)."""
        if self.case is not None:
            return self.case.rhs(states)
        return evaluators.rhs(states, self.params)

    def motion_rate(self, omega0: np.ndarray) -> float:
        """:func:`motion_rate` of the flown model."""
        return motion_rate(self.params, omega0, self.case)

    def terms(self, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """dV/dgamma and mu at ``gamma`` (m, 3) each."""
        if self.case is not None:
            return self.case.terms(gamma)
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


def invariants(states: np.ndarray, params: Parameters) -> tuple[np.ndarray, np.ndarray]:
    """I3 and I4 of the theorem at ``states`` (..., 6)."""
    flat = states.reshape(-1, 6)
    pt = evaluators.parameter_tuple(params)
    values = evaluators.compiled("integrals", params.singular, "numpy")(*flat.T, *pt)
    shape = states.shape[:-1]
    return (
        np.broadcast_to(values[2], flat.shape[:1]).reshape(shape),
        np.broadcast_to(values[3], flat.shape[:1]).reshape(shape),
    )


def _columns(outputs: list, m: int) -> np.ndarray:
    out = np.empty((m, 3))
    for k, column in enumerate(outputs):
        out[:, k] = column  # broadcasts outputs that do not depend on gamma
    return out


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


def model_rate_terms(
    params: Parameters, omega0: np.ndarray, case: CaseModel | None = None
) -> dict[str, float]:
    """The flown model's rates (1/s) by source: the theorem's (:func:`rate_terms`) or the
    ``case``'s (:meth:`CaseModel.rate_terms`; ``params`` unused)."""
    return rate_terms(params, omega0) if case is None else case.rate_terms(omega0)


def motion_rate(params: Parameters, omega0: np.ndarray, case: CaseModel | None = None) -> float:
    """The fastest rate of the flown model's motion, 1/s: the largest of
    :func:`model_rate_terms`, at least 1e-12."""
    return max(max(model_rate_terms(params, omega0, case).values()), 1e-12)


__all__ = [
    "CaseModel",
    "Plant",
    "case_model",
    "case_singular_factors",
    "flight_refusal",
    "invariants",
    "model_rate_terms",
    "motion_rate",
    "rate_terms",
]
