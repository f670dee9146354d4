"""Simulation benchmarks: what integral conservation costs in time.

Tables (every ratio against a baseline measured in the same run):

0. Accuracy against time: taylor (heyoka), DOP853 and Gauss-Legendre at several tolerances on
   the same state, for the theorem's model (I4) and a Kowalevski top (Kowalevski's integral).
0. Ensembles: 1e4 trajectories to t = 100 on heyoka's batch integrators against DOP853.
1. The theorem's reduced model over t = 1000 (omega of order 1) on I3 = 0: chargedesign's
   right-hand side (Python-float hot path of the cse-compiled evaluators) against a plain
   ``sympy.lambdify`` of the derived equations (no cse), both with solve_ivp DOP853.
2. Tolerance against I4 drift against time (DOP853 tolerances and Gauss-Legendre steps).
3. The direct route (element by element: its kernel, and term by term as before the kernel)
   against the reduced route (moment contractions) for a 50-element body, and both routes'
   cost against the number of elements.
4. Many trajectories in one batched call against separate calls.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from chargedesign.bench.common import UNIT_SCALE as PARAMS
from chargedesign.bench.common import BenchTable, best_time, measured, random_body
from chargedesign.formatting import PLAIN, ROUGH, fmt
from chargedesign.model import evaluators
from chargedesign.scene import scene_from_dict
from chargedesign.scene.keys import KEY
from chargedesign.simulation import (
    RigidBodySystem,
    attitude_from_gamma,
    direct_terms,
    quaternion_gamma,
    quaternion_rotation,
    rotation_quaternion,
    setup_from_source,
    simulate,
    simulate_batch,
    simulate_ensemble,
)
from chargedesign.simulation.integrate import integrate

START = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 0.6, "q": -0.4}


def _baseline(t_end: float, rtol: float, y0: np.ndarray) -> tuple[float, float, int]:
    """Plain sympy.lambdify of the derived equations (no cse) with solve_ivp DOP853."""
    import sympy as sp
    from scipy.integrate import solve_ivp

    from chargedesign.model.case import PARAMETER_SYMBOLS, STATE_SYMBOLS, lam, rho
    from chargedesign.model.equations import equations_of_motion

    eqs = [e.xreplace({lam: 0, rho: 0}) for e in equations_of_motion()]
    f = sp.lambdify(STATE_SYMBOLS + PARAMETER_SYMBOLS, eqs)
    pt = evaluators.parameter_tuple(PARAMS)

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        return np.array(f(*y, *pt), dtype=float)

    sol, seconds, _ = measured(
        solve_ivp, fun, (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=rtol
    )
    if not sol.success:
        raise RuntimeError(sol.message)
    I4 = evaluators.integrals(sol.y.T, PARAMS)[:, 3]
    return seconds, float(np.max(np.abs(I4 - I4[0])) / abs(I4[0])), len(sol.t) - 1


def _reduced_model_table(t_end: float, rtol: float) -> BenchTable:
    result = simulate(PARAMS, t_end=t_end, method="DOP853", rtol=rtol, atol=rtol, initial=START)
    s = result.summary()
    y0 = np.concatenate([result.omega[0], result.gamma[0]])
    base_s, base_drift, base_steps = _baseline(t_end, rtol, y0)
    table = BenchTable(
        title=f"Reduced model over t = {fmt(t_end, PLAIN)} s on I3 = 0 (DOP853, rtol = atol ="
        f" {fmt(rtol, PLAIN)})",
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
    runs: list[tuple[str, str, dict[str, Any]]] = [
        ("DOP853", f"rtol {fmt(r, PLAIN)}", {"rtol": r, "atol": r}) for r in rtols
    ] + [("gauss-legendre", f"step {fmt(h, PLAIN)}", {"step": h}) for h in steps]
    rows: list[list[Any]] = []
    base = None  # the first DOP853 run's seconds: the baseline of the ratios
    for method, setting, options in runs:
        s = simulate(PARAMS, t_end=t_end, method=method, initial=START, **options).summary()
        if method == "DOP853":
            base = base or s["seconds"]
        rows.append(
            [
                method,
                setting,
                s["I4_rel_drift"],
                s["I1_rel_drift"],
                s["I3_max"],
                s["steps"],
                s["seconds"],
                s["seconds"] / (base or 1.0),
            ]
        )
    return BenchTable(
        title=f"Tolerance vs drift vs time, theorem effect, t = {fmt(t_end, PLAIN)} s",
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
        notes=[f"time ratio: against DOP853 at rtol {fmt(rtols[0], PLAIN)} (first row)."],
        plot={"x": "seconds", "y": ["I4 rel drift"], "logx": True, "logy": True},
    )


def fifty_element_body(elements: int = 50) -> Any:
    """A random body in the default fields: 40% charges, 30% masses, 30% dipoles.

    The default 50 elements are 20 charges, 15 masses and 15 dipoles.
    """
    nq, nm = 2 * elements // 5, 3 * elements // 10
    fields = {"magnetic": (1.0, 1.0), "electric": (0.0, 0.3, 0.2, 0.1), "gravity": (9.81,)}
    return random_body(0, PARAMS, fields, nq, nm, elements - nq - nm)


def _term_by_term_system(body: Any, effects: list[str]) -> Any:
    """The direct route as it was before its kernel: :func:`direct_terms` in space axes.

    Every right-hand side rotates the elements with the quaternion's matrix and calls the
    checked field methods once per effect (kept as the literal reference of the physics).
    """

    class TermByTerm(RigidBodySystem):
        def derivatives(self, states: np.ndarray) -> np.ndarray:
            self._rotation = quaternion_rotation(states[:, 3:])
            return super().derivatives(states)

        def torque(self, omega: np.ndarray, gamma: np.ndarray, *args: Any, **kw: Any) -> Any:
            return sum(direct_terms(self.body, e, omega, self._rotation)[0] for e in self.physical)

        def rhs_function(self, batch: int = 1) -> Any:
            def fun(t: float, y: np.ndarray) -> np.ndarray:
                return self.derivatives(y.reshape(batch, 7)).reshape(-1)

            return fun

    return TermByTerm(body, effects, "direct")


def _route_table(t_end: float) -> BenchTable:
    body = fifty_element_body()
    effects = ["lorentz", "electric", "magnetization", "gravity"]
    y0 = np.concatenate(
        [[0.6, -0.4, 0.3], rotation_quaternion(attitude_from_gamma(np.array([0.36, 0.48, 0.8])))]
    )
    systems = [
        ("reduced (moment contractions)", RigidBodySystem(body, effects, "reduced"), 2000),
        ("direct (element kernel)", RigidBodySystem(body, effects, "direct"), 2000),
        ("direct, term by term (direct_terms)", _term_by_term_system(body, effects), 100),
    ]
    funs = [system.rhs_function(1) for _, system, _ in systems]
    # rounds over the three right-hand sides in turn, so that a burst of load on the shared
    # machine hits all of them; the best round of each counts
    per_eval = [float("inf")] * len(systems)
    for _ in range(5):
        for k, (fun, (_, _, n_eval)) in enumerate(zip(funs, systems, strict=True)):

            def evaluations(f: Any = fun, count: int = n_eval) -> list[Any]:
                return [f(0.0, y0) for _ in range(count)]

            per_eval[k] = min(per_eval[k], best_time(evaluations, repeat=1)[0] / n_eval)
    rows = []
    finals = {}
    base_run = None
    for k, (label, system, _) in enumerate(systems):
        run = integrate(system, y0[None], t_end, method="DOP853", rtol=1e-12, atol=1e-12, samples=2)
        finals[label] = run.states[0, -1]
        base_run = base_run or run.seconds
        rows.append(
            [
                label,
                per_eval[k] * 1e6,
                per_eval[k] / per_eval[0],
                run.steps,
                run.seconds,
                run.seconds / base_run,
            ]
        )
    labels = [label for label, _, _ in systems]
    diff = float(np.max(np.abs(finals[labels[1]] - finals[labels[0]])))
    rng = np.random.default_rng(2)
    quats = rng.normal(size=(100, 4))
    omegas = rng.normal(size=(100, 3))
    system = RigidBodySystem(body, effects)
    G, R = quaternion_gamma(quats), quaternion_rotation(quats)
    t_red = system.torque(omegas, G, R, route="reduced")
    t_dir = system.torque(omegas, G, R, route="direct")
    t_ref = sum(direct_terms(body, e, omegas, R)[0] for e in effects)
    scale = float(np.max(np.abs(t_ref)))
    torque_diff = float(np.max(np.abs(t_red - t_dir))) / scale
    reference_diff = float(np.max(np.abs(t_ref - t_dir))) / scale
    return BenchTable(
        title=f"Force routes for a 50-element body (t = {fmt(t_end, PLAIN)} s, DOP853 rtol 1e-12)",
        columns=[
            "route",
            "us per evaluation",
            "evaluation ratio",
            "steps",
            "seconds",
            "time ratio",
        ],
        rows=rows,
        notes=[
            "20 charges, 15 masses, 15 dipoles; magnetic (degree 2), electric (degree 4) and "
            "uniform gravity; all four physical effects.",
            "us per evaluation: one single-trajectory right-hand side; ratios against the "
            "reduced route (first row).",
            "term by term: the direct route before its kernel (direct_terms per effect, space "
            "axes, checked field methods), the reference the kernel is tested against.",
            f"torques at 100 random states: kernel vs reduced {fmt(torque_diff, ROUGH)}, kernel vs"
            " term "
            f"by term {fmt(reference_diff, ROUGH)} (relative to the largest); final states of the "
            f"kernel and reduced runs differ by {fmt(diff, ROUGH)} (the motion amplifies rounding "
            "differences).",
        ],
    )


def _element_count_table(counts: list[int]) -> BenchTable:
    """Per-evaluation cost of both routes against the number of elements."""

    effects = ["lorentz", "electric", "magnetization", "gravity"]
    y0 = np.concatenate(
        [[0.6, -0.4, 0.3], rotation_quaternion(attitude_from_gamma(np.array([0.36, 0.48, 0.8])))]
    )
    rows = []
    for n in counts:
        body = fifty_element_body(n)
        funs = [RigidBodySystem(body, effects, r).rhs_function(1) for r in ("reduced", "direct")]
        times = [float("inf")] * 2
        for _ in range(5):  # in turn, as in the table above
            for k, fun in enumerate(funs):

                def evaluations(f: Any = fun) -> list[Any]:
                    return [f(0.0, y0) for _ in range(500)]

                times[k] = min(times[k], best_time(evaluations, repeat=1)[0] / 500)
        rows.append([n, times[0] * 1e6, times[1] * 1e6, times[1] / times[0]])
    return BenchTable(
        title="Right-hand side cost against the number of elements (one trajectory)",
        columns=["elements", "reduced us", "direct us", "direct / reduced"],
        rows=rows,
        notes=[
            "the body of the table above scaled (40% charges, 30% masses, 30% dipoles); the "
            "reduced route's cost does not depend on the number of elements, the direct "
            "kernel's grows linearly once numpy's per-call overhead is covered.",
        ],
    )


def _batch_table(m: int, t_end: float) -> BenchTable:
    rng = np.random.default_rng(1)
    gam = rng.normal(size=(m, 3))
    gam[:, 2] = np.abs(gam[:, 2]) + 0.3
    gam /= np.linalg.norm(gam, axis=1)[:, None]
    states = np.hstack([rng.uniform(-1, 1, (m, 3)), gam])
    kw: dict[str, Any] = {
        KEY.t_end: t_end,
        "method": "DOP853",
        "rtol": 1e-10,
        "atol": 1e-10,
        "samples": 2,
    }
    t0 = time.perf_counter()
    for k in range(m):
        simulate(PARAMS, initial=states[k], **kw)
    separate = time.perf_counter() - t0
    _, batched, _ = measured(simulate_batch, PARAMS, states, **kw)
    return BenchTable(
        title=f"{m} trajectories of the theorem model, t = {fmt(t_end, PLAIN)} s, DOP853 rtol"
        " 1e-10",
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


#: a Kowalevski top: A = B = 2C = 8 kg m^2, centre of mass on the body x axis, uniform gravity
KOWALEVSKI_SCENE: dict[str, Any] = {
    "fields": {"gravity": {"legendre": [9.81]}},
    "body": {
        "masses": {
            "positions": [
                [1, 0, 0],
                [-1, 0, 0],
                [0, 1, 0],
                [0, -1, 0],
                [0, 0, 3**0.5],
                [0, 0, -(3**0.5)],
            ],
            "values": [1.5, 0.5, 1.0, 1.0, 1.0, 1.0],
        }
    },
    "initial": {"gamma": [0.3, 0.4, 0.866], "omega": [0.5, -0.2, 1.0]},
}


def _accuracy_rows(source: Any, monitor: str, t_end: float, quick: bool) -> list[list[Any]]:
    """taylor, DOP853 and Gauss-Legendre at several tolerances on the same state."""

    settings: list[tuple[str, str, dict[str, Any]]] = [
        ("taylor", "tol eps", {}),
        ("taylor", "tol 1e-12", {"tol": 1e-12}),
        ("taylor", "tol 1e-9", {"tol": 1e-9}),
    ]
    for rtol in [1e-8, 1e-12] if quick else [1e-8, 1e-10, 1e-12, 1e-13]:
        settings.append(("DOP853", f"rtol {fmt(rtol, PLAIN)}", {"rtol": rtol, "atol": rtol}))
    for h in [0.05] if quick else [0.05, 0.02]:
        settings.append(("gauss-legendre", f"step {fmt(h, PLAIN)}", {"step": h}))
    rows: list[list[Any]] = []
    base = None
    for method, label, extra in settings:
        s = simulate(source, t_end=t_end, method=method, monitors=[monitor], **extra).summary()
        mon = s["monitors"][monitor]
        base = base or s["seconds"]
        rows.append(
            [
                method,
                label,
                mon["drift"],
                s["I1_rel_drift"],
                s["steps"],
                s["seconds"],
                s["compile_seconds"],
                s["seconds"] / base,
            ]
        )
    return rows


def _accuracy_table(t_end: float, quick: bool) -> list[BenchTable]:
    """Accuracy against time: the theorem's model (I4) and a Kowalevski top (its integral)."""

    columns = [
        "method",
        "setting",
        "integral drift",
        "I1 rel drift",
        "steps",
        "seconds",
        "compile s",
        "time ratio",
    ]
    plot = {"x": "seconds", "y": ["integral drift"], "logx": True, "logy": True, "group": "method"}
    theorem = setup_from_source(PARAMS)
    theorem.initial = START
    kowalevski = scene_from_dict({**KOWALEVSKI_SCENE, "simulation": {"samples": 2001}})
    out = []
    for title, source, monitor in (
        ("the theorem's reduced model on I3 = 0, I4", theorem, "I4"),
        (
            "a Kowalevski top (masses, uniform gravity), Kowalevski's integral",
            kowalevski,
            "kowalevski",
        ),
    ):
        out.append(
            BenchTable(
                title=f"Accuracy against time, t = {fmt(t_end, PLAIN)} s: {title}",
                columns=columns,
                rows=_accuracy_rows(source, monitor, t_end, quick),
                notes=[
                    "the same initial state for every row; drifts are maxima over 2001 samples "
                    "(relative to |X(0)|; I1 relative to the largest kinetic energy); nothing "
                    "is projected.",
                    "seconds: the integration; compile s: heyoka's JIT compile when this "
                    "process has not compiled the structure yet (0 when reused; heyoka also "
                    "caches compiled code on disk). time ratio: against the first row.",
                ],
                plot=plot,
            )
        )
    return out


def _ensemble_table(m: int, t_end: float, m_dop: int) -> BenchTable:
    """Many trajectories of the theorem model: heyoka batch integrators against DOP853."""

    rng = np.random.default_rng(1)
    gam = rng.normal(size=(m, 3))
    gam /= np.linalg.norm(gam, axis=1)[:, None]
    states = np.hstack([rng.uniform(-1, 1, (m, 3)), gam])
    rows: list[list[Any]] = []
    tay, wall, _ = measured(simulate_ensemble, PARAMS, states, t_end=t_end, samples=2)
    per = tay.seconds / m
    rows.append(["taylor (batch, 4 lanes x 2 threads)", m, tay.seconds, wall, per * 1e3, 1.0])
    dop = simulate_ensemble(
        PARAMS, states[:m_dop], t_end=t_end, samples=2, method="DOP853", rtol=1e-12, atol=1e-12
    )
    rows.append(
        [
            "DOP853 rtol 1e-12 (one batched call)",
            m_dop,
            dop.seconds,
            dop.seconds,
            dop.seconds / m_dop * 1e3,
            (dop.seconds / m_dop) / per,
        ]
    )
    s = tay.summary()
    return BenchTable(
        title=f"Ensembles: {m} trajectories of the theorem model to t = {fmt(t_end, PLAIN)} s",
        columns=["method", "trajectories", "seconds", "wall s", "ms per trajectory", "x slower"],
        rows=rows,
        notes=[
            "random omega in [-1, 1]^3 and gamma on the sphere; seconds: the integration "
            "(taylor: without the compile of a first run, reported below); wall s: the whole "
            "simulate_ensemble call, with the compile and the integrals of every trajectory.",
            "taylor: largest energy drift over the ensemble"
            f" {fmt(s.get('energy_max_drift', 0), ROUGH)}"
            f" (compile {fmt(tay.compile_seconds, ROUGH)} s).",
        ],
    )


def run(quick: bool = False) -> list[BenchTable]:
    """The simulation tables; ``quick=True`` uses short runs (a few seconds in all)."""
    if quick:
        return [
            *_accuracy_table(20.0, True),
            _ensemble_table(16, 5.0, 4),
            _reduced_model_table(20.0, 1e-12),
            _tolerance_table(20.0, [1e-8, 1e-12], [0.05]),
            _route_table(0.5),
            _element_count_table([50, 500]),
            _batch_table(4, 2.0),
        ]
    return [
        *_accuracy_table(1000.0, False),
        _ensemble_table(10000, 100.0, 100),
        _reduced_model_table(1000.0, 1e-13),
        _tolerance_table(1000.0, [1e-8, 1e-10, 1e-12, 1e-13], [0.05, 0.025]),
        _route_table(20.0),
        _element_count_table([50, 500, 5000]),
        _batch_table(100, 20.0),
    ]
