"""Chambers of the diagram: how many Liouville tori lie over a point (h, k), by the flow.

The level ``F^-1(h, k)`` (on ``|gamma| = 1, I3 = 0``) is sampled on a Fibonacci grid of
gamma: over each gamma the states of energy h form a conic (the plane I3 = 0 cut by the
energy ellipsoid, :func:`~chargedesign.topology.critical.states_on_level`), and the points of
the conic where I4 = k are found by sign changes of ``I4 - k`` at ``angles`` samples (one
secant refinement).

The samples are then joined by the motion, not by their distances: trajectories start from
samples (heyoka's ensemble propagation, DOP853 without heyoka) and each joins its start to
every sample it passes within ``delta`` of (states scaled to unit size). A trajectory never
leaves its torus, so two tori are joined only when some trajectory passes within delta of a
sample of the other: below the tori's separation that cannot happen, however close they are.
Rounds of new trajectories start from the samples no trajectory has passed yet, until every
sample is covered. The components are counted over a ladder of join distances; the count
reported is the first (finest) one that holds over a run of them spanning at least a factor
:data:`MIN_PLATEAU` with every sample covered (a later run is that of tori merged at the
larger distances); each compact regular component is one torus (Liouville-Arnold). A level
with fewer than :data:`MIN_SAMPLES` samples (thin tubes near an elliptic branch) is sampled
again at twice the resolution, up to :data:`REFINEMENTS` times. The separation (least
distance between samples of different tori) and the coverage are kept as the evidence.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.params import Parameters
from chargedesign.simulation import taylor
from chargedesign.simulation.integrate import FALLBACK_METHOD, integrate
from chargedesign.simulation.system import (
    Body,
    RigidBodySystem,
    attitude_from_gamma,
    quaternion_gamma,
    rotation_quaternion,
)
from chargedesign.topology.critical import plane_basis, sphere_points
from chargedesign.topology.equations import MomentumMap

#: the count must hold from delta to at least this factor times delta
MIN_PLATEAU = 2.0
#: a level with fewer samples is sampled again at twice the resolution, at most
#: REFINEMENTS times
MIN_SAMPLES = 1000
REFINEMENTS = 2


@dataclass(frozen=True)
class LevelSampling:
    """Resolution of the level sampling: gamma grid points and angles on each conic."""

    gammas: int = 3000
    angles: int = 64

    def doubled(self) -> LevelSampling:
        return LevelSampling(2 * self.gammas, 2 * self.angles)


class LevelSampler:
    """The conics of one energy over a fixed gamma grid (reused for many k)."""

    def __init__(self, F: MomentumMap, h: float, sampling: LevelSampling) -> None:
        self.F = F
        self.sampling = sampling
        gamma = sphere_points(sampling.gammas)
        omega0, e1, e2 = plane_basis(F, gamma)
        base = F.values(np.concatenate([omega0, gamma], axis=1))[:, 0]
        inside = base < h
        self.gamma, self.omega0 = gamma[inside], omega0[inside]
        self.e1, self.e2 = e1[inside], e2[inside]
        self.radius = np.sqrt(h - base[inside])
        self.phi = np.linspace(0.0, 2 * np.pi, sampling.angles, endpoint=False)
        self.quartic = self._quartic(np.broadcast_to(self.phi, (len(self.gamma), len(self.phi))))
        self.spacing = np.sqrt(4 * np.pi / sampling.gammas)
        self.omega_scale = max(float(np.max(np.abs(self.omega0), initial=0.0)), 1e-300) + float(
            np.max(self.radius, initial=0.0)
        )

    def _states(self, phi: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """States at angles phi (m, j) on the conics of ``rows`` (default all), (m, j, 6)."""
        sel = slice(None) if rows is None else rows
        omega = self.omega0[sel][:, None, :] + self.radius[sel][:, None, None] * (
            np.cos(phi)[..., None] * self.e1[sel][:, None, :]
            + np.sin(phi)[..., None] * self.e2[sel][:, None, :]
        )
        gamma = np.broadcast_to(self.gamma[sel][:, None, :], omega.shape)
        return np.concatenate([omega, gamma], axis=2)

    def _quartic(self, phi: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        x = self._states(phi, rows)
        return self.F.values(x.reshape(-1, 6))[:, 1].reshape(phi.shape)

    def points(self, k: float) -> np.ndarray:
        """Sampled points of ``F^-1(h, k)``, scaled states (m, 6)."""
        g = self.quartic - k
        after = np.roll(g, -1, axis=1)
        rows, cols = np.nonzero(np.sign(g) != np.sign(after))
        if len(rows) == 0:
            return np.zeros((0, 6))
        step = self.phi[1] - self.phi[0]
        g0, g1 = g[rows, cols], after[rows, cols]
        phi = self.phi[cols] + step * g0 / (g0 - g1)
        # one secant refinement on the conic
        value = self._quartic(phi[:, None], rows)[:, 0] - k
        same = np.sign(value) == np.sign(g0)  # the sign change lies after phi
        left = np.where(same, phi, self.phi[cols])
        right = np.where(same, self.phi[cols] + step, phi)
        gl = np.where(same, value, g0)
        gr = np.where(same, g1, value)
        phi = left + (right - left) * gl / np.where(gl != gr, gl - gr, 1.0)
        x = self._states(phi[:, None], rows)[:, 0]
        return x / np.array([self.omega_scale] * 3 + [1.0] * 3)


@dataclass(frozen=True)
class FlowCounting:
    """How the tori of one level are counted by the flow (unit time scale, n = 0).

    ``starts`` trajectories per round of ``t_end`` (unit time) with ``samples`` output
    points each, at most ``rounds`` rounds; join distances ``deltas`` (scaled states: omega
    over its largest value on the level, gamma on the unit sphere); a sample is covered when
    a trajectory passes within ``deltas[cover]`` of it.
    """

    sampling: LevelSampling = field(default_factory=lambda: LevelSampling(1500, 48))
    starts: int = 48
    rounds: int = 8
    t_end: float = 200.0
    samples: int = 8000
    deltas: tuple[float, ...] = (0.01, 0.014, 0.02, 0.028, 0.04, 0.056, 0.08, 0.11, 0.16)
    cover: int = 3
    seed: int = 0


@dataclass
class FlowCount:
    """The evidence of one count: samples, trajectories, and per join distance the number
    of components and the fraction of samples a trajectory passed within it."""

    tori: int | None  # None: no count holds over a factor MIN_PLATEAU of join distances
    points: int
    trajectories: int
    deltas: list[float]
    counts: list[int]
    coverage: list[float]
    plateau: tuple[float, float] | None
    separation: float | None  # least distance between samples of different tori

    def to_dict(self) -> dict[str, Any]:
        return {
            "tori": self.tori,
            "samples": self.points,
            "trajectories": self.trajectories,
            "deltas": self.deltas,
            "counts": self.counts,
            "coverage": self.coverage,
            "plateau": None if self.plateau is None else list(self.plateau),
            "separation": self.separation,
        }


def seven_state(x: np.ndarray) -> np.ndarray:
    """``(p, q, r, quaternion)`` of a state ``(p, q, r, gamma)``: the integrator's start."""
    return np.concatenate([x[:3], rotation_quaternion(attitude_from_gamma(x[3:]))])


def propagate(
    params: Parameters,
    starts: np.ndarray,
    t_end: float,
    samples: int,
    rtol: float = 1e-12,
    atol: float = 1e-14,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Trajectories of the theorem's reduced model from ``starts`` (m, 6) on an even grid of
    ``samples`` times over ``[0, t_end]``: ``(times (T,), states (m, T, 6), quaternions (m, T,
    4))``, by heyoka's ensemble (without heyoka DOP853 at ``rtol``, ``atol``, its accepted step
    ends as the times). The flow counting's and the flight's one route."""
    system = RigidBodySystem(Body(parameters=params), ["theorem"])
    y0 = np.array([seven_state(x) for x in starts])
    grid = np.linspace(0.0, t_end, samples)
    if taylor.available():
        states = taylor.propagate_many(system, y0, grid).states
        times = grid
    else:
        run = integrate(
            system,
            y0,
            t_end,
            method=FALLBACK_METHOD,
            rtol=rtol,
            atol=atol,
            max_step=t_end / samples,
            samples=samples,
        )
        states, times = run.states, run.times
    quats = states[..., 3:]
    gamma = quaternion_gamma(quats.reshape(-1, 4)).reshape((*states.shape[:2], 3))
    return times, np.concatenate([states[..., :3], gamma], axis=2), quats


def _trajectories(F: MomentumMap, starts: np.ndarray, counting: FlowCounting) -> np.ndarray:
    """States (omega, gamma) along the trajectories from ``starts`` (m, 6): (m, T, 6)."""
    # sympy (a case file's map): lazy, so that design's and simulate's start-up skip it
    from chargedesign.topology.case_map import CaseMomentumMap, case_trajectories

    if isinstance(F, CaseMomentumMap):
        return case_trajectories(F, starts, counting.t_end * F.time_unit, counting.samples)
    return propagate(F.params, starts, counting.t_end, counting.samples, rtol=1e-10, atol=1e-12)[1]


def count_by_flow(
    F: MomentumMap, h: float, k: float, counting: FlowCounting | None = None
) -> FlowCount:
    """The number of tori of ``F^-1(h, k)`` by the flow (see the module's notes); None (with
    no samples) when no state of the level is found at the sampling and at twice it. ``F`` at
    n = 0 and unit time scale (the diagram's reading)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    counting = counting or FlowCounting()
    deltas = list(counting.deltas)
    sampling = counting.sampling
    for _ in range(REFINEMENTS + 1):
        sampler = LevelSampler(F, h, sampling)
        points = sampler.points(k) if sampler.quartic.size else np.zeros((0, 6))
        if len(points) >= MIN_SAMPLES:
            break
        # a small level (thin tubes near an elliptic branch) may fall between the grid's
        # points: refine until it has enough samples
        sampling = sampling.doubled()
    if len(points) == 0:
        # no state found even at the finest sampling: not a count (the caller knows the bounds)
        return FlowCount(None, 0, 0, deltas, [0] * len(deltas), [0.0] * len(deltas), None, None)
    scale = np.array([sampler.omega_scale] * 3 + [1.0] * 3)
    tree = cKDTree(points)
    rng = np.random.default_rng(counting.seed)
    # per trajectory: its start and, for each of its points, the nearest sample and distance
    visits: list[tuple[int, np.ndarray, np.ndarray]] = []
    nearest = np.full(len(points), np.inf)  # distance from each sample to the trajectories
    for _ in range(counting.rounds):
        waiting = np.flatnonzero(nearest > deltas[counting.cover])
        if len(waiting) == 0:
            break
        chosen = rng.choice(waiting, size=min(counting.starts, len(waiting)), replace=False)
        paths = _trajectories(F, points[chosen] * scale, counting) / scale
        for start, path in zip(chosen, paths, strict=True):
            distance, index = tree.query(path)
            visits.append((int(start), index, distance))
            np.minimum.at(nearest, index, distance)
        nearest[chosen] = 0.0
    counts, coverage, labels = [], [], []
    for delta in deltas:
        rows, cols = [], []
        for start, index, distance in visits:
            hit = np.unique(index[distance < delta])
            rows.append(np.full(hit.size, start))
            cols.append(hit)
        r, c = np.concatenate(rows), np.concatenate(cols)
        graph = coo_matrix((np.ones(r.size), (r, c)), shape=(len(points),) * 2)
        found, label = connected_components(graph, directed=False)
        counts.append(int(found))
        coverage.append(float(np.mean(nearest < delta)))
        labels.append(label)
    tori, plateau, separation = None, None, None
    best = _plateau(deltas, counts, coverage)
    if best is not None:
        first, last = best
        tori, plateau = counts[first], (deltas[first], deltas[last])
        separation = _separation(points, labels[first])
    return FlowCount(tori, len(points), len(visits), deltas, counts, coverage, plateau, separation)


def _plateau(
    deltas: list[float], counts: list[int], coverage: list[float]
) -> tuple[int, int] | None:
    """The first run of join distances (from the smallest) with every sample covered and the
    same count, spanning at least :data:`MIN_PLATEAU` (indices of its ends), or None.

    The first, not the longest: tori closer together than a join distance are merged there,
    so the count that holds at the finest resolution the samples support is the true one
    (a longer run at larger distances is the merged count)."""
    i = 0
    while i < len(deltas):
        if coverage[i] < 1.0:
            i += 1
            continue
        j = i
        while j + 1 < len(deltas) and coverage[j + 1] == 1.0 and counts[j + 1] == counts[i]:
            j += 1
        if deltas[j] >= MIN_PLATEAU * deltas[i] * (1 - 1e-9):
            return i, j
        i = j + 1
    return None


def _separation(points: np.ndarray, label: np.ndarray) -> float | None:
    """The least distance between samples of different components (None for one)."""
    from scipy.spatial import cKDTree

    groups = [points[label == g] for g in np.unique(label)]
    if len(groups) < 2:
        return None
    best = np.inf
    for i, a in enumerate(groups):
        tree = cKDTree(a)
        for b in groups[i + 1 :]:
            best = min(best, float(np.min(tree.query(b)[0])))
    return best
