"""Time integration: adaptive explicit Runge-Kutta (solve_ivp) or implicit Gauss-Legendre.

Both integrate the 7 states per trajectory of :class:`~.system.RigidBodySystem` and can
batch many trajectories into one call (one state vector of length 7 m: the Python overhead
per step is paid once for all of them).

- ``taylor`` (default): heyoka's Taylor integrator (:mod:`.taylor`) at tolerance ``tol``
  (default machine epsilon), dense output at the samples. Without heyoka: DOP853 with a note.
- ``DOP853``, ``RK45``, ``Radau``, ``BDF``, ``LSODA``: :func:`scipy.integrate.solve_ivp`
  with explicit ``rtol``/``atol``; ``.success`` is checked and a failure raises SolverError.
- ``gauss-legendre``: 3-stage Gauss-Legendre collocation (order 6), fixed step, stages solved
  by fixed-point iteration to rounding level. It is symmetric and conserves every quadratic
  invariant exactly (here the quaternion norm); the energy and I4 errors oscillate without
  secular drift on this reversible system.

Nothing is projected: neither energy, I3 nor I4 is enforced. ``|gamma| = 1`` holds by
construction of gamma from the quaternion (see :mod:`.system`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from chargedesign.errors import SolverError
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.simulation import taylor
from chargedesign.simulation.integration import Integration
from chargedesign.simulation.system import RigidBodySystem, quaternion_gamma
from chargedesign.vocabulary import DEFAULT_SIMULATION_METHOD as DEFAULT_METHOD
from chargedesign.vocabulary import SIMULATION_METHODS as METHODS
from chargedesign.vocabulary import SOLVE_IVP_METHODS as SOLVE_IVP_METHODS

#: state names, in order, for Poincare sections and CSV columns
from chargedesign.vocabulary import STATE_NAMES as STATE_NAMES

#: the method used when heyoka cannot be imported
FALLBACK_METHOD = "DOP853"

_SQ15 = math.sqrt(15.0)
_GL_A = np.array(
    [
        [5 / 36, 2 / 9 - _SQ15 / 15, 5 / 36 - _SQ15 / 30],
        [5 / 36 + _SQ15 / 24, 2 / 9, 5 / 36 - _SQ15 / 24],
        [5 / 36 + _SQ15 / 30, 2 / 9 + _SQ15 / 15, 5 / 36],
    ]
)
_GL_B = np.array([5 / 18, 4 / 9, 5 / 18])
_GL_C = np.array([0.5 - _SQ15 / 10, 0.5, 0.5 + _SQ15 / 10])
# Lagrange extrapolation of the stage derivatives to the next step's nodes (starting guess)
_GL_E = np.array(
    [
        [
            np.prod([(1.0 + ci - _GL_C[k]) / (_GL_C[j] - _GL_C[k]) for k in range(3) if k != j])
            for j in range(3)
        ]
        for ci in _GL_C
    ]
)


def _state_value(states: np.ndarray, name: str) -> np.ndarray:
    index = STATE_NAMES.index(name)
    if index < 3:
        return states[:, index]
    return quaternion_gamma(states[:, 3:])[:, index - 3]


def integrate(
    system: RigidBodySystem,
    initial: np.ndarray,
    t_end: float,
    *,
    method: str = DEFAULT_METHOD,
    tol: float | None = None,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    max_step: float = math.inf,
    step: float | None = None,
    samples: int = 1001,
    gamma3_min: float | None = None,
    poincare: str | None = None,
    progress: Callable[[float], None] | None = None,
) -> Integration:
    """Integrate ``m`` trajectories from ``initial`` (m, 7) over ``[0, t_end]``.

    Parameters
    ----------
    system : RigidBodySystem
    initial : ndarray, shape (m, 7)
        Initial ``(p, q, r, w, x, y, z)``.
    t_end : float
        Duration, s (> 0).
    method : str
        One of :data:`METHODS`.
    tol : float, optional
        Tolerance of ``taylor`` (default machine epsilon).
    rtol, atol : float
        Tolerances of solve_ivp (ignored by ``gauss-legendre``).
    max_step : float
        Largest step of solve_ivp, s.
    step : float, optional
        Fixed step of ``gauss-legendre``, s (default ``t_end / ceil(100 t_end)``).
    samples : int
        About this many output samples over ``[0, t_end]`` (at least 2): accepted step ends
        spread evenly in time, never interpolated points.
    gamma3_min : float, optional
        When given, reaching ``|gamma3| < gamma3_min`` (the singular plane of lambda and rho)
        stops the integration and is reported as an event.
    poincare : str, optional
        State name (:data:`STATE_NAMES`) whose upward zero crossings are recorded (one
        trajectory; solve_ivp methods and taylor).
    progress : callable, optional
        Called with the fraction of ``t_end`` done (0..1), at most about 100 times.

    Raises
    ------
    SolverError
        The solver failed or returned non-finite states.
    """
    # method and samples are the scene's checked [simulation] values
    if method not in METHODS or samples < 2:
        raise ValueError(f"method {method!r} or samples {samples!r} out of range")
    y0 = np.asarray(initial, dtype=np.float64)
    fallback_note = None
    if method == "taylor":
        if taylor.available():
            out = taylor.integrate_taylor(
                system,
                y0,
                t_end,
                tol=taylor.DEFAULT_TOL if tol is None else tol,
                samples=samples,
                gamma3_min=gamma3_min,
                poincare=poincare,
                progress=progress,
            )
            out.extra["method"] = "taylor"
            if progress is not None:
                progress(1.0)
            return out
        fallback_note = (
            f"taylor: heyoka unavailable ({taylor.unavailable_reason()}); "
            f"{FALLBACK_METHOD} at rtol = {fmt(rtol, PLAIN)}, atol = {fmt(atol, PLAIN)} instead"
        )
        method = FALLBACK_METHOD
    if method == "gauss-legendre":
        out = _integrate_gauss(system, y0, t_end, step, samples, gamma3_min, progress)
    else:
        out = _integrate_solve_ivp(
            system,
            y0,
            t_end,
            method,
            rtol,
            atol,
            max_step,
            samples,
            gamma3_min,
            poincare,
            progress,
        )
    if not np.all(np.isfinite(out.states)):
        raise SolverError(f"simulation: {method} produced non-finite states")
    out.extra["method"] = method
    if fallback_note is not None:
        out.extra.setdefault("notes", []).insert(0, fallback_note)
    if progress is not None:
        progress(1.0)
    return out


def _integrate_solve_ivp(
    system: RigidBodySystem,
    y0: np.ndarray,
    t_end: float,
    method: str,
    rtol: float,
    atol: float,
    max_step: float,
    samples: int,
    gamma3_min: float | None,
    poincare: str | None,
    progress: Callable[[float], None] | None,
) -> Integration:
    m = len(y0)
    rhs = system.rhs_function(m)
    next_report = [0.0]

    def fun_progress(t: float, y: np.ndarray) -> np.ndarray:
        if t >= next_report[0] and progress is not None:
            progress(min(t / t_end, 1.0))
            next_report[0] = t + 0.01 * t_end
        return rhs(t, y)

    fun = rhs if progress is None else fun_progress

    events: list[Callable[..., float]] = []
    if gamma3_min is not None:

        def singular(t: float, y: np.ndarray) -> float:
            g3 = quaternion_gamma(y.reshape(m, 7)[:, 3:])[:, 2]
            return float(np.min(np.abs(g3)) - gamma3_min)

        singular.terminal = True  # type: ignore[attr-defined]
        singular.direction = -1  # type: ignore[attr-defined]
        events.append(singular)
    if poincare is not None:
        if poincare not in STATE_NAMES:  # the scene's checked [output] poincare_section
            raise ValueError(f"poincare: {poincare!r} is not a state name")
        if m != 1:
            # simulate records a section of its one trajectory; batches and ensembles none
            raise ValueError(f"poincare: a section of a single trajectory, not of {m}")

        def section(t: float, y: np.ndarray) -> float:
            return float(_state_value(y.reshape(1, 7), poincare)[0])

        section.direction = 1  # type: ignore[attr-defined]
        events.append(section)

    t0 = time.perf_counter()
    # every accepted step is kept (no t_eval): step ends carry the integrator's accuracy,
    # interpolated points are less accurate and would show up as spurious drift
    sol = solve_ivp(
        fun,
        (0.0, t_end),
        y0.reshape(-1),
        method=method,
        rtol=rtol,
        atol=atol,
        max_step=max_step,
        events=events or None,
    )
    seconds = time.perf_counter() - t0
    if not sol.success:
        reached = float(sol.t[-1]) if len(sol.t) else 0.0
        raise SolverError(
            f"simulation: {method} failed near t = {fmt(reached, CELL)} s: {sol.message}"
        )
    times = np.asarray(sol.t)
    accepted = len(times) - 1
    states = np.asarray(sol.y).T.reshape(len(times), m, 7)
    keep = thin_step_ends(times, samples)
    times, states = times[keep], states[keep]
    short = samples_note(method, accepted, len(times), samples)
    found: list[dict[str, Any]] = []
    poincare_points = None
    k = 0
    if gamma3_min is not None:
        if len(sol.t_events[0]):
            t_hit = float(sol.t_events[0][0])
            y_hit = np.asarray(sol.y_events[0][0]).reshape(m, 7)
            g3 = quaternion_gamma(y_hit[:, 3:])[:, 2]
            which = int(np.argmin(np.abs(g3)))
            found.append(
                {
                    "kind": "singular_plane",
                    "t": t_hit,
                    "trajectory": which,
                    "gamma3": float(g3[which]),
                    "threshold": gamma3_min,
                    "terminal": True,
                }
            )
            if times.size == 0 or times[-1] < t_hit:
                times = np.append(times, t_hit)
                states = np.concatenate([states, y_hit[None]], axis=0)
        k = 1
    if poincare is not None:
        ys = np.asarray(sol.y_events[k]).reshape(-1, 7)
        ts = np.asarray(sol.t_events[k])
        poincare_points = np.column_stack(
            [ts, ys[:, :3], quaternion_gamma(ys[:, 3:]) if len(ys) else np.zeros((0, 3))]
        )
    return Integration(
        times=times,
        states=np.transpose(states, (1, 0, 2)),
        events=found,
        poincare=poincare_points,
        steps=accepted,
        rhs_evaluations=int(sol.nfev),
        seconds=seconds,
        extra={"notes": [short]} if short else {},
    )


def thin_step_ends(times: np.ndarray, samples: int) -> np.ndarray:
    """Indices of exactly ``min(samples, len(times))`` step ends, spread evenly in time.

    The step end at or after each of ``samples`` evenly spaced times; where several times
    fall in one step, the next step ends are taken, so no index repeats (first and last kept).
    """
    n = len(times)
    if n <= samples:
        return np.arange(n)
    targets = np.linspace(times[0], times[-1], samples)
    idx = np.clip(np.searchsorted(times, targets), 0, n - 1)
    rank = np.arange(samples)
    idx = np.maximum.accumulate(idx - rank) + rank  # strictly increasing
    return np.minimum(idx, n - samples + rank)  # room left for the later ones


def samples_note(method: str, steps: int, delivered: int, asked: int) -> str | None:
    """Why a run delivered fewer samples than asked (None when it delivered them all)."""
    if delivered >= asked:
        return None
    return (
        f"simulation.samples: {delivered} samples, not the {asked} asked: {method} took "
        f"{steps} steps and its output is their ends (points between steps would be "
        "interpolated, less accurate than the steps); method = 'taylor' gives exactly the "
        "samples asked"
    )


def _integrate_gauss(
    system: RigidBodySystem,
    y0: np.ndarray,
    t_end: float,
    step: float | None,
    samples: int,
    gamma3_min: float | None,
    progress: Callable[[float], None] | None,
) -> Integration:
    m = len(y0)
    h_target = step if step is not None else min(0.01, t_end)
    if not (h_target > 0.0 and math.isfinite(h_target)):  # the scene checks step > 0
        raise ValueError(f"step: expected a step > 0, got {h_target!r}")
    n_steps = max(1, math.ceil(t_end / h_target - 1e-9))
    h = t_end / n_steps
    keep = thin_step_ends(np.arange(n_steps + 1, dtype=float), samples)
    times = [0.0]
    states = [y0.copy()]
    events: list[dict[str, Any]] = []
    hA = h * _GL_A
    hb = h * _GL_B
    derivatives = system.derivatives
    if 3 * m <= 12 and not (system.physical and system.route == "direct"):
        # few stages: the single-state Python-float path beats numpy on tiny arrays
        single = system.rhs_function(1)

        def derivatives(states: np.ndarray) -> np.ndarray:
            return np.array([single(0.0, row) for row in states])

    y = y0.reshape(-1).copy()  # (7 m,)
    K = np.repeat(system.derivatives(y0)[None].reshape(1, -1), 3, axis=0)  # (3, 7 m)
    rhs_evals = 1
    report_every = max(1, n_steps // 100)
    keep_set = {int(k) for k in keep}
    t0 = time.perf_counter()
    n = 0
    for n in range(1, n_steps + 1):
        if n > 1:
            K = _GL_E @ K
        previous = math.inf
        scale = 1.0 + float(np.max(np.abs(y)))
        for it in range(100):
            stages = y + hA @ K
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                K_new = derivatives(stages.reshape(3 * m, 7)).reshape(3, -1)
            rhs_evals += 1
            diverged = not np.all(np.isfinite(K_new))
            change = float(np.max(np.abs(K_new - K))) * h if not diverged else math.inf
            K = K_new
            # converged: at rounding level, or no longer decreasing once tiny
            if change <= 1e-15 * scale or (change >= previous and change <= 1e-12 * scale):
                break
            previous = change
            if diverged or it == 99:
                g3 = float(np.min(np.abs(quaternion_gamma(y.reshape(m, 7)[:, 3:])[:, 2])))
                raise SolverError(
                    "simulation: gauss-legendre stages did not converge at t ="
                    f" {fmt((n - 1) * h, CELL)}"
                    f" s (|gamma3| = {fmt(g3)}); reduce simulation.step or use DOP853"
                )
        y = y + hb @ K
        t = n * h
        if n in keep_set:
            times.append(t)
            states.append(y.reshape(m, 7).copy())
        if gamma3_min is not None:
            g3_all = quaternion_gamma(y.reshape(m, 7)[:, 3:])[:, 2]
            if np.min(np.abs(g3_all)) < gamma3_min:
                which = int(np.argmin(np.abs(g3_all)))
                events.append(
                    {
                        "kind": "singular_plane",
                        "t": t,
                        "trajectory": which,
                        "gamma3": float(g3_all[which]),
                        "threshold": gamma3_min,
                        "terminal": True,
                        "located": "at the end of the step that crossed the threshold",
                    }
                )
                if n not in keep_set:
                    times.append(t)
                    states.append(y.reshape(m, 7).copy())
                break
        if progress is not None and n % report_every == 0:
            progress(t / t_end)
    seconds = time.perf_counter() - t0
    return Integration(
        times=np.array(times),
        states=np.transpose(np.array(states), (1, 0, 2)),
        events=events,
        steps=n,
        rhs_evaluations=rhs_evals,
        seconds=seconds,
    )
