"""The Taylor integrator (heyoka): equations as heyoka expressions, compiled once per structure.

heyoka (https://bluescarni.github.io/heyoka.py) integrates by Taylor series of adaptive order
built by automatic differentiation and compiled to machine code by LLVM. At its default
tolerance (machine epsilon) it keeps the integrals at round-off over long runs, much faster
than DOP853 at its tightest tolerance (numbers in docs/simulate.md).

The equations are those of :class:`~chargedesign.simulation.system.RigidBodySystem`, state
``(p, q, r, w, x, y, z)`` with ``gamma`` from the quaternion, built from the same derivation:

- ``reduced`` route: the polynomial bank of :func:`~.system.reduced_polynomials` (moment
  contractions); each coefficient of ``dV/dgamma`` and ``mu`` is a runtime parameter;
- ``direct`` route: the rows of :class:`~.direct.DirectKernel` (an element's field quantity,
  a polynomial in ``Z = r . gamma``, times a fixed vector); positions, coefficients and
  vectors are runtime parameters;
- ``theorem``: ``dV/dgamma`` and ``mu`` of :mod:`chargedesign.model.case` translated from
  sympy (``heyoka.from_sympy``), the theorem's parameters ``C, c, d, n, K, kappa, lambda,
  rho`` runtime parameters.

The numbers of a body are runtime parameters (``pars``): a new body of the same *structure*
(effects, route, monomials or element rows) reuses the compiled integrator of this process
(:data:`_CACHE`); heyoka also caches compiled code in memory and, where it supports it, on
disk (``heyoka.llvm_state``), which shortens the compile of the next process.

heyoka is imported lazily. When it cannot be imported, :func:`available` is False and
:mod:`.integrate` falls back to DOP853 with a note.
"""

from __future__ import annotations

import copy
import math
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.errors import SolverError
from chargedesign.formatting import CELL, fmt
from chargedesign.model import evaluators
from chargedesign.simulation.integration import Integration, singular_plane_event
from chargedesign.simulation.system import RigidBodySystem, quaternion_gamma

#: the default tolerance: machine epsilon (heyoka's own default)
DEFAULT_TOL = float(np.finfo(float).eps)
#: state names of the sections (as :data:`.integrate.STATE_NAMES`)
SECTION_NAMES = ("p", "q", "r", "gamma1", "gamma2", "gamma3")

#: heyoka's compact mode: None chooses (compact above 200 runtime parameters), True or False
#: forces it. Compact code compiles about 7x faster and runs about 2.6x slower (theorem model,
#: measured); the test suite sets True to keep cold compiles short.
COMPACT_MODE: bool | None = None

_LOCK = threading.Lock()
_CACHE: dict[tuple[Any, ...], Any] = {}
_IMPORT_ERROR: list[str] = []


def heyoka_module() -> Any:
    """The ``heyoka`` module, or None when it cannot be imported (the reason is kept)."""
    try:
        import heyoka
    except Exception as exc:  # ImportError, or a broken binary (OSError)
        _IMPORT_ERROR[:] = [f"{type(exc).__name__}: {exc}"]
        return None
    return heyoka


def available() -> bool:
    """True when heyoka can be imported (the ``taylor`` method then runs)."""
    return heyoka_module() is not None


def unavailable_reason() -> str:
    """Why heyoka could not be imported (empty when it can)."""
    if available():
        return ""
    return _IMPORT_ERROR[0] if _IMPORT_ERROR else "heyoka is not installed"


def cache_info() -> dict[str, Any]:
    """What is compiled in this process and heyoka's own caches (JSON-ready)."""
    hy = heyoka_module()
    out: dict[str, Any] = {"integrators": len(_CACHE)}
    if hy is not None:
        st = hy.llvm_state
        out["llvm_memcache_bytes"] = int(st.memcache_size)
        if hasattr(st, "get_diskcache_enabled"):
            out["llvm_diskcache"] = bool(st.get_diskcache_enabled())
    return out


# ----------------------------------------------------------------------- equations
@dataclass
class Equations:
    """The right-hand side of a system as heyoka expressions with runtime parameters.

    Attributes
    ----------
    key : tuple
        The structure: equal keys give the same compiled code.
    sys : list of (expression, expression)
        ``(variable, derivative)`` for ``p, q, r, w, x, y, z``.
    pars : ndarray, shape (n,)
        The values of ``par[0 .. n-1]`` for this body.
    variables : list of expression
        ``p, q, r, w, x, y, z``.
    gamma : list of expression
        ``gamma1, gamma2, gamma3`` in the variables.
    """

    key: tuple[Any, ...]
    sys: list[tuple[Any, Any]]
    pars: np.ndarray
    variables: list[Any]
    gamma: list[Any]
    extra: dict[str, Any] = field(default_factory=dict)


class _Pars:
    """Hands out ``par[k]`` for values and records them."""

    def __init__(self, hy: Any) -> None:
        self.hy = hy
        self.values: list[float] = []

    def __call__(self, value: float) -> Any:
        self.values.append(float(value))
        return self.hy.par[len(self.values) - 1]


def _sum(hy: Any, terms: list[Any]) -> Any:
    if not terms:
        return hy.expression(0.0)
    if len(terms) == 1:
        return terms[0]
    return hy.sum(terms)


def _powers(gamma: Sequence[Any], degree: int) -> list[list[Any]]:
    out = []
    for g in gamma:
        row = [None, g]
        for _ in range(2, degree + 1):
            row.append(row[-1] * g)
        out.append(row)
    return out


def _monomial(powers: list[list[Any]], e: Sequence[int]) -> Any:
    factors = [powers[a][int(k)] for a, k in enumerate(e) if k > 0]
    if not factors:
        return None
    out = factors[0]
    for f in factors[1:]:
        out = out * f
    return out


def _reduced_terms(
    hy: Any, system: RigidBodySystem, gamma: list[Any], pars: _Pars
) -> tuple[list[Any], list[Any], tuple[Any, ...]]:
    """``D = dV/dgamma`` and ``M = mu`` of the physical effects from the polynomial bank."""
    bank = system.polynomial_bank  # the same bank as the scipy route (moment contractions)
    exps = [tuple(int(v) for v in e) for e in bank.exponents]
    coef = bank.coefficients[:, 1:7]
    used = [bool(np.any(coef[:, col] != 0.0)) for col in range(6)]
    powers = _powers(gamma, max(bank.degree, 1))
    out: list[list[Any]] = [[] for _ in range(6)]
    for k, e in enumerate(exps):
        mono = _monomial(powers, e)
        for col in range(6):
            if not used[col]:
                continue
            c = pars(coef[k, col])
            out[col].append(c if mono is None else c * mono)
    terms = [_sum(hy, t) for t in out]
    return terms[:3], terms[3:], ("reduced", tuple(exps), tuple(used))


def _direct_terms(
    hy: Any, system: RigidBodySystem, gamma: list[Any], pars: _Pars
) -> tuple[list[Any], list[Any], tuple[Any, ...]]:
    """``D`` and ``M`` element by element: the rows of the direct kernel."""
    kernel = system.direct_kernel()
    P = kernel.positions
    coeffs = kernel.coefficients  # (width, J)
    V = kernel.vectors  # (J, 15)
    groups = (slice(0, 3), slice(3, 6), slice(6, 15))
    D: list[list[Any]] = [[], [], []]
    M: list[list[Any]] = [[], [], []]
    T: list[list[Any]] = [[] for _ in range(9)]
    masks = []
    width = coeffs.shape[0]
    for j in range(kernel.rows):
        Z = pars(P[j, 0]) * gamma[0] + pars(P[j, 1]) * gamma[1] + pars(P[j, 2]) * gamma[2]
        # Horner's rule in Z, coefficients as parameters
        value = pars(coeffs[width - 1, j])
        for a in range(width - 2, -1, -1):
            value = value * Z + pars(coeffs[a, j])
        mask = tuple(bool(np.any(V[j, g] != 0.0)) for g in groups)
        masks.append(mask)
        if mask[0]:
            for i in range(3):
                D[i].append(value * pars(V[j, i]))
        if mask[1]:
            for i in range(3):
                M[i].append(value * pars(V[j, 3 + i]))
        if mask[2]:
            for i in range(9):
                T[i].append(value * pars(V[j, 6 + i]))
    Dx = [_sum(hy, t) for t in D]
    if kernel.has_matrix:
        Tx = [_sum(hy, t) for t in T]
        for i in range(3):
            Dx[i] = (
                Dx[i] + Tx[3 * i] * gamma[0] + Tx[3 * i + 1] * gamma[1] + Tx[3 * i + 2] * gamma[2]
            )
    return Dx, [_sum(hy, t) for t in M], ("direct", width, tuple(masks))


def _theorem_terms(
    hy: Any, system: RigidBodySystem, gamma: list[Any], pars: _Pars
) -> tuple[list[Any], list[Any], tuple[Any, ...]]:
    """``dV/dgamma`` and ``mu`` of the theorem from the sympy model (parameters as pars)."""
    from chargedesign.model.case import GAMMA, PARAMETER_SYMBOLS, lam, rho

    singular = bool(system.parameters.singular)
    values = evaluators.parameter_tuple(system.parameters)
    exprs = evaluators.model_expressions("potential_gradient") + evaluators.model_expressions(
        "gyroscopic"
    )
    if not singular:
        exprs = [e.xreplace({lam: 0, rho: 0}) for e in exprs]
    used = set().union(*(e.free_symbols for e in exprs))
    # only the parameters that occur (heyoka counts the parameters of the system)
    mapping = {
        sym: pars(v) for sym, v in zip(PARAMETER_SYMBOLS, values, strict=True) if sym in used
    }
    mapping.update({GAMMA[i]: gamma[i] for i in range(3)})
    memo: dict[Any, Any] = {}
    out = [_from_sympy(hy, e, mapping, memo) for e in exprs]
    return out[:3], out[3:], ("theorem", singular)


def _case_torque(hy: Any, torque: Any, gamma: list[Any], omega: Any) -> list[Any]:
    """A case's torque (sympy, in omega and gamma) as heyoka expressions, numbers as
    constants (the key holds the expressions: each case compiles its own code)."""
    from chargedesign.model.case import GAMMA, OMEGA

    mapping = {GAMMA[i]: gamma[i] for i in range(3)}
    mapping.update({OMEGA[i]: omega[i] for i in range(3)})
    memo: dict[Any, Any] = {}
    return [_from_sympy(hy, e, mapping, memo) for e in torque]


def _from_sympy(hy: Any, e: Any, mapping: dict[Any, Any], memo: dict[Any, Any]) -> Any:
    """A sympy polynomial / rational expression as a heyoka expression.

    Integer powers become products (heyoka's Taylor recursion of ``pow`` divides by the
    base, which is NaN where the base vanishes, e.g. gamma3 = 0 on the section); negative
    integer powers become ``1 / product``.
    """
    import sympy as sp

    if e in memo:
        return memo[e]
    if e in mapping:
        out = mapping[e]
    elif e.is_Number:
        out = hy.expression(float(e))
    elif e.is_Add:
        out = _sum(hy, [_from_sympy(hy, a, mapping, memo) for a in e.args])
    elif e.is_Mul:
        factors = [_from_sympy(hy, a, mapping, memo) for a in e.args]
        out = factors[0]
        for f in factors[1:]:
            out = out * f
    elif e.is_Pow and e.exp.is_Integer:
        n = int(e.exp)
        base = _from_sympy(hy, e.base, mapping, memo)
        prod = base
        for _ in range(abs(n) - 1):
            prod = prod * base
        out = prod if n > 0 else 1.0 / prod
    else:
        out = hy.from_sympy(sp.sympify(e), mapping)
    memo[e] = out
    return out


def build_equations(system: RigidBodySystem) -> Equations:
    """The equations of ``system`` as heyoka expressions (see the module docstring)."""
    hy = heyoka_module()
    if hy is None:
        raise SolverError(f"simulation: heyoka is not available ({unavailable_reason()})")
    p, q, r, w, x, y, z = hy.make_vars("p", "q", "r", "w", "x", "y", "z")
    nq = w * w + x * x + y * y + z * z
    inv = 1.0 / nq
    gamma = [
        2.0 * (x * z - w * y) * inv,
        2.0 * (y * z + w * x) * inv,
        (w * w - x * x - y * y + z * z) * inv,
    ]
    g1, g2, g3 = gamma
    pars = _Pars(hy)
    inv_C = pars(1.0 / system.C)
    key: list[Any] = [tuple(system.effects)]
    N = [hy.expression(0.0)] * 3
    parts = []
    if system.physical:
        if system.route == "direct":
            parts.append(_direct_terms(hy, system, gamma, pars))
        else:
            parts.append(_reduced_terms(hy, system, gamma, pars))
    if "theorem" in system.effects and system.case is None:
        parts.append(_theorem_terms(hy, system, gamma, pars))
    omega = (p, q, r)
    for D, M, part_key in parts:
        key.append(part_key)
        # gamma x D + M x omega
        N = [
            N[0] + g2 * D[2] - g3 * D[1] + M[1] * omega[2] - M[2] * omega[1],
            N[1] + g3 * D[0] - g1 * D[2] + M[2] * omega[0] - M[0] * omega[2],
            N[2] + g1 * D[1] - g2 * D[0] + M[0] * omega[1] - M[1] * omega[0],
        ]
    if "theorem" in system.effects and system.case is not None:
        # the case's torque derived from its Lagrangian (case_numeric.lagrangian_torque)
        import sympy as sp

        from chargedesign.model.case_numeric import lagrangian_torque

        torque = lagrangian_torque(system.case.case)
        key.append(("case", tuple(sp.srepr(e) for e in torque)))
        N = [a + b for a, b in zip(N, _case_torque(hy, torque, gamma, omega), strict=True)]
    if system.general_inertia:
        # I omega' = (I omega) x omega + N, I = diag(A, B, C)
        A, B, C = (float(m) for m in system.inertia)
        key.append("inertia")
        omega_dot = [
            pars((B - C) / A) * q * r + pars(1.0 / A) * N[0],
            pars((C - A) / B) * r * p + pars(1.0 / B) * N[1],
            pars((A - B) / C) * p * q + pars(1.0 / C) * N[2],
        ]
    else:
        omega_dot = [
            0.5 * q * r + 0.5 * inv_C * N[0],
            -0.5 * p * r + 0.5 * inv_C * N[1],
            inv_C * N[2],
        ]
    sys = [
        (p, omega_dot[0]),
        (q, omega_dot[1]),
        (r, omega_dot[2]),
        (w, -0.5 * (x * p + y * q + z * r)),
        (x, 0.5 * (w * p + y * r - z * q)),
        (y, 0.5 * (w * q + z * p - x * r)),
        (z, 0.5 * (w * r + x * q - y * p)),
    ]
    # heyoka expects as many values as the largest parameter index used + 1
    used = [int(str(e)[1:]) for e in hy.get_params([rhs for _, rhs in sys])]
    n_used = max(used) + 1 if used else 0
    return Equations(
        key=tuple(key),
        sys=sys,
        pars=np.array(pars.values[:n_used], dtype=float),
        variables=[p, q, r, w, x, y, z],
        gamma=gamma,
    )


def section_expression(eq: Equations, name: str) -> Any:
    """The expression of a state name (:data:`SECTION_NAMES`) in the equations' variables."""
    if name not in SECTION_NAMES:  # the scene's checked [output] poincare_section
        raise ValueError(f"poincare: {name!r} is not a section name")
    i = SECTION_NAMES.index(name)
    return eq.variables[i] if i < 3 else eq.gamma[i - 3]


# ------------------------------------------------------------------------ compiling
def _compact(eq: Equations) -> bool:
    """Compact mode for large systems (many parameters): much shorter compiles."""
    if COMPACT_MODE is not None:
        return bool(COMPACT_MODE)
    return len(eq.pars) > 200


@dataclass
class _Section:
    """A non-terminal event's records (filled by the heyoka callback)."""

    times: list[float] = field(default_factory=list)
    states: list[np.ndarray] = field(default_factory=list)
    which: list[int] = field(default_factory=list)

    def clear(self) -> None:
        self.times.clear()
        self.states.clear()
        self.which.clear()


class _Recorder:
    """The callback of a non-terminal event: dense output at the event's exact time."""

    def __init__(self, section: _Section, batch: bool) -> None:
        self.section = section
        self.batch = batch

    def __call__(self, ta: Any, t: float, d_sign: int, *rest: Any) -> None:
        if self.batch:
            i = int(rest[0])
            ta.update_d_output([t if k == i else ta.time[k] for k in range(ta.batch_size)])
            self.section.states.append(np.array(ta.d_output[:, i]))
            self.section.which.append(i)
        else:
            ta.update_d_output(t)
            self.section.states.append(np.array(ta.d_output))
        self.section.times.append(float(t))


@dataclass
class Compiled:
    """A compiled integrator and what it records."""

    ta: Any
    equations: Equations
    section: _Section | None
    compile_seconds: float
    reused: bool = False


def compiled_integrator(
    system: RigidBodySystem,
    *,
    tol: float = DEFAULT_TOL,
    batch: int = 1,
    section: str | None = None,
    singular_plane: bool = False,
    batch_mode: bool | None = None,
) -> Compiled:
    """The integrator of ``system`` (compiled once per structure, its parameters set).

    Parameters
    ----------
    system : RigidBodySystem
    tol : float
        heyoka's tolerance (default machine epsilon).
    batch : int
        1: ``taylor_adaptive``; > 1: ``taylor_adaptive_batch`` of that size.
    section : str, optional
        Record upward zero crossings of this state (a non-terminal event).
    singular_plane : bool
        A terminal event at ``|gamma3| = par`` (set by :func:`integrate_taylor`).

    Returns
    -------
    Compiled
        A private copy is not made: the integrator is shared by later calls of this process
        with the same structure (callers set time, state and parameters before each use).
    """
    hy = heyoka_module()
    if hy is None:
        raise SolverError(f"simulation: heyoka is not available ({unavailable_reason()})")
    eq = build_equations(system)
    use_batch = batch > 1 if batch_mode is None else bool(batch_mode)
    key = (eq.key, float(tol), int(batch), use_batch, section, bool(singular_plane), _compact(eq))
    with _LOCK:
        hit = _CACHE.get(key)
    if hit is not None:
        hit_eq: Equations = hit.equations
        if len(hit_eq.pars) != len(eq.pars):  # pragma: no cover - the key fixes the layout
            raise SolverError("simulation: heyoka parameter layout changed for a cached key")
        return Compiled(
            ta=hit.ta, equations=eq, section=hit.section, compile_seconds=0.0, reused=True
        )
    n_par = len(eq.pars) + (1 if singular_plane else 0)
    t_events = []
    nt_events = []
    rec = None
    if singular_plane:
        thr = hy.par[len(eq.pars)]
        g3 = eq.gamma[2]
        ev_cls = hy.t_event_batch if use_batch else hy.t_event
        t_events.append(ev_cls(g3 * g3 - thr * thr, direction=hy.event_direction.negative))
    if section is not None:
        rec = _Section()
        nt_cls = hy.nt_event_batch if use_batch else hy.nt_event
        nt_events.append(
            nt_cls(
                section_expression(eq, section),
                _Recorder(rec, use_batch),
                direction=hy.event_direction.positive,
            )
        )
    t0 = time.perf_counter()
    kwargs: dict[str, Any] = {"tol": tol, "compact_mode": _compact(eq)}
    if t_events:
        kwargs["t_events"] = t_events
    if nt_events:
        kwargs["nt_events"] = nt_events
    if use_batch:
        ta = hy.taylor_adaptive_batch(
            eq.sys, np.zeros((7, batch)), pars=np.zeros((n_par, batch)), **kwargs
        )
    else:
        ta = hy.taylor_adaptive(eq.sys, np.zeros(7), pars=np.zeros(n_par), **kwargs)
    seconds = time.perf_counter() - t0
    if rec is not None:
        # heyoka copies the callback into the integrator: record through its own copy
        rec = ta.nt_events[0].callback.section
    out = Compiled(ta=ta, equations=eq, section=rec, compile_seconds=seconds)
    with _LOCK:
        _CACHE[key] = out
    return out


# ----------------------------------------------------------------------- integrating
def _check_outcome(outcome: Any, where: str, t: float) -> int | None:
    """None for success / time limit; the event index of a terminal event; else raise."""
    hy = heyoka_module()
    value = int(outcome.value) if hasattr(outcome, "value") else int(outcome)
    if outcome in (hy.taylor_outcome.time_limit, hy.taylor_outcome.success):
        return None
    if -(2**32) < value < 0:
        return -value - 1  # terminal event index
    raise SolverError(
        f"simulation: taylor (heyoka) stopped near t = {fmt(t, CELL)} s: {outcome} ({where})"
    )


def integrate_taylor(
    system: RigidBodySystem,
    y0: np.ndarray,
    t_end: float,
    *,
    tol: float = DEFAULT_TOL,
    samples: int = 1001,
    gamma3_min: float | None = None,
    poincare: str | None = None,
    progress: Callable[[float], None] | None = None,
) -> Integration:
    """Integrate trajectories with heyoka; returns an :class:`.integration.Integration`.

    Samples are ``samples`` evenly spaced times from the Taylor series of each step (dense
    output at the tolerance, not a lower-order interpolant). One trajectory runs on the
    scalar integrator; several run on batch integrators of heyoka's SIMD width (each lane its
    own step size), chunk by chunk.
    """
    y0 = np.atleast_2d(np.asarray(y0, dtype=float))
    grid = np.linspace(0.0, t_end, samples)
    t0 = time.perf_counter()
    if len(y0) == 1:
        return _integrate_one(system, y0, grid, t_end, tol, gamma3_min, poincare, progress, t0)
    if poincare is not None:
        # simulate records a section of its one trajectory; batches and ensembles none
        raise ValueError(f"poincare: a section of a single trajectory, not of {len(y0)}")
    return _integrate_many(system, y0, grid, tol, gamma3_min, progress, t0)


def _integrate_one(
    system: RigidBodySystem,
    y0: np.ndarray,
    grid: np.ndarray,
    t_end: float,
    tol: float,
    gamma3_min: float | None,
    poincare: str | None,
    progress: Callable[[float], None] | None,
    t0: float,
) -> Integration:
    """One trajectory on the scalar integrator (dense output, section, terminal event)."""
    singular = gamma3_min is not None
    comp = compiled_integrator(system, tol=tol, section=poincare, singular_plane=singular)
    ta = comp.ta
    ta.time = 0.0
    ta.state[:] = y0[0]
    pars = comp.equations.pars
    if gamma3_min is not None:
        pars = np.append(pars, float(gamma3_min))
    ta.pars[:] = pars
    if comp.section is not None:
        comp.section.clear()
    if singular:
        ta.reset_cooldowns()
    run_t0 = time.perf_counter()
    kwargs: dict[str, Any] = {}
    if progress is not None:

        def cb(ta_: Any) -> bool:
            progress(min(ta_.time / t_end, 1.0))
            return True

        kwargs["callback"] = cb
    outcome, _, _, nsteps, _, states = ta.propagate_grid(grid, **kwargs)
    seconds = time.perf_counter() - run_t0
    hit = _check_outcome(outcome, "propagate_grid", float(ta.time))
    states = np.asarray(states, dtype=float)
    times = grid[: len(states)].copy()
    events: list[dict[str, Any]] = []
    if hit is not None:
        t_hit = float(ta.time)
        g3 = float(quaternion_gamma(np.asarray(ta.state)[None, 3:])[0, 2])
        events.append(singular_plane_event(t_hit, 0, g3, gamma3_min))
        times = np.append(times, t_hit)
        states = np.vstack([states, np.asarray(ta.state)[None]])
    points = None
    if comp.section is not None:
        ys = np.array(comp.section.states).reshape(-1, 7)
        ts = np.array(comp.section.times)
        points = np.column_stack(
            [ts, ys[:, :3], quaternion_gamma(ys[:, 3:]) if len(ys) else np.zeros((0, 3))]
        )
    if not np.all(np.isfinite(states)):
        raise SolverError("simulation: taylor (heyoka) produced non-finite states")
    return Integration(
        times=times,
        states=states[None],
        events=events,
        poincare=points,
        steps=int(nsteps),
        rhs_evaluations=0,
        seconds=seconds,
        extra={
            "compile_seconds": comp.compile_seconds,
            "compiled_reused": comp.reused,
            "total_seconds": time.perf_counter() - t0,
        },
    )


def _integrate_many(
    system: RigidBodySystem,
    y0: np.ndarray,
    grid: np.ndarray,
    tol: float,
    gamma3_min: float | None,
    progress: Callable[[float], None] | None,
    t0: float,
) -> Integration:
    """Several trajectories on batch integrators; a terminal event stops its own only."""
    ens = propagate_many(system, y0, grid, tol=tol, gamma3_min=gamma3_min, progress=progress)
    events = [
        singular_plane_event(
            float(ens.t_stop[i]), int(i), None, gamma3_min, stops="this trajectory only"
        )
        for i in np.flatnonzero(ens.stopped)
    ]
    # trajectories stopped early keep their last state (NaN rows are not returned)
    states = ens.states
    if np.any(ens.stopped):
        for i in np.flatnonzero(ens.stopped):
            bad = ~np.all(np.isfinite(states[i]), axis=1)
            if np.any(bad):
                first = int(np.argmax(bad))
                states[i, first:] = states[i, first - 1] if first > 0 else y0[i]
    return Integration(
        times=grid,
        states=states,
        events=events,
        steps=int(ens.steps.sum()),
        seconds=ens.seconds,
        extra={"compile_seconds": ens.compile_seconds, "total_seconds": time.perf_counter() - t0},
    )


def _scalar_grid(
    system: RigidBodySystem,
    y0: np.ndarray,
    grid: np.ndarray,
    tol: float,
    gamma3_min: float | None,
    section: str | None,
) -> tuple[np.ndarray, int, list[np.ndarray], float | None]:
    """One trajectory over ``grid`` on the scalar integrator.

    Returns the states (T, 7) (NaN after a terminal event), the steps, the section rows and
    the time of a terminal event (None without one).
    """
    comp = compiled_integrator(
        system, tol=tol, section=section, singular_plane=gamma3_min is not None
    )
    ta = comp.ta
    ta.time = 0.0
    ta.state[:] = y0
    pars = comp.equations.pars
    if gamma3_min is not None:
        pars = np.append(pars, float(gamma3_min))
        ta.reset_cooldowns()
    ta.pars[:] = pars
    if comp.section is not None:
        comp.section.clear()
    outcome, _, _, nsteps, _, values = ta.propagate_grid(np.asarray(grid, dtype=float))
    hit = _check_outcome(outcome, "ensemble", float(ta.time))
    out = np.full((len(grid), 7), np.nan)
    out[: len(values)] = values
    rows = []
    if comp.section is not None:
        rows = [
            np.concatenate([[t], st])
            for t, st in zip(comp.section.times, comp.section.states, strict=True)
        ]
    return out, int(nsteps), rows, (float(ta.time) if hit is not None else None)


@dataclass
class Ensemble:
    """Many trajectories of one structure (see :func:`propagate_many`).

    Attributes
    ----------
    times : ndarray, shape (T,)
    states : ndarray, shape (m, T, 7)
        NaN after a trajectory stopped at a terminal event.
    steps : ndarray, shape (m,)
    stopped : ndarray of bool, shape (m,)
    t_stop : ndarray, shape (m,)
        Time of the terminal event (``t_end`` when none).
    sections : list of ndarray, shape (k_i, 8)
        Per trajectory ``(t, p, q, r, w, x, y, z)`` at the section crossings.
    """

    times: np.ndarray
    states: np.ndarray
    steps: np.ndarray
    stopped: np.ndarray
    t_stop: np.ndarray
    sections: list[np.ndarray] | None
    seconds: float
    compile_seconds: float
    batch: int


def propagate_many(
    system: RigidBodySystem | Sequence[RigidBodySystem],
    y0: np.ndarray,
    grid: np.ndarray,
    *,
    tol: float = DEFAULT_TOL,
    gamma3_min: float | None = None,
    section: str | None = None,
    batch: int | None = None,
    threads: int | None = None,
    progress: Callable[[float], None] | None = None,
) -> Ensemble:
    """Propagate many states (and bodies of one structure) over a time grid.

    Parameters
    ----------
    system : RigidBodySystem or sequence of RigidBodySystem
        One system for every state, or one per state (same structure: same effects, route
        and monomials or element rows; only the numbers differ).
    y0 : ndarray, shape (m, 7)
    grid : ndarray, shape (T,)
        Output times from 0, increasing.
    tol : float
    gamma3_min : float, optional
        Terminal singular-plane event: it stops that trajectory only.
    section : str, optional
        Record upward zero crossings of this state for every trajectory (non-terminal: the
        others go on).
    batch : int, optional
        Lanes of the batch integrator (default: 4, or fewer when the CPU has fewer).
    threads : int, optional
        Worker threads (default: the CPU count); each owns one integrator copy.
    """
    from concurrent.futures import ThreadPoolExecutor

    hy = heyoka_module()
    if hy is None:
        raise SolverError(f"simulation: heyoka is not available ({unavailable_reason()})")
    y0 = np.atleast_2d(np.asarray(y0, dtype=float))
    m = len(y0)
    systems = list(system) if isinstance(system, Sequence) else [system] * m
    if len(systems) != m:
        raise ValueError(f"systems: expected {m} systems (one per state), got {len(systems)}")
    # 4 lanes on 2 threads measured fastest here (AVX-512 machine: 8 lanes were slower)
    B = int(batch or min(4, hy.recommended_simd_size()))
    B = max(1, min(B, m)) if m < B else B
    comp = compiled_integrator(
        systems[0],
        tol=tol,
        batch=B,
        section=section,
        singular_plane=gamma3_min is not None,
        batch_mode=True,
    )
    run = _EnsembleRun(
        comp=comp,
        systems=systems,
        y0=y0,
        pars=_ensemble_parameters(systems, comp, gamma3_min),
        grid=np.asarray(grid, dtype=float),
        batch=B,
        tol=tol,
        gamma3_min=gamma3_min,
        section=section,
        progress=progress,
    )
    n_threads = max(1, min(int(threads or os.cpu_count() or 1), run.n_chunks))
    t0 = time.perf_counter()
    plan = [list(range(k, run.n_chunks, n_threads)) for k in range(n_threads)]
    if n_threads == 1:
        run.work(plan[0], copy_integrator=False)
    else:
        with ThreadPoolExecutor(n_threads) as pool:
            list(pool.map(run.work, plan))
    seconds = time.perf_counter() - t0
    sec_out = None
    if section is not None:
        sec_out = [np.array(rows).reshape(-1, 8) for rows in run.sections]
    return Ensemble(
        times=run.grid,
        states=run.states,
        steps=run.steps,
        stopped=run.stopped,
        t_stop=run.t_stop,
        sections=sec_out,
        seconds=seconds,
        compile_seconds=comp.compile_seconds,
        batch=B,
    )


def _ensemble_parameters(
    systems: list[RigidBodySystem], comp: Compiled, gamma3_min: float | None
) -> np.ndarray:
    """The runtime parameters (m, n_par) of every state's system (one structure required),
    with the singular-plane threshold appended when set."""
    key0 = comp.equations.key
    par_rows = []
    cache_eq: dict[int, np.ndarray] = {}
    for s in systems:
        if id(s) not in cache_eq:
            eq = build_equations(s) if s is not systems[0] else comp.equations
            if eq.key != key0:
                raise ValueError("systems: expected bodies of one structure")
            cache_eq[id(s)] = eq.pars
        par_rows.append(cache_eq[id(s)])
    P = np.array(par_rows)  # (m, n_par)
    if gamma3_min is not None:
        P = np.column_stack([P, np.full(len(systems), float(gamma3_min))])
    return P


class _EnsembleRun:
    """The shared outputs of :func:`propagate_many`, filled chunk by chunk (``batch`` states
    a chunk) by worker threads, each on its own copy of the batch integrator."""

    def __init__(
        self,
        *,
        comp: Compiled,
        systems: list[RigidBodySystem],
        y0: np.ndarray,
        pars: np.ndarray,
        grid: np.ndarray,
        batch: int,
        tol: float,
        gamma3_min: float | None,
        section: str | None,
        progress: Callable[[float], None] | None,
    ) -> None:
        self.comp, self.systems, self.y0, self.pars = comp, systems, y0, pars
        self.grid, self.batch, self.tol = grid, batch, tol
        self.gamma3_min, self.section, self.progress = gamma3_min, section, progress
        m = len(y0)
        self.n_chunks = math.ceil(m / batch)
        self.states = np.full((m, len(grid), 7), np.nan)
        self.steps = np.zeros(m, dtype=np.int64)
        self.stopped = np.zeros(m, dtype=bool)
        self.t_stop = np.full(m, float(grid[-1]))
        self.sections: list[list[np.ndarray]] = [[] for _ in range(m)]
        self.grid2 = np.ascontiguousarray(np.repeat(grid[:, None], batch, axis=1))
        self.done = 0
        self.done_lock = threading.Lock()

    def work(self, chunks: list[int], copy_integrator: bool = True) -> None:
        """Run the ``chunks`` on one integrator (a private copy when ``copy_integrator``)."""
        local = copy.deepcopy(self.comp.ta) if copy_integrator else self.comp.ta
        rec = None
        if self.section is not None:
            # the copy's callback objects were copied with it: find its recorder
            rec = local.nt_events[0].callback.section
        for c in chunks:
            self.run_chunk(local, rec, c)
            if self.progress is not None:
                with self.done_lock:
                    self.done += 1
                    self.progress(self.done / self.n_chunks)

    def run_chunk(self, local: Any, rec: Any, chunk: int) -> None:
        """Propagate the states of one chunk on the batch integrator ``local``."""
        B, m = self.batch, len(self.y0)
        idx = np.arange(chunk * B, min((chunk + 1) * B, m))
        lanes = np.concatenate([idx, np.full(B - len(idx), idx[-1])])
        local.set_time(0.0)
        local.state[:] = self.y0[lanes].T
        local.pars[:] = self.pars[lanes].T
        if self.gamma3_min is not None:
            local.reset_cooldowns()
        if rec is not None:
            rec.clear()
        res = local.propagate_grid(self.grid2)
        out = np.asarray(res[-1])  # (T, 7, B)
        outcomes = local.propagate_res
        any_stop = False
        for lane, i in enumerate(idx):
            outcome = outcomes[lane][0]
            hit = _check_outcome(outcome, "ensemble", float(local.time[lane]))
            self.states[i] = out[:, :, lane]
            self.steps[i] = int(outcomes[lane][3])
            if hit is not None:
                self.stopped[i] = True
                self.t_stop[i] = float(local.time[lane])
                any_stop = True
            if rec is not None:
                self.sections[i] = [
                    np.concatenate([[t], st])
                    for t, st, w in zip(rec.times, rec.states, rec.which, strict=True)
                    if w == lane
                ]
        if any_stop:
            self.rerun_unstopped(idx, rec is not None)

    def rerun_unstopped(self, idx: np.ndarray, record: bool) -> None:
        """Run again, on the scalar integrator, the states of a chunk that did not stop.

        heyoka ends the grid output of the whole batch at a terminal event of one lane.
        """
        for i in idx:
            if self.stopped[i]:
                continue
            self.states[i], self.steps[i], rows, t_hit = _scalar_grid(
                self.systems[i], self.y0[i], self.grid, self.tol, self.gamma3_min, self.section
            )
            if t_hit is not None:
                self.stopped[i] = True
                self.t_stop[i] = t_hit
            if record:
                self.sections[i] = rows


# ------------------------------------------------------------ any symbolic system
def symbolic_integrator(variables: Sequence[Any], rhs: Sequence[Any], *, tol: float) -> Any:
    """heyoka's ``taylor_adaptive`` of ``x' = rhs(x)`` for sympy ``rhs`` in ``variables``.

    ``rhs`` are polynomial or rational sympy expressions in ``variables`` (numbers enter as
    constants); integer powers become products (see :func:`_from_sympy`). The integrator is
    compiled once per (expressions, tolerance) in this process and shared: callers set its
    time and state before each use.

    Raises
    ------
    SolverError
        heyoka cannot be imported.
    """
    import sympy as sp

    hy = heyoka_module()
    if hy is None:
        raise SolverError(f"simulation: heyoka is not available ({unavailable_reason()})")
    key = ("symbolic", tuple(sp.srepr(v) for v in variables), tuple(map(sp.srepr, rhs)), tol)
    with _LOCK:
        hit = _CACHE.get(key)
    if hit is not None:
        return hit
    names = [f"x{k}" for k in range(len(variables))]
    heyoka_vars = hy.make_vars(*names) if len(names) > 1 else [hy.make_vars(*names)]
    mapping = dict(zip(variables, heyoka_vars, strict=True))
    memo: dict[Any, Any] = {}
    sys = [
        (v, _from_sympy(hy, sp.sympify(e), mapping, memo))
        for v, e in zip(heyoka_vars, rhs, strict=True)
    ]
    ta = hy.taylor_adaptive(sys, np.zeros(len(sys)), tol=tol)
    with _LOCK:
        _CACHE[key] = ta
    return ta


def propagate_symbolic(
    variables: Sequence[Any], rhs: Sequence[Any], y0: np.ndarray, grid: np.ndarray, *, tol: float
) -> tuple[np.ndarray, int]:
    """States (T, n) of ``x' = rhs(x)`` from ``y0`` (n,) at ``grid`` (T,) (``grid[0]`` the
    start), heyoka's outcome checked; and the steps taken.

    Raises
    ------
    SolverError
        heyoka is unavailable, stopped before the grid's end or gave non-finite states.
    """
    ta = symbolic_integrator(variables, rhs, tol=tol)
    ta.time = float(grid[0])
    ta.state[:] = np.asarray(y0, dtype=float)
    outcome, _, _, nsteps, _, states = ta.propagate_grid(np.asarray(grid, dtype=float))
    hit = _check_outcome(outcome, "propagate_grid", float(ta.time))
    states = np.asarray(states, dtype=float)
    if hit is not None or len(states) < len(grid) or not np.all(np.isfinite(states)):
        raise SolverError(
            f"taylor (heyoka) stopped near t = {fmt(float(ta.time), CELL)} s before the grid's"
            " end or gave non-finite states"
        )
    return states, int(nsteps)
