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
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from chargedesign.errors import SolverError
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.results import Result
from chargedesign.simulation import taylor
from chargedesign.simulation.integration import Integration, singular_plane_event
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


def _fallback_note(rtol: float, atol: float) -> str:
    """What a run asked for ``taylor`` says when heyoka cannot be imported: it runs
    :data:`FALLBACK_METHOD` at ``rtol``, ``atol`` instead."""
    return (
        f"taylor: heyoka unavailable ({taylor.unavailable_reason()}); "
        f"{FALLBACK_METHOD} at rtol = {fmt(rtol, PLAIN)}, atol = {fmt(atol, PLAIN)} instead"
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
        fallback_note = _fallback_note(rtol, atol)
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
    sol = solve(
        fun,
        y0.reshape(-1),
        (0.0, t_end),
        method=method,
        rtol=rtol,
        atol=atol,
        max_step=max_step,
        events=events or None,
        what="simulation",
    )
    seconds = time.perf_counter() - t0
    times = sol.t
    accepted = len(times) - 1
    states = sol.y.reshape(len(times), m, 7)
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
            found.append(singular_plane_event(t_hit, which, float(g3[which]), gamma3_min))
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
        rhs_evaluations=sol.steps,
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
                    singular_plane_event(
                        t,
                        which,
                        float(g3_all[which]),
                        gamma3_min,
                        located="at the end of the step that crossed the threshold",
                    )
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


# -------------------------------------------------------------- the one service
#: the methods of :func:`solve`: heyoka's Taylor integrator (a symbolic system), scipy's
#: solve_ivp methods, and a fixed-step DOP853 for short pieces between control samples
SOLVE_METHODS = ("taylor", *SOLVE_IVP_METHODS, "fixed-DOP853")


def solve_ivp(*args: Any, **kwargs: Any) -> Any:
    """:func:`scipy.integrate.solve_ivp`, imported on the first call: ``scipy.integrate``
    imports ``scipy.optimize`` (about 0.1 s of CPU at start-up), which a run on heyoka's
    Taylor integrator and the commands that never integrate (``design`` imports this module
    through the flight record) do not need. The tests replace this name to make it fail."""
    from scipy.integrate import solve_ivp as scipy_solve_ivp

    return scipy_solve_ivp(*args, **kwargs)


@lru_cache(maxsize=1)
def _dop853_tableau() -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """The 12 stages of Dormand and Prince's 8th-order method (the tableau of scipy's DOP853
    class: ``n_stages``, ``A``, ``B``, ``C``), used with a fixed step by ``fixed-DOP853``; read
    on first use, not at import (``scipy.integrate`` is heavy, see :func:`solve_ivp`)."""
    from scipy.integrate import DOP853

    return DOP853.n_stages, DOP853.A, DOP853.B, DOP853.C


#: pieces up to this fraction of ``max_step`` take one classical Runge-Kutta step (fixed-DOP853)
SHORT_PIECE = 0.1


@dataclass(frozen=True)
class Symbolic:
    """A system ``x' = rhs(x)`` as sympy expressions (autonomous), for the ``taylor`` method.

    Attributes
    ----------
    variables : tuple of sympy.Symbol
        The state's names, in the order of ``y0``'s last axis.
    rhs : tuple of sympy.Expr
        Their derivatives: polynomial or rational in ``variables``, numbers as constants.
    """

    variables: tuple[Any, ...]
    rhs: tuple[Any, ...]


@dataclass(frozen=True, repr=False)
class Solution(Result):
    """The checked outcome of :func:`solve`.

    Attributes
    ----------
    t : ndarray, shape (T,)
        Output times, s (``t_eval``, or the accepted step ends without it).
    y : ndarray, shape (T, *y0.shape)
        States at ``t``.
    method : str
        The method that ran (``DOP853`` when ``taylor`` fell back).
    steps : int
        Steps taken (scipy: right-hand side evaluations, its ``nfev``).
    t_events, y_events : list of ndarray
        scipy's event records (empty lists for the other methods).
    note : str or None
        Why the method asked did not run (heyoka unavailable).
    """

    t: np.ndarray
    y: np.ndarray
    method: str
    steps: int = 0
    t_events: list[np.ndarray] = field(default_factory=list)
    y_events: list[np.ndarray] = field(default_factory=list)
    note: str | None = None

    @property
    def end(self) -> np.ndarray:
        """The last state, shape ``y0.shape``."""
        return self.y[-1]

    def to_dict(self) -> dict[str, Any]:
        return {
            "method": self.method,
            "samples": len(self.t),
            "t_end": float(self.t[-1]),
            "steps": self.steps,
            "note": self.note,
        }

    def _summary(self) -> dict[str, Any]:
        return {"method": self.method, "samples": len(self.t), "t_end": float(self.t[-1])}

    def _text(self) -> str:
        text = (
            f"{self.method}: {len(self.t)} samples to t = {fmt(float(self.t[-1]), CELL)} s,"
            f" {self.steps} steps"
        )
        return text if self.note is None else f"{text} ({self.note})"


def solve(
    rhs: Callable[[float, np.ndarray], np.ndarray] | None,
    y0: np.ndarray,
    t_span: tuple[float, float],
    *,
    t_eval: np.ndarray | None = None,
    events: list[Callable[..., float]] | None = None,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    method: str = "DOP853",
    max_step: float = math.inf,
    symbolic: Symbolic | None = None,
    tol: float | None = None,
    what: str = "integration",
) -> Solution:
    """Integrate ``y' = rhs(t, y)`` over ``t_span``: the package's one integrator service.

    Parameters
    ----------
    rhs : callable or None
        ``rhs(t, y)`` with ``y`` of ``y0``'s shape, returning that shape (scipy and fixed
        methods; may be None with ``taylor`` when heyoka is sure to be there).
    y0 : ndarray
        Initial state, any shape (``taylor``: shape (n,), or (m, n) for m independent
        trajectories of ``symbolic``).
    t_span : (float, float)
        Start and end time, s.
    t_eval : ndarray, optional
        Output times within ``t_span`` (default: scipy's step ends; ``taylor`` the two ends;
        ``fixed-DOP853`` the two ends).
    events : list of callable, optional
        scipy's events (scipy methods only).
    rtol, atol : float
        scipy's tolerances (and the fallback's when ``taylor`` cannot run).
    method : str
        One of :data:`SOLVE_METHODS`. ``taylor`` needs ``symbolic`` and falls back to DOP853
        at ``rtol``/``atol`` (the solution's ``note`` says so) without heyoka.
        ``fixed-DOP853`` takes equal steps no longer than ``max_step``; a piece shorter than
        :data:`SHORT_PIECE` of ``max_step`` takes one classical Runge-Kutta step.
    max_step : float
        Largest step, s (scipy; the fixed step's bound, required there).
    symbolic : Symbolic, optional
        The same system as sympy expressions (``taylor``).
    tol : float, optional
        heyoka's tolerance (default machine epsilon).
    what : str
        Names the integration in an error.

    Raises
    ------
    SolverError
        The solver did not reach the end (scipy's ``success`` false, heyoka's outcome not
        a success) or gave non-finite states.
    """
    if method not in SOLVE_METHODS:
        raise ValueError(f"method {method!r} is not one of {SOLVE_METHODS}")
    t0, t1 = float(t_span[0]), float(t_span[1])
    y0 = np.asarray(y0, dtype=float)
    note = None
    if method == "taylor":
        if symbolic is None:
            raise ValueError("method 'taylor' needs the system as sympy expressions (symbolic)")
        if taylor.available():
            return _solve_taylor(symbolic, y0, t0, t1, t_eval, tol, what)
        note = _fallback_note(rtol, atol)
        method = FALLBACK_METHOD
    if rhs is None:
        raise ValueError(f"method {method!r} needs the right-hand side rhs(t, y)")
    if method == "fixed-DOP853":
        if t_eval is not None or events:
            raise ValueError("fixed-DOP853 gives the end state only (no t_eval, no events)")
        end = advance(rhs, y0, t1 - t0, max_step, t0)
        if not np.all(np.isfinite(end)):
            raise SolverError(f"{what}: fixed-DOP853 produced non-finite states")
        return Solution(t=np.array([t0, t1]), y=np.stack([y0, end]), method=method)
    shape = y0.shape
    sol = solve_ivp(
        lambda t, v: np.asarray(rhs(t, v.reshape(shape)), dtype=float).reshape(-1),
        (t0, t1),
        y0.reshape(-1),
        method=method,
        rtol=rtol,
        atol=atol,
        max_step=max_step,
        t_eval=t_eval,
        events=events,
    )
    if not sol.success:
        reached = float(sol.t[-1]) if len(sol.t) else t0
        raise SolverError(f"{what}: {method} failed near t = {fmt(reached, CELL)} s: {sol.message}")
    y = np.asarray(sol.y).T.reshape(len(sol.t), *shape)
    if not np.all(np.isfinite(y)):
        raise SolverError(f"{what}: {method} produced non-finite states")
    return Solution(
        t=np.asarray(sol.t),
        y=y,
        method=method,
        steps=int(sol.nfev),
        t_events=list(sol.t_events or []),
        y_events=list(sol.y_events or []),
        note=note,
    )


def _solve_taylor(
    symbolic: Symbolic,
    y0: np.ndarray,
    t0: float,
    t1: float,
    t_eval: np.ndarray | None,
    tol: float | None,
    what: str,
) -> Solution:
    grid = np.array([t0, t1]) if t_eval is None else np.asarray(t_eval, dtype=float)
    start = grid[0] != t0
    if start:  # the grid starts at t0 (dropped from the output again)
        grid = np.concatenate([[t0], grid])
    rows = y0 if y0.ndim == 2 else y0[None]
    out, steps = [], 0
    try:
        for row in rows:
            states, n = taylor.propagate_symbolic(
                symbolic.variables,
                symbolic.rhs,
                row,
                grid,
                tol=taylor.DEFAULT_TOL if tol is None else tol,
            )
            out.append(states[1:] if start else states)
            steps += n
    except SolverError as exc:
        raise SolverError(f"{what}: {exc}") from exc
    y = np.stack(out, axis=1) if y0.ndim == 2 else out[0]
    return Solution(t=grid[1:] if start else grid, y=y, method="taylor", steps=steps)


def dop853_step(
    f: Callable[[float, np.ndarray], np.ndarray], t: float, x: np.ndarray, h: float
) -> np.ndarray:
    """One fixed step of DOP853 (8th order) of ``x' = f(t, x)`` from ``(t, x)`` by h."""
    stages, a, b, c = _dop853_tableau()
    k = np.empty((stages, x.size))  # stage derivatives, flattened: one matmul per stage
    flat = x.reshape(-1)
    k[0] = f(t, x).reshape(-1)
    for s in range(1, stages):
        stage = (flat + h * (a[s, :s] @ k[:s])).reshape(x.shape)
        k[s] = f(t + c[s] * h, stage).reshape(-1)
    return (flat + h * (b @ k)).reshape(x.shape)


def rk4_step(
    f: Callable[[float, np.ndarray], np.ndarray], t: float, x: np.ndarray, h: float
) -> np.ndarray:
    """One classical Runge-Kutta step (4th order) of ``x' = f(t, x)``."""
    k1 = f(t, x)
    k2 = f(t + 0.5 * h, x + 0.5 * h * k1)
    k3 = f(t + 0.5 * h, x + 0.5 * h * k2)
    k4 = f(t + h, x + h * k3)
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def advance(
    f: Callable[[float, np.ndarray], np.ndarray],
    x: np.ndarray,
    dt: float,
    max_step: float,
    t: float = 0.0,
) -> np.ndarray:
    """``x`` advanced by dt in equal fixed DOP853 steps no longer than ``max_step``; a piece
    shorter than :data:`SHORT_PIECE` of a step (the testbed's delay: dt times the motion's
    rate below 5e-3 with the loop's steps) takes one classical Runge-Kutta step instead,
    whose local error ``(dt rate)^5 / 120 < 3e-14`` is below the long steps'."""
    if dt <= 0.0:
        return x
    if not (max_step > 0.0 and math.isfinite(max_step)):
        raise ValueError(f"fixed-DOP853: max_step must be finite and > 0, got {max_step!r}")
    if dt <= SHORT_PIECE * max_step:
        return rk4_step(f, t, x, dt)
    n = max(1, int(np.ceil(dt / max_step - 1e-12)))
    h = dt / n
    for i in range(n):
        x = dop853_step(f, t + i * h, x, h)
    return x
