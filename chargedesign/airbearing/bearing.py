"""The bearing: its style, the pedestal axis the design chooses, the tilt each motion needs,
the volume the pedestal sweeps, and planned motions that fit.

gamma is the lab's upward vertical in body axes (the theorem's Z is the lab's vertical, so
precession about Z is yaw, free on every bearing). The pedestal (or hanger) holds the ball
from below, along ``-u`` for a body-fixed unit vector u; the tilt is ``arccos(u . gamma)``.
Within a tilt limit ``theta`` the pedestal sweeps the cone about ``-u`` of half-angle
``theta + asin(rho / R_b)`` (rho the pedestal's radius, R_b the ball's) beyond the ball: the
keep-out cone no part may enter (the contract's formula, :func:`clear_of_cone`).

The largest tilt of a motion is over its torus, not one run: the motion is integrated (the
theorem's own equations, adaptive DOP853) over a horizon that doubles until a longer one no
longer raises the largest tilt by more than :data:`TILT_SETTLED_DEG` (:func:`largest_tilt`).
The axis u is the centre of the smallest cap holding every planned motion's gamma
(:func:`best_axis`). Motions that fit start near a stable relative equilibrium on I3 = 0
(found and typed by chargedesign.topology's public functions) at a chosen tilt
(:func:`fitting_starts`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from chargedesign.errors import InfeasibleError
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.physical.limits import close_pairs
from chargedesign.simulation.integrate import solve
from chargedesign.topology.chambers import LevelSampler, LevelSampling
from chargedesign.topology.compute import make_scales, resolve_range
from chargedesign.topology.critical import equilibria
from chargedesign.topology.equations import MomentumMap
from chargedesign.topology.stability import equilibrium_type, linearised_eigenvalues

#: a longer horizon raising the largest tilt by less than this (deg) has settled
TILT_SETTLED_DEG = 0.05
#: the horizon doubles at most this many times
HORIZON_DOUBLINGS = 5
#: samples per unit of (1 / the motion's fastest rate) when the tilt is read
SAMPLES_PER_RATE = 40
#: the largest tilt a planned motion takes on a full sphere (deg): big enough to tumble
FULL_SPHERE_PLANNED_DEG = 120.0


def tilt_deg(axis: np.ndarray, gammas: np.ndarray) -> np.ndarray:
    """Tilt (deg) of ``gammas`` (..., 3) from the unit ``axis`` (3,)."""
    return np.degrees(np.arccos(np.clip(gammas @ axis, -1.0, 1.0)))


@dataclass(frozen=True)
class Sampled:
    """One motion sampled over its settled horizon: times (s), gammas (S, 3), horizon (s),
    and whether the last doubling raised the largest tilt by less than TILT_SETTLED_DEG."""

    times: np.ndarray
    gammas: np.ndarray
    horizon_s: float
    settled: bool = True


def motion_samples(
    params: Parameters,
    x0: np.ndarray,
    horizon_s: float,
    rate: float,
    axis: np.ndarray | None,
    rhs: Any = None,
) -> Sampled:
    """The theorem's motion (or ``rhs(t, y)``'s, a case's) from ``x0`` over a horizon that
    starts at ``horizon_s`` and doubles until the largest tilt from ``axis`` (or, without one,
    from the best axis of the samples so far) settles to :data:`TILT_SETTLED_DEG`."""
    f = evaluators.rhs_function(params) if rhs is None else rhs
    times = [np.zeros(1)]
    gammas = [np.asarray(x0[3:6], float)[None]]
    state, t0, span = np.asarray(x0[:6], float), 0.0, horizon_s
    last = None
    settled = False
    for _ in range(HORIZON_DOUBLINGS + 1):
        count = max(2, math.ceil(span * rate * SAMPLES_PER_RATE))
        t_eval = np.linspace(t0, t0 + span, count + 1)[1:]
        sol = solve(
            f,
            state,
            (t0, t0 + span),
            t_eval=t_eval,
            method="DOP853",
            rtol=1e-10,
            atol=1e-12,
            what="testbed: the planned motion's integration",
        )
        times.append(sol.t)
        gammas.append(sol.y[:, 3:6])
        state, t0 = sol.end, t0 + span
        everything = np.concatenate(gammas)
        u = axis if axis is not None else best_axis([everything])
        tilt = float(tilt_deg(u, everything).max())
        if last is not None and tilt - last < TILT_SETTLED_DEG:
            settled = True
            break
        last = tilt
        span = t0  # the horizon doubles
    return Sampled(np.concatenate(times), np.concatenate(gammas), t0, settled)


def best_axis(gamma_sets: list[np.ndarray]) -> np.ndarray:
    """The unit axis whose largest angle to every gamma of every set is least: the centre of
    the smallest spherical cap holding them (Badoiu-Clarkson steps toward the farthest
    point, then Nelder-Mead on the largest angle)."""
    from scipy.optimize import minimize

    points = np.concatenate(gamma_sets)
    points = points[:: max(1, len(points) // 20000)]
    u = points.mean(axis=0)
    u = u / np.linalg.norm(u) if np.linalg.norm(u) > 1e-9 else points[0]
    for k in range(1, 200):
        far = points[int(np.argmin(points @ u))]
        u = u + (far - u) / (k + 1)
        u /= np.linalg.norm(u)

    def largest(angles: np.ndarray) -> float:
        return float(tilt_deg(_unit(angles), points).max())

    start = np.array([math.acos(max(-1.0, min(1.0, u[2]))), math.atan2(u[1], u[0])])
    result = minimize(
        largest,
        start,
        method="Nelder-Mead",
        options={"xatol": 1e-7, "fatol": 1e-7, "maxiter": 2000},
    )
    return _unit(result.x) if result.fun <= largest(start) else u


def _unit(angles: np.ndarray) -> np.ndarray:
    theta, phi = angles
    return np.array(
        [math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)]
    )


@dataclass(frozen=True)
class KeepOut:
    """The pedestal's swept cone: apex at O about ``axis``, ``half_angle_deg``, beyond
    ``inner_radius_m``."""

    axis: np.ndarray
    half_angle_deg: float
    inner_radius_m: float

    def to_dict(self) -> dict:
        return {
            "axis": self.axis.tolist(),
            "half_angle_deg": self.half_angle_deg,
            "inner_radius_m": self.inner_radius_m,
        }


def keep_out(
    u: np.ndarray, tilt_limit_deg: float, ball_radius: float, pedestal_radius: float
) -> KeepOut | None:
    """The cone the pedestal sweeps within the tilt limit (None for a full sphere)."""
    if tilt_limit_deg >= 180.0:
        return None
    width = math.degrees(math.asin(min(1.0, pedestal_radius / ball_radius)))
    return KeepOut(-np.asarray(u, float), tilt_limit_deg + width, ball_radius)


def clear_of_cone(centres: np.ndarray, radii: np.ndarray, cone: KeepOut | None) -> np.ndarray:
    """Which spheres (centres (n, 3), radii (n,)) are clear of the cone: the angle between
    the centre and the axis, less ``asin(a / |c|)``, at least the half-angle."""
    if cone is None:
        return np.ones(len(centres), bool)
    dist = np.linalg.norm(centres, axis=1)
    angle = np.degrees(np.arccos(np.clip(centres @ cone.axis / np.maximum(dist, 1e-300), -1, 1)))
    reach = np.degrees(np.arcsin(np.clip(radii / np.maximum(dist, 1e-300), 0.0, 1.0)))
    return angle - reach >= cone.half_angle_deg


def on_level(params: Parameters, gamma: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """``(omega', gamma)`` on I3 = 0: omega less its part along gamma that breaks
    ``(I omega + l) . gamma = 0`` (works for every gamma, gamma3 = 0 included)."""
    g = np.asarray(gamma, float) / np.linalg.norm(gamma)
    inertia = np.array([2.0 * params.C, 2.0 * params.C, params.C])
    l_vec = evaluators.angular_potential(g, params)
    shift = (float((inertia * omega) @ g) + float(l_vec @ g)) / float(g @ (inertia * g))
    return np.concatenate([np.asarray(omega, float) - shift * g, g])


@cache
def level_map(params: Parameters) -> tuple[MomentumMap, tuple[float, float]]:
    """(H, I4) on I3 = 0 and the diagram's default energy range (chargedesign.topology)."""
    F = MomentumMap(params)
    h_range, _ = resolve_range(F, None)
    return F, h_range


@dataclass(frozen=True)
class TiltMap:
    """The tilt (deg) from the pedestal axis that the tori over each (h, k) of the
    bifurcation diagram need: ``tilt`` (energies, quartics), NaN where the level is empty.

    Over each energy the level is sampled by chargedesign.topology's LevelSampler (a
    Fibonacci grid of gamma, the conic of states over each; ``points(k)`` the states where
    I4 = k). The points are split into tori: pieces whose points lie within
    :data:`TORUS_JOIN` grid spacings of each other (single linkage). Each torus needs the
    largest tilt of its points; the map gives the least of these over the tori of (h, k): the
    torus the bearing hosts best. The grid's spacing bounds the error (about 3 deg). The
    tori near a stable equilibrium lie in a thin band of I4 under the elliptic periodic
    orbits that bound the level (the planned motions sit there): each energy's top cells;
    tori above the sampled maximum of I4 are not shown."""

    h: np.ndarray
    k: np.ndarray
    tilt: np.ndarray
    limit_deg: float

    def to_dict(self) -> dict:
        return {
            "h_J": self.h.tolist(),
            "I4": self.k.tolist(),  # (energies, quartics): each energy's own I4 values
            "tilt_max_deg": [[None if np.isnan(v) else float(v) for v in row] for row in self.tilt],
            "limit_deg": self.limit_deg,
            "gamma_grid": TILT_MAP_GAMMAS,
        }


#: the tilt map's resolution: energies, I4 values, gamma grid points and conic angles
TILT_MAP_SHAPE = (16, 16)
TILT_MAP_GAMMAS = 2000
TILT_MAP_ANGLES = 32


def tilt_map(
    params: Parameters, axis: np.ndarray, limit_deg: float, h_top: float | None = None
) -> TiltMap:
    """The tilt map from the least energy on the level to ``h_top`` (default: the diagram's
    default range), each energy's I4 from its least to its largest on the level (see
    :class:`TiltMap`): ``k`` is then (energies, quartics) too."""
    F, (h_low, h_high) = level_map(params)
    energies, quartics = TILT_MAP_SHAPE
    top = h_high if h_top is None else min(h_top, h_high)
    hs = np.linspace(h_low, top, energies + 1)[1:]
    out = np.full((energies, quartics), np.nan)
    ks = np.zeros((energies, quartics))
    for i, h in enumerate(hs):
        s = LevelSampler(F, float(h), LevelSampling(TILT_MAP_GAMMAS, TILT_MAP_ANGLES))
        if not s.quartic.size:
            continue
        low, high = float(s.quartic.min()), float(s.quartic.max())
        ks[i] = low + (high - low) * (np.arange(quartics) + 0.5) / quartics
        for j, k in enumerate(ks[i]):
            pts = s.points(float(k))
            if len(pts):
                out[i, j] = _hosted_tilt(pts, axis, TORUS_JOIN * s.spacing)
    return TiltMap(hs, ks, out, limit_deg)


#: points of one torus lie within this many grid spacings of another of its points
TORUS_JOIN = 3.0


def _hosted_tilt(points: np.ndarray, axis: np.ndarray, join: float) -> float:
    """The least, over the tori among ``points`` (scaled states), of their largest tilt: a
    torus is a component of the points at most ``join`` apart (:func:`close_pairs`)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pairs = close_pairs(points, join)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(points),) * 2)
    count, labels = connected_components(graph, directed=False)
    tilts = tilt_deg(axis, points[:, 3:6] / np.linalg.norm(points[:, 3:6], axis=1, keepdims=True))
    largest = np.full(count, -np.inf)
    np.maximum.at(largest, labels, tilts)
    return float(largest.min())


def stable_equilibria(params: Parameters) -> list[np.ndarray]:
    """The stable (centre-centre) relative equilibria on I3 = 0, states (6,), least energy
    first (chargedesign.topology's public functions)."""
    F, h_range = level_map(params)
    scales = make_scales(F, h_range)
    found = equilibria(F, scales)
    stable = [
        (float(hk[0]), z[:6])
        for z, hk in zip(found.z, found.hk, strict=True)
        if equilibrium_type(linearised_eigenvalues(F, z, scales)) == "centre-centre"
    ]
    return [z for _, z in sorted(stable, key=lambda item: item[0])]


def fitting_starts(params: Parameters, tilts_deg: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """Starts on I3 = 0 whose motions stay within the given tilts of the stable equilibrium.

    Each start turns the equilibrium's gamma_e by the tilt toward the body axis most normal
    to it (the critical equator family keeps I4 = 0: the start leaves it) and keeps the
    equilibrium's spin ``omega = w gamma`` (projected on I3 = 0): the motion then starts at
    its turning point, farthest from gamma_e. Returns (starts (k, 6), gamma_e (3,)).

    Raises
    ------
    InfeasibleError
        When the parameters have no stable relative equilibrium on I3 = 0.
    """
    stable = stable_equilibria(params)
    if not stable:
        raise InfeasibleError(
            "testbed: these parameters have no stable relative equilibrium on I3 = 0 to plan "
            "small motions around; give initial_gamma, initial_p, initial_q and a "
            "full_sphere bearing"
        )
    eq = stable[0]
    gamma_e = eq[3:6] / np.linalg.norm(eq[3:6])
    spin = float(eq[0:3] @ gamma_e)
    axis = np.eye(3)[int(np.argmin(np.abs(gamma_e)))]
    normal = axis - (axis @ gamma_e) * gamma_e
    normal /= np.linalg.norm(normal)
    starts = []
    for tilt in tilts_deg:
        a = math.radians(tilt)
        g = math.cos(a) * gamma_e + math.sin(a) * normal
        starts.append(on_level(params, g, spin * g))
    return np.array(starts), gamma_e


__all__ = [
    "FULL_SPHERE_PLANNED_DEG",
    "KeepOut",
    "Sampled",
    "TiltMap",
    "best_axis",
    "clear_of_cone",
    "fitting_starts",
    "keep_out",
    "motion_samples",
    "on_level",
    "stable_equilibria",
    "tilt_deg",
    "tilt_map",
]
