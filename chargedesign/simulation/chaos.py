"""Poincare atlases and the fast Lyapunov indicator (heyoka: events and variational equations).

What "conditionally integrable" looks like: on the level ``I3 = 0`` the theorem's I4 is a
second integral besides the energy, the motion on an energy level lies on tori and a Poincare
section shows invariant curves; off the level (``I3 != 0``) at the same energy the section
shows a chaotic sea. The fast Lyapunov indicator (FLI, ``max_t log |Phi(t) v|`` for the
tangent flow ``Phi`` from the variational equations) grows like ``log t`` on tori and like
``lambda t`` on chaotic orbits.

Section: ``gamma3 = 0`` crossed upwards (``gamma3' = gamma1 q - gamma2 p > 0``). On it the
level fixes ``u = p cos(phi) + q sin(phi) = (I3 - L(gamma)) / (2C)`` with
``gamma = (cos phi, sin phi, 0)``; ``v = gamma3' > 0`` and the energy fix the rest:
``r^2 = (2 (E - V(gamma)) - 2C (u^2 + v^2)) / C``. The chart of the section is
``(phi, r)``.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.errors import InputError, SolverError
from chargedesign.files import atomic_path
from chargedesign.formatting import CELL, PLAIN, PRECISE, fmt
from chargedesign.scene.keys import KEY
from chargedesign.scene.simulation import DEFAULT_INITIAL
from chargedesign.simulation import taylor
from chargedesign.simulation.api import initial_state
from chargedesign.simulation.system import (
    RigidBodySystem,
    attitude_from_gamma,
    quaternion_gamma,
    rotation_quaternion,
)
from chargedesign.validation import as_finite_float, input_error


def section_state(
    system: RigidBodySystem,
    phi: float,
    v: float,
    energy: float,
    level: float = 0.0,
    sign: float = 1.0,
) -> np.ndarray | None:
    """The 7-state on the section at angle ``phi`` with ``gamma3' = v``, the given energy and
    level of I3, ``r`` of the given sign, or None (the energy too low there)."""
    C = system.C
    g = np.array([math.cos(phi), math.sin(phi), 0.0])
    R = attitude_from_gamma(g)
    L = float(system.momentum_potential(g[None], R[None])[0])
    V = float(system.energy(g[None], R[None])[0])
    u = (level - L) / (2.0 * C)
    r2 = (2.0 * (energy - V) - 2.0 * C * (u * u + v * v)) / C
    if not r2 >= 0.0:
        return None
    p = u * math.cos(phi) - v * math.sin(phi)
    q = u * math.sin(phi) + v * math.cos(phi)
    quat = rotation_quaternion(R)
    return np.concatenate([[p, q, sign * math.sqrt(r2)], quat])


def section_starts(
    system: RigidBodySystem, energy: float, level: float, orbits: int, seed: int = 0
) -> np.ndarray:
    """``orbits`` states on the section ``gamma3 = 0`` (upwards) at energy and level.

    Returns
    -------
    ndarray, shape (orbits, 7)

    Raises
    ------
    InputError
        The energy is too low for the level on most of the section.
    """
    rng = np.random.default_rng(seed)
    out: list[np.ndarray] = []
    tries = 0
    while len(out) < orbits and tries < 200 * orbits:
        tries += 1
        phi = rng.uniform(0.0, 2.0 * math.pi)
        v = rng.uniform(0.0, 2.0) * math.sqrt(max(energy, 1e-300) / system.C) / 2.0
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        state = section_state(system, phi, v, energy, level, sign)
        if state is not None:
            out.append(state)
    if len(out) < orbits:
        raise InputError(
            f"poincare: energy {fmt(energy, PLAIN)} J is too low for the level I3 ="
            f" {fmt(level, PLAIN)} J s on the "
            "section gamma3 = 0; raise the energy"
        )
    return np.array(out)


@dataclass
class PoincareAtlas:
    """Section points of many orbits on one energy level, on and off ``I3 = 0``.

    Attributes
    ----------
    energy : float
        J.
    levels : tuple of float
        The two levels of I3 (J s): ``(0, off)``.
    points : list of list of ndarray
        ``points[k][i]``: orbit ``i`` on level ``k``, rows ``(t, p, q, r, g1, g2, g3)``.
    """

    energy: float
    levels: tuple[float, float]
    points: list[list[np.ndarray]]
    t_end: float
    seconds: float

    def table(self) -> np.ndarray:
        """Rows ``(level, orbit, t, p, q, r, gamma1, gamma2, gamma3, phi)``."""
        rows = []
        for k, level in enumerate(self.levels):
            for i, pts in enumerate(self.points[k]):
                if len(pts) == 0:
                    continue
                phi = np.arctan2(pts[:, 5], pts[:, 4])
                rows.append(
                    np.column_stack([np.full(len(pts), level), np.full(len(pts), i), pts, phi])
                )
        return np.vstack(rows) if rows else np.zeros((0, 10))

    def write_csv(self, path: str | os.PathLike[str]) -> None:
        """The section points as CSV (header ``level, orbit, t, p, q, r, gamma1, ...``)."""
        header = "level,orbit,t,p,q,r,gamma1,gamma2,gamma3,phi"

        with atomic_path(path) as tmp:
            np.savetxt(tmp, self.table(), delimiter=",", header=header, comments="", fmt="%.17g")

    def plot(self, axes: Any = None) -> Any:
        """Side-by-side sections ``(phi, r)``, coloured by orbit; returns the figure."""
        from matplotlib.figure import Figure

        if axes is None:
            fig = Figure(figsize=(12, 5.5))
            axes = fig.subplots(1, 2, sharey=True)
        else:
            fig = axes[0].figure
        for ax, level, orbits in zip(axes, self.levels, self.points, strict=True):
            colours = _colours(len(orbits))
            for i, pts in enumerate(orbits):
                if len(pts):
                    phi = np.arctan2(pts[:, 5], pts[:, 4])
                    ax.plot(phi, pts[:, 3], ".", ms=1.2, color=colours[i])
            kind = "I4 is an integral: invariant curves" if level == 0 else "I4 is no integral"
            ax.set_title(f"I3 = {fmt(level, PLAIN)} J s ({kind})", fontsize=10)
            ax.set_xlabel("phi = atan2(gamma2, gamma1) on gamma3 = 0 (upwards) [rad]")
            ax.grid(True, alpha=0.3)
        axes[0].set_ylabel("r [1/s]")
        # the colour carries the orbit's number (its start, in order): its bar
        from matplotlib import colormaps
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import Normalize

        count = max(len(self.points[0]), 1)
        shades = ScalarMappable(Normalize(1, max(count, 2)), colormaps["turbo"])
        fig.colorbar(shades, ax=list(axes), label="orbit (in the order of its start)")
        fig.suptitle(
            f"Poincare atlas: {len(self.points[0])} orbits per level, energy"
            f" {fmt(self.energy, PRECISE)} J, "
            f"t = {fmt(self.t_end, PLAIN)} s"
        )
        return fig


def _colours(n: int) -> list[Any]:
    from matplotlib import colormaps

    cmap = colormaps["turbo"]
    return [cmap(i / max(n - 1, 1)) for i in range(n)]


def section_points(system: RigidBodySystem, starts: np.ndarray, t_end: float) -> list[np.ndarray]:
    """Each orbit's upward crossings of ``gamma3 = 0`` from ``starts`` (m, 7) over
    ``[0, t_end]`` as rows ``(t, omega, gamma)`` (heyoka's non-terminal event; gamma from the
    states' quaternions)."""
    ens = taylor.propagate_many(system, starts, np.array([0.0, t_end]), section="gamma3")
    orbit_points = []
    for rows in ens.sections or []:
        if len(rows) == 0:
            orbit_points.append(np.zeros((0, 7)))
            continue
        gam = quaternion_gamma(rows[:, 4:])
        orbit_points.append(np.column_stack([rows[:, 0], rows[:, 1:4], gam]))
    return orbit_points


def poincare_atlas(
    system: RigidBodySystem,
    *,
    energy: float | None = None,
    off_level: float | None = None,
    orbits: int = 50,
    t_end: float = 500.0,
    seed: int = 0,
) -> PoincareAtlas:
    """Section ``gamma3 = 0`` (upwards) of ``orbits`` orbits on I3 = 0 and on ``off_level``.

    Parameters
    ----------
    system : RigidBodySystem
    energy : float, optional
        J; default: the energy of the default start (gamma = (0.36, 0.48, 0.8), p = 0.6,
        q = -0.4 on I3 = 0).
    off_level : float, optional
        The second level of I3, J s (default ``0.5 C`` in J s: half the momentum of a spin
        of 1 rad/s about the symmetry axis, the CLI's ``--off-level`` example).
    orbits : int
        Orbits per level (each from its own section point).
    t_end : float
        Duration of each orbit, s.

    Notes
    -----
    The event is non-terminal: each orbit's crossings are located (to round-off in time, by
    heyoka's event detection on the Taylor series) without stopping the other orbits of the
    same batch.
    """
    if not taylor.available():
        raise SolverError(f"poincare atlas: needs heyoka ({taylor.unavailable_reason()})")
    if energy is None:
        y0, _ = initial_state(system, DEFAULT_INITIAL)
        energy = float(system.integrals(y0[None])[0, 0])
    t0 = time.perf_counter()
    points = []
    levels = (0.0, float(0.5 * system.C if off_level is None else off_level))
    for level in levels:
        points.append(
            section_points(system, section_starts(system, energy, level, orbits, seed), t_end)
        )
    return PoincareAtlas(
        energy=float(energy),
        levels=levels,
        points=points,
        t_end=float(t_end),
        seconds=time.perf_counter() - t0,
    )


# ----------------------------------------------------------------------------- FLI
_VAR_CACHE: dict[tuple[Any, ...], Any] = {}


#: the tangent vector the indicators start from: a perturbation of the angular velocity (the
#: quaternion's norm and the turn about Z are symmetries and would add nothing)
TANGENT_START = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]) / math.sqrt(3.0)


def _variational_integrator(system: RigidBodySystem, tol: float | None, what: str) -> Any:
    """``(heyoka, equations, integrator)`` of the state and its tangent flow ``Phi`` (7 + 49
    equations, heyoka's ``var_ode_sys``), compiled once per system and tolerance."""

    hy = taylor.heyoka_module()
    if hy is None:
        raise SolverError(f"{what}: needs heyoka ({taylor.unavailable_reason()})")
    eq = taylor.build_equations(system)
    tol_value = taylor.DEFAULT_TOL if tol is None else float(tol)
    key = (eq.key, tol_value)
    ta = _VAR_CACHE.get(key)
    if ta is None:
        vsys = hy.var_ode_sys(eq.sys, hy.var_args.vars, order=1)
        ta = hy.taylor_adaptive(
            vsys,
            np.zeros(7),
            pars=np.zeros(len(eq.pars)),
            tol=tol_value,
            # the tangent flow is 49 more equations: compact mode compiles in seconds, not
            # minutes (measured: the full unrolled form took over 10 minutes to compile)
            compact_mode=True,
        )
        _VAR_CACHE[key] = ta
    return hy, eq, ta


def _restart(ta: Any, eq: Any, y0: np.ndarray) -> None:
    """The variational integrator at t = 0 from ``y0``, with ``Phi(0)`` the identity
    (row-major ``d x_i / d x0_j``) and the body's parameters."""
    ta.time = 0.0
    ta.state[:7] = y0
    ta.state[7:] = np.eye(7).reshape(-1)
    ta.pars[:] = eq.pars


def fast_lyapunov_indicator(
    system: RigidBodySystem,
    states: np.ndarray,
    t_end: float,
    *,
    samples: int = 64,
    tol: float | None = None,
) -> np.ndarray:
    """The FLI ``max_{t <= t_end} log |Phi(t) w|`` of each state, ndarray shape (m,).

    ``Phi`` is the tangent flow from heyoka's first-order variational equations
    (``var_ode_sys`` with respect to the initial state); ``w`` is :data:`TANGENT_START`. The
    maximum is over ``samples`` times.

    Parameters
    ----------
    system : RigidBodySystem
    states : ndarray, shape (m, 7)
    t_end : float
        s.
    """
    hy, eq, ta = _variational_integrator(system, tol, "FLI")
    states = np.atleast_2d(np.asarray(states, dtype=float))
    w = TANGENT_START
    grid = np.linspace(0.0, t_end, samples)
    out = np.empty(len(states))
    n = 7
    for i, y0 in enumerate(states):
        _restart(ta, eq, y0)
        outcome, *_, values = ta.propagate_grid(grid)
        if outcome != hy.taylor_outcome.time_limit:
            raise SolverError(f"FLI: heyoka stopped at t = {fmt(ta.time, CELL)} s: {outcome}")
        phi = np.asarray(values)[:, n:].reshape(len(grid), n, n)
        growth = np.linalg.norm(phi @ w, axis=1)
        out[i] = float(np.log(np.max(growth)))
    return out


def lyapunov_exponent(
    system: RigidBodySystem,
    states: np.ndarray,
    t_end: float,
    *,
    interval: float = 1.0,
    tol: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The largest Lyapunov exponent of each state, as its running estimate (Benettin).

    The tangent vector ``v`` (from :data:`TANGENT_START`) is carried by the tangent flow
    ``Phi`` of heyoka's variational equations over each ``interval``, its growth logged and
    the vector renormalised (``Phi`` restarts from the identity, so it never overflows):
    ``lambda(t_k) = sum_j log |v_j| / t_k``. It tends to the largest exponent; on a torus it
    falls like ``log t / t`` towards 0, on a chaotic orbit it settles at a positive value.

    Parameters
    ----------
    system : RigidBodySystem
    states : ndarray, shape (m, 7)
    t_end : float
        s (> 0).
    interval : float
        Renormalisation interval, s (> 0, at most ``t_end``).

    Returns
    -------
    times : ndarray, shape (k,)
        The renormalisation times, s.
    estimates : ndarray, shape (m, k)
        ``lambda(t_k)`` per state, 1/s.
    """
    t_end = as_finite_float(t_end, KEY.t_end, positive=True)
    interval = as_finite_float(interval, "interval", positive=True)
    if interval > t_end:
        raise input_error(
            "interval", f"a duration of at most t_end = {fmt(t_end, PLAIN)} s", interval
        )
    hy, eq, ta = _variational_integrator(system, tol, "Lyapunov exponent")
    states = np.atleast_2d(np.asarray(states, dtype=float))
    times = interval * np.arange(1, math.floor(t_end / interval + 1e-9) + 1)
    out = np.empty((len(states), len(times)))
    for i, y0 in enumerate(states):
        _restart(ta, eq, y0)
        out[i] = _benettin_estimates(hy, ta, times)
    return times, out


def _benettin_estimates(hy: Any, ta: Any, times: np.ndarray) -> np.ndarray:
    """One state's running estimates at ``times``: the tangent vector carried over each
    interval, its growth logged, renormalised, the tangent flow restarted from the identity."""
    n = 7
    identity = np.eye(n).reshape(-1)
    estimates = np.empty(len(times))
    v = TANGENT_START.copy()
    total = 0.0
    for k, t in enumerate(times):
        outcome = ta.propagate_until(float(t))[0]
        if outcome != hy.taylor_outcome.time_limit:
            raise SolverError(f"Lyapunov exponent: heyoka stopped at t = {fmt(ta.time, CELL)} s")
        v = np.asarray(ta.state[n:]).reshape(n, n) @ v
        growth = float(np.linalg.norm(v))
        total += math.log(growth)
        v /= growth
        ta.state[n:] = identity
        estimates[k] = total / t
    return estimates


@dataclass
class FLIMap:
    """FLI over a grid of section points ``(phi, v)`` on and off ``I3 = 0``."""

    phi: np.ndarray
    v: np.ndarray
    fli: list[np.ndarray]  # per level, shape (len(v), len(phi)), NaN where no state
    levels: tuple[float, ...]
    energy: float
    t_end: float
    seconds: float

    def plot(self, axes: Any = None) -> Any:
        from matplotlib.figure import Figure

        if axes is None:
            fig = Figure(figsize=(12, 5))
            axes = fig.subplots(1, 2, sharey=True)
        else:
            fig = axes[0].figure
        finite: np.ndarray = (
            np.concatenate([f[np.isfinite(f)] for f in self.fli]) if self.fli else np.zeros(0)
        )
        vmin, vmax = (float(np.min(finite)), float(np.max(finite))) if len(finite) else (0, 1)
        image = None
        for ax, level, values in zip(axes, self.levels, self.fli, strict=True):
            image = ax.pcolormesh(
                self.phi, self.v, values, shading="nearest", cmap="magma", vmin=vmin, vmax=vmax
            )
            ax.set_title(f"FLI, I3 = {fmt(level, PLAIN)} J s", fontsize=10)
            ax.set_xlabel("phi on gamma3 = 0 [rad]")
        axes[0].set_ylabel("v = gamma3' [1/s]")
        if image is not None:
            fig.colorbar(image, ax=list(axes), label=f"FLI at t = {fmt(self.t_end, PLAIN)} s")
        fig.suptitle(f"Fast Lyapunov indicator, energy {fmt(self.energy, PRECISE)} J (r >= 0 half)")
        return fig


def fli_map(
    system: RigidBodySystem,
    *,
    energy: float | None = None,
    off_level: float | None = None,
    n_phi: int = 24,
    n_v: int = 12,
    t_end: float = 100.0,
    on_level_only: bool = False,
) -> FLIMap:
    """The FLI over a ``(phi, v)`` grid of the section at one energy, on and off I3 = 0
    (``on_level_only``: on I3 = 0 alone, half the cost)."""
    if energy is None:
        y0, _ = initial_state(system, DEFAULT_INITIAL)
        energy = float(system.integrals(y0[None])[0, 0])
    t0 = time.perf_counter()
    phi = np.linspace(0.0, 2.0 * math.pi, n_phi, endpoint=False)
    v = np.linspace(0.05, 1.0, n_v) * math.sqrt(max(energy, 1e-300) / system.C)
    levels: tuple[float, ...] = (0.0,)
    if not on_level_only:
        levels += (float(0.5 * system.C if off_level is None else off_level),)
    maps = []
    for level in levels:
        values = np.full((n_v, n_phi), np.nan)
        starts, where = [], []
        for a, ph in enumerate(phi):
            for b, vv in enumerate(v):
                state = section_state(system, float(ph), float(vv), energy, level, 1.0)
                if state is not None:
                    starts.append(state)
                    where.append((b, a))
        if starts:
            fl = fast_lyapunov_indicator(system, np.array(starts), t_end)
            for (b, a), f in zip(where, fl, strict=True):
                values[b, a] = f
        maps.append(values)
    return FLIMap(
        phi=phi,
        v=v,
        fli=maps,
        levels=levels,
        energy=float(energy),
        t_end=float(t_end),
        seconds=time.perf_counter() - t0,
    )
