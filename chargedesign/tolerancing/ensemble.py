"""Many perturbed bodies of one structure integrated as one batch (the I4 drift of each), and
the linear-response prediction of that drift along the nominal trajectory.

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.simulation import api
from chargedesign.simulation.direct import cross
from chargedesign.simulation.integrate import integrate
from chargedesign.simulation.polynomials import PolynomialBank, monomial_values
from chargedesign.simulation.system import (
    Body,
    RigidBodySystem,
    quaternion_gamma,
    reduced_polynomials,
    select_effects,
    state_derivatives,
    theorem_i4,
)
from chargedesign.tolerancing.common import DEFAULT_RTOL, DEFAULT_T_END


class _Ensemble:
    """Many bodies of one structure, integrated as one batch (the reduced force route).

    Duck-types the part of :class:`~chargedesign.simulation.system.RigidBodySystem` that
    :func:`chargedesign.simulation.integrate.integrate` uses (``rhs_function``): each body's
    ``dV/dgamma`` and ``mu`` are polynomials in gamma
    (:func:`~chargedesign.simulation.system.reduced_polynomials`), stacked on one basis.
    """

    def __init__(self, bodies: Sequence[Any], effects: Sequence[str]) -> None:
        banks = [PolynomialBank(reduced_polynomials(b, *effects)) for b in bodies]
        exps = sorted({tuple(int(x) for x in e) for b in banks for e in b.exponents})
        index = {e: i for i, e in enumerate(exps)}
        self.exponents = np.array(exps, dtype=np.intp).reshape(-1, 3)
        self.degree = int(self.exponents.sum(axis=1).max(initial=0))
        coef = np.zeros((len(bodies), len(exps), 6))
        for b, bank in enumerate(banks):
            rows = [index[tuple(int(x) for x in e)] for e in bank.exponents]
            coef[b, rows] = bank.coefficients[:, 1:7]
        self.coef = coef
        self.C = bodies[0].parameters.C

    def monomials(self, gamma: np.ndarray) -> np.ndarray:
        """Basis monomials at gammas (m, 3): shape (m, K)."""
        return monomial_values(gamma, self.exponents, self.degree)

    def torque(self, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        """Torque of body b at state b: omega, gamma (B, 3) -> (B, 3)."""
        v = np.matmul(self.monomials(gamma)[:, None, :], self.coef)[:, 0]
        return cross(gamma, v[:, 0:3]) + cross(v[:, 3:6], omega)

    def rhs_function(self, batch: int = 1) -> Any:
        C = self.C

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            states = y.reshape(batch, 7)
            N = self.torque(states[:, :3], quaternion_gamma(states[:, 3:]))
            return state_derivatives(states, N, C).reshape(-1)

        return fun


def _physical_effects(body: Any) -> list[str]:
    return [e for e in select_effects(body, None)[0] if e != "theorem"]


@dataclass
class EnsembleRun:
    """Times (s,), per-body I4 relative drift over time (B, s) and the seconds taken."""

    times: np.ndarray
    drift: np.ndarray
    i4_0: np.ndarray
    seconds: float
    steps: int


def simulate_ensemble(
    designs: Sequence[Design],
    *,
    t_end: float = DEFAULT_T_END,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_RTOL,
    samples: int = 201,
    initial: Any = None,
    progress: Callable[[float], None] | None = None,
) -> EnsembleRun:
    """Integrate many bodies of one structure in one batch; I4 drift of each over time.

    This is the one place the tolerance analysis calls the simulation (the reduced route of
    :mod:`chargedesign.simulation`, DOP853 on the whole batch).

    Parameters
    ----------
    designs : sequence of Design
        Bodies with the same fields and parameters (perturbed copies of one design).
    t_end : float
        Duration, s.
    rtol, atol : float
        solve_ivp tolerances (one step size for the whole batch).
    samples : int
        Output samples (at least 2).
    initial : mapping, optional
        Initial-state spec (default: the simulation's default on I3 = 0, r solved per body).
    progress : callable, optional
        Told the fraction of the time span integrated (the whole batch advances together).

    Returns
    -------
    EnsembleRun
        ``drift[b, i] = |I4_b(t_i) - I4_b(0)| / |I4_b(0)|``.
    """

    if not designs:
        raise ValueError("designs: expected at least one design")
    spec = api.parse_initial(api.DEFAULT_INITIAL if initial is None else initial)
    bodies = [Body.from_design(d) for d in designs]
    effects = _physical_effects(bodies[0])
    y0 = [api.initial_state(RigidBodySystem(b, effects, "reduced"), spec)[0] for b in bodies]
    ens = _Ensemble(bodies, effects)
    run = integrate(
        ens,  # type: ignore[arg-type]
        np.array(y0),
        t_end,
        method="DOP853",
        rtol=rtol,
        atol=atol,
        samples=samples,
        progress=progress,
    )
    states = run.states  # (B, s, 7)
    B, s = states.shape[0], states.shape[1]

    flat = states.reshape(-1, 7)
    six = np.hstack([flat[:, :3], quaternion_gamma(flat[:, 3:])])
    i4 = theorem_i4(six, designs[0].body_parameters).reshape(B, s)
    i4_0 = i4[:, 0]
    denom = np.where(np.abs(i4_0) > 0.0, np.abs(i4_0), 1.0)
    drift = np.abs(i4 - i4_0[:, None]) / denom[:, None]
    return EnsembleRun(
        times=np.asarray(run.times), drift=drift, i4_0=i4_0, seconds=run.seconds, steps=run.steps
    )


def linear_drift(
    nominal: Design, perturbed: Sequence[Design], t_end: float, samples: int = 4001
) -> np.ndarray:
    """Linear-response I4 drift of each perturbed body: (B,) max over time.

    ``I4_b(t) - I4_b(0) = int_0^t dI4/domega . I^-1 (N_b - N_0) ds`` along the nominal
    trajectory (gamma's equation does not depend on the body and the nominal flow keeps I4),
    with ``N_b - N_0`` the torque difference at the nominal states (linear in the
    polynomial coefficients, so first order in the errors); dI4/domega by a 5-point stencil,
    exact for I4's quartic dependence on omega; the time integral by the trapezoid rule on
    the nominal run's step ends.
    """

    spec = api.parse_initial(api.DEFAULT_INITIAL)
    bodies = [Body.from_design(nominal)] + [Body.from_design(d) for d in perturbed]
    effects = _physical_effects(bodies[0])
    system = RigidBodySystem(bodies[0], effects, "reduced")
    y0 = api.initial_state(system, spec)[0]
    run = integrate(
        system, y0[None], t_end, method="DOP853", rtol=1e-12, atol=1e-12, samples=samples
    )
    st = run.states[0]
    t = np.asarray(run.times)
    omega = st[:, :3]
    gamma = quaternion_gamma(st[:, 3:])
    params = nominal.body_parameters
    grad = np.zeros_like(omega)
    h = 1e-3 * max(1.0, float(np.abs(omega).max()))
    for a in range(3):
        vals = []
        for k in (-2, -1, 1, 2):
            w = omega.copy()
            w[:, a] += k * h
            vals.append(theorem_i4(np.hstack([w, gamma]), params))
        grad[:, a] = (vals[0] - 8 * vals[1] + 8 * vals[2] - vals[3]) / (12 * h)
    inv_inertia = 1.0 / np.array([2.0 * params.C, 2.0 * params.C, params.C])
    i4_0 = float(theorem_i4(np.hstack([omega[:1], gamma[:1]]), params)[0])
    denom = abs(i4_0) if i4_0 != 0.0 else 1.0
    ens = _Ensemble(bodies, effects)
    mono = ens.monomials(gamma)  # (T, K)
    dcoef = ens.coef[1:] - ens.coef[:1]  # (B, K, 6)
    out = np.empty(len(perturbed))
    dt = np.diff(t)
    chunk = max(1, 2_000_000 // max(1, len(t) * 6))
    for start in range(0, len(perturbed), chunk):
        dv = np.einsum("tk,bkc->btc", mono, dcoef[start : start + chunk])  # (b, T, 6)
        dN = np.cross(gamma[None], dv[..., 0:3]) + np.cross(dv[..., 3:6], omega[None])
        rate = np.einsum("tj,btj->bt", grad * inv_inertia, dN)
        integral = np.cumsum(0.5 * (rate[:, 1:] + rate[:, :-1]) * dt, axis=1)
        out[start : start + chunk] = np.abs(integral).max(axis=1, initial=0.0) / denom
    return out
