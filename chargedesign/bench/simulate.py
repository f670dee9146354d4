"""Simulation benchmarks: what integral conservation costs in time.

Tables (every ratio against a baseline measured in the same run):

1. The theorem's reduced model over t = 1000 (omega of order 1) on I3 = 0: chargedesign's
   right-hand side (Python-float hot path of the cse-compiled evaluators) against a plain
   ``sympy.lambdify`` of the derived equations (no cse), both with solve_ivp DOP853.
2. Tolerance against I4 drift against time (DOP853 tolerances and Gauss-Legendre steps).
3. The direct route (element by element) against the reduced route (moment contractions)
   for a 50-element body.
4. Many trajectories in one batched call against separate calls.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from chargedesign.bench.common import BenchTable, best_time
from chargedesign.params import Parameters

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
START = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 0.6, "q": -0.4}


def _baseline(t_end: float, rtol: float, y0: np.ndarray) -> tuple[float, float, int]:
    """Plain sympy.lambdify of the derived equations (no cse) with solve_ivp DOP853."""
    import sympy as sp
    from scipy.integrate import solve_ivp

    from chargedesign.model import evaluators
    from chargedesign.model.case import PARAMETER_SYMBOLS, STATE_SYMBOLS, lam, rho
    from chargedesign.model.equations import equations_of_motion

    eqs = [e.xreplace({lam: 0, rho: 0}) for e in equations_of_motion()]
    f = sp.lambdify(STATE_SYMBOLS + PARAMETER_SYMBOLS, eqs)
    pt = evaluators.parameter_tuple(PARAMS)

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        return np.array(f(*y, *pt), dtype=float)

    t0 = time.perf_counter()
    sol = solve_ivp(fun, (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=rtol)
    seconds = time.perf_counter() - t0
    if not sol.success:
        raise RuntimeError(sol.message)
    I4 = evaluators.integrals(sol.y.T, PARAMS)[:, 3]
    return seconds, float(np.max(np.abs(I4 - I4[0])) / abs(I4[0])), len(sol.t) - 1


def _reduced_model_table(t_end: float, rtol: float) -> BenchTable:
    from chargedesign.simulate import simulate

    result = simulate(PARAMS, t_end=t_end, rtol=rtol, atol=rtol, initial=START)
    s = result.summary()
    y0 = np.concatenate([result.omega[0], result.gamma[0]])
    base_s, base_drift, base_steps = _baseline(t_end, rtol, y0)
    table = BenchTable(
        title=f"Reduced model over t = {t_end:g} s on I3 = 0 (DOP853, rtol = atol = {rtol:g})",
        columns=["right-hand side", "I4 rel drift", "steps", "seconds", "speed-up"],
        rows=[
            ["baseline: sympy.lambdify, no cse", base_drift, base_steps, base_s, 1.0],
            [
                "chargedesign (theorem effect)",
                s["I4_rel_drift"],
                s["steps"],
                s["seconds"],
                base_s / s["seconds"],
            ],
        ],
        notes=[
            "omega of order 1: gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4, r from I3 = 0.",
            "I4 drift: max |I4(t) - I4(0)| / |I4(0)| over the accepted steps; nothing projected.",
        ],
    )
    return table


def _tolerance_table(t_end: float, rtols: list[float], steps: list[float]) -> BenchTable:
    from chargedesign.simulate import simulate

    rows: list[list[Any]] = []
    base = None
    for rtol in rtols:
        s = simulate(PARAMS, t_end=t_end, rtol=rtol, atol=rtol, initial=START).summary()
        base = base or s["seconds"]
        rows.append(
            [
                "DOP853",
                f"rtol {rtol:g}",
                s["I4_rel_drift"],
                s["I1_rel_drift"],
                s["I3_max"],
                s["steps"],
                s["seconds"],
                s["seconds"] / base,
            ]
        )
    for h in steps:
        s = simulate(PARAMS, t_end=t_end, method="gauss-legendre", step=h, initial=START).summary()
        rows.append(
            [
                "gauss-legendre",
                f"step {h:g}",
                s["I4_rel_drift"],
                s["I1_rel_drift"],
                s["I3_max"],
                s["steps"],
                s["seconds"],
                s["seconds"] / (base or 1.0),
            ]
        )
    return BenchTable(
        title=f"Tolerance vs drift vs time, theorem effect, t = {t_end:g} s",
        columns=[
            "method",
            "setting",
            "I4 rel drift",
            "I1 rel drift",
            "I3 max",
            "steps",
            "seconds",
            "time ratio",
        ],
        rows=rows,
        notes=[f"time ratio: against DOP853 at rtol {rtols[0]:g} (first row)."],
        plot={"x": "seconds", "y": ["I4 rel drift"], "logx": True, "logy": True},
    )


def fifty_element_body() -> Any:
    """A random body of 50 elements (20 charges, 15 masses, 15 dipoles) in the default fields."""
    from chargedesign.simulate import Body

    rng = np.random.default_rng(0)
    return Body(
        parameters=PARAMS,
        fields={"magnetic": (1.0, 1.0), "electric": (0.0, 0.3, 0.2, 0.1), "gravity": (9.81,)},
        charge_positions=rng.uniform(-1, 1, (20, 3)),
        charge_values=rng.normal(size=20),
        mass_positions=rng.uniform(-1, 1, (15, 3)),
        mass_values=rng.uniform(0, 1, 15),
        dipole_positions=rng.uniform(-1, 1, (15, 3)),
        dipole_moments=rng.normal(size=(15, 3)),
        has_elements=True,
    )


def _route_table(t_end: float) -> BenchTable:
    from chargedesign.simulate import (
        RigidBodySystem,
        attitude_from_gamma,
        integrate,
        quaternion_gamma,
        quaternion_rotation,
        rotation_quaternion,
    )

    body = fifty_element_body()
    effects = ["lorentz", "electric", "magnetization", "gravity"]
    y0 = np.concatenate(
        [[0.6, -0.4, 0.3], rotation_quaternion(attitude_from_gamma(np.array([0.36, 0.48, 0.8])))]
    )
    rows = []
    finals = {}
    base = None
    for route in ("reduced", "direct"):
        system = RigidBodySystem(body, effects, route)
        fun = system.rhs_function(1)
        n_eval = 2000 if route == "reduced" else 200

        def evaluations(f: Any = fun, k: int = n_eval) -> list[Any]:
            return [f(0.0, y0) for _ in range(k)]

        per_eval, _ = best_time(evaluations, repeat=3)
        per_eval /= n_eval
        run = integrate(system, y0[None], t_end, rtol=1e-12, atol=1e-12, samples=2)
        finals[route] = run.states[0, -1]
        base = base or run.seconds
        rows.append([route, per_eval * 1e6, run.steps, run.seconds, run.seconds / base])
    diff = float(np.max(np.abs(finals["direct"] - finals["reduced"])))
    rng = np.random.default_rng(2)
    quats = rng.normal(size=(100, 4))
    omegas = rng.normal(size=(100, 3))
    system = RigidBodySystem(body, effects)
    G, R = quaternion_gamma(quats), quaternion_rotation(quats)
    t_red = system.torque(omegas, G, R, route="reduced")
    t_dir = system.torque(omegas, G, R, route="direct")
    torque_diff = float(np.max(np.abs(t_red - t_dir)) / np.max(np.abs(t_dir)))
    return BenchTable(
        title=f"Force routes for a 50-element body (t = {t_end:g} s, DOP853 rtol 1e-12)",
        columns=["route", "us per evaluation", "steps", "seconds", "time ratio"],
        rows=rows,
        notes=[
            "20 charges, 15 masses, 15 dipoles; magnetic (degree 2), electric (degree 4) and "
            "uniform gravity; all four physical effects.",
            "time ratio: against the reduced route.",
            f"torques at 100 random states agree to {torque_diff:.2g} (relative to the largest); "
            f"final states differ by {diff:.2g} (the motion amplifies rounding differences).",
        ],
    )


def _batch_table(m: int, t_end: float) -> BenchTable:
    from chargedesign.simulate import simulate, simulate_batch

    rng = np.random.default_rng(1)
    gam = rng.normal(size=(m, 3))
    gam[:, 2] = np.abs(gam[:, 2]) + 0.3
    gam /= np.linalg.norm(gam, axis=1)[:, None]
    states = np.hstack([rng.uniform(-1, 1, (m, 3)), gam])
    kw: dict[str, Any] = {"t_end": t_end, "rtol": 1e-10, "atol": 1e-10, "samples": 2}
    t0 = time.perf_counter()
    for k in range(m):
        simulate(PARAMS, initial=states[k], **kw)
    separate = time.perf_counter() - t0
    t0 = time.perf_counter()
    simulate_batch(PARAMS, states, **kw)
    batched = time.perf_counter() - t0
    return BenchTable(
        title=f"{m} trajectories of the theorem model, t = {t_end:g} s, DOP853 rtol 1e-10",
        columns=["calls", "seconds", "speed-up"],
        rows=[
            [f"{m} separate calls", separate, 1.0],
            ["one batched call", batched, separate / batched],
        ],
        notes=[
            "separate calls use the single-state Python-float path; the batch one numpy call "
            "per stage for all trajectories (one step size serves them all).",
        ],
    )


def run(quick: bool = False) -> list[BenchTable]:
    """The simulation tables; ``quick=True`` uses short runs (a few seconds in all)."""
    if quick:
        return [
            _reduced_model_table(20.0, 1e-12),
            _tolerance_table(20.0, [1e-8, 1e-12], [0.05]),
            _route_table(0.5),
            _batch_table(4, 2.0),
        ]
    return [
        _reduced_model_table(1000.0, 1e-13),
        _tolerance_table(1000.0, [1e-8, 1e-10, 1e-12, 1e-13], [0.05, 0.025]),
        _route_table(20.0),
        _batch_table(100, 20.0),
    ]
