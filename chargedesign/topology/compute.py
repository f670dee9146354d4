"""The diagram's computation, stage by stage, for one parameter set (any n).

Stages (each timed): compile the exact equations; find the energy range's admissible part;
seeds (random points of the level corrected by Gauss-Newton) and rank-zero points; the
exact equator family; continuation of every family through the seeds; the stability type of
every point; the tori count of each chamber. :func:`critical_diagram` runs them for the
parameters as given; :mod:`.diagram` runs them at n = 0 and shifts (Larmor). The same stages
for a case without closed form: :mod:`.general`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.params import Parameters
from chargedesign.topology.branches import Branch, ContinuationSettings, trace_all
from chargedesign.topology.chambers import FlowCount, FlowCounting, count_by_flow
from chargedesign.topology.closed_form import RESOLVED, ClosedForm
from chargedesign.topology.critical import (
    CriticalPoints,
    Scales,
    amended_minimum,
    critical_seeds,
    distinct,
    equator_family,
    equator_vertices,
    equilibria,
    multipliers,
    rank_zero,
    sphere_points,
)
from chargedesign.topology.equations import MomentumMap
from chargedesign.topology.stability import branch_types, equilibrium_type, linearised_eigenvalues


@dataclass(frozen=True)
class DiagramOptions:
    """How hard to look: seeds, continuation steps, the flow counting of the chambers."""

    seeds: int = 300
    seed: int = 0
    continuation: ContinuationSettings = field(default_factory=ContinuationSettings)
    counting: FlowCounting = field(default_factory=FlowCounting)


@dataclass
class TracedBranch:
    """A branch of the diagram: states (m, 6), image (m, 2), type per point, its ends."""

    states: np.ndarray
    hk: np.ndarray
    types: list[str]
    ends: tuple[str, str]
    exact: bool = False


@dataclass
class Vertex:
    """A rank-zero point (relative equilibrium critical for both integrals)."""

    state: np.ndarray
    hk: np.ndarray
    type: str


@dataclass
class Chamber:
    """A cell of the diagram (between two walls, between two consecutive vertex energies)
    with its sample point, its number of tori by the flow (None: not resolved), the chamber
    it belongs to (cells joined across a vertex energy where their walls stay apart), its
    energy width (J) and the count's evidence (:class:`~.chambers.FlowCount`, None when the
    cell is too thin to count)."""

    h: float
    k: float
    tori: int | None
    walls: tuple[str, str]
    chamber: int
    width: float
    evidence: FlowCount | None = None


@dataclass
class RawDiagram:
    """What :func:`critical_diagram` computes (SI, body axes, at the parameters given)."""

    params: Parameters
    h_range: tuple[float, float]
    h_min: float
    branches: list[TracedBranch]
    vertices: list[Vertex]
    chambers: list[Chamber]
    admissible: np.ndarray  # (columns, 3): h, k_min, k_max
    seconds: dict[str, float]
    seeds_found: int


def energy_bounds(F: MomentumMap) -> tuple[float, float]:
    """Least energy on the level and the highest relative-equilibrium energy bound (the
    amended potential's extremes over a fine sphere grid, the least one refined), J."""
    from scipy.optimize import minimize

    grid = sphere_points(20000)
    values = amended_minimum(F, grid)
    best = grid[int(np.argmin(values))]

    def amended(angles: np.ndarray) -> float:
        theta, phi = angles
        gamma = np.array(
            [[np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)]]
        )
        return float(amended_minimum(F, gamma)[0])

    start = np.array([np.arccos(np.clip(best[2], -1.0, 1.0)), np.arctan2(best[1], best[0])])
    refined = minimize(amended, start, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 0.0})
    low = min(float(values.min()), float(refined.fun))
    return low, float(values.max())


def resolve_range(
    F: MomentumMap, h_range: tuple[float, float] | None
) -> tuple[tuple[float, float], float]:
    """The energy range (J) clipped to the admissible energies, and the least energy.

    Default: from the least energy to the top of the amended potential plus half its span.
    """
    low, top = energy_bounds(F)
    if h_range is None:
        return (low, top + 0.5 * (top - low) + 1e-9 * max(abs(top), abs(low))), low
    lo, hi = (float(v) for v in h_range)
    # the command checks the range first (diagram.check_energy_range, commands.bifurcation):
    # here a bad one is the caller's error
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo >= hi:
        raise ValueError(
            f"--h-range: expected two finite energies LO < HI, got {fmt(lo, PLAIN)}"
            f" {fmt(hi, PLAIN)}"
        )
    if hi <= low:
        raise ValueError(
            f"--h-range: no admissible motion for energies {fmt(lo, PLAIN)} .. {fmt(hi, PLAIN)}:"
            f" on the level the energy is at least {fmt(low, CELL)}"
        )
    return (max(lo, low), hi), low


def make_scales(F: MomentumMap, h_range: tuple[float, float]) -> Scales:
    """Diagram units: the energy span and the largest I4 at the top energy (closed form)."""
    k_top = ClosedForm.of(F.params).upper(h_range[1])
    return Scales(
        energy=h_range[1] - h_range[0],
        quartic=max(k_top, 1e-12),
        h_low=h_range[0],
        h_high=h_range[1],
    )


def _seeds(F: MomentumMap, scales: Scales, options: DiagramOptions) -> CriticalPoints:
    """Random seeds without the rank-zero points and the exact equator family."""
    found = critical_seeds(F, scales, options.seeds, np.random.default_rng(options.seed))
    x = found.z[:, :6]
    P = x[:, 0] + F.params.n * x[:, 3]
    Q = x[:, 1] + F.params.n * x[:, 4]
    on_equator = (np.abs(x[:, 5]) < 1e-4) & (np.hypot(P, Q) < 1e-3)
    keep = ~rank_zero(F, x) & ~on_equator & (found.hk[:, 1] > 1e-9 * scales.quartic)
    return CriticalPoints(found.z[keep], found.hk[keep])


def _vertices(F: MomentumMap, scales: Scales) -> list[Vertex]:
    found = [equilibria(F, scales), equator_vertices(F, scales)]
    points = distinct(
        CriticalPoints(np.concatenate([p.z for p in found]), np.concatenate([p.hk for p in found]))
    )
    return typed_vertices(F, points, scales)


def typed_vertices(F: MomentumMap, points: CriticalPoints, scales: Scales) -> list[Vertex]:
    """Rest states as vertices, each typed by the energy's flow: (a, b) = (1, 0), multipliers
    refitted (any momentum map of the room: the theorem's or a case's)."""
    z = points.z.copy()
    z[:, 6] = 0.0
    z[:, 7:] = multipliers(F, z[:, :6], z[:, 6], scales)
    return [
        Vertex(zi[:6], hk, equilibrium_type(linearised_eigenvalues(F, zi, scales)))
        for zi, hk in zip(z, points.hk, strict=True)
    ]


#: the stages of :func:`critical_diagram`, in order (its ``seconds`` keys)
STAGES = ("equations", "energy range", "seeds", "continuation", "stability", "chambers")


class Stopwatch:
    """The seconds of each stage of a diagram (:meth:`lap` ends one); ``tally(done, total)``,
    when given, is told the stages done of ``total``."""

    def __init__(self, total: int = 0, tally: Callable[[int, int], None] | None = None) -> None:
        self.seconds: dict[str, float] = {}
        self._clock = time.perf_counter()
        self._total = total
        self._tally = tally

    def lap(self, stage: str) -> None:
        now = time.perf_counter()
        self.seconds[stage] = now - self._clock
        self._clock = now
        if self._tally is not None:
            self._tally(len(self.seconds), self._total)


def drawn_branches(
    F: MomentumMap,
    traced: list[Branch],
    extra: TracedBranch | None,
    vertices: list[Vertex],
    scales: Scales,
) -> list[TracedBranch]:
    """The families to draw: each traced one typed by the flow, the ``extra`` one (exact or
    sampled, already typed) after them, every one cut to its runs inside the energy range with
    the ends at a vertex named (:func:`clipped_runs`, :func:`name_vertex_ends`)."""
    branches = [typed_branch(F, b, scales) for b in traced]
    if extra is not None:
        branches.append(extra)
    return [
        name_vertex_ends(run, vertices, scales) for b in branches for run in clipped_runs(b, scales)
    ]


def critical_diagram(
    params: Parameters,
    h_range: tuple[float, float] | None = None,
    options: DiagramOptions | None = None,
    tally: Callable[[int, int], None] | None = None,
    count: bool = True,
) -> RawDiagram:
    """The critical set, its image and the chambers, computed at ``params`` as given
    (``tally(done, total)`` is told the stages done of :data:`STAGES`; ``count``: tori of
    each chamber by the flow, the slow stage)."""
    options = options or DiagramOptions()
    watch = Stopwatch(len(STAGES), tally)
    lap = watch.lap
    F = MomentumMap(params)
    F.hessians(np.zeros((2, 6)))
    lap("equations")
    rng_range, h_min = resolve_range(F, h_range)
    scales = make_scales(F, rng_range)
    lap("energy range")
    seeds = _seeds(F, scales, options)
    vertices = _vertices(F, scales)
    lap("seeds")
    raw = trace_all(F, seeds, scales, options.continuation)
    exact = equator_family(F, scales, options.continuation.max_image_step)
    lap("continuation")
    equator = None
    if len(exact.z):
        kinds = ["degenerate"] * len(exact.z)
        equator = TracedBranch(exact.z[:, :6], exact.hk, kinds, ("end", "energy range"), True)
    branches = drawn_branches(F, [b for b in raw if len(b.z) > 1], equator, vertices, scales)
    lap("stability")
    chambers = chamber_samples(F, scales, options.counting, count)
    admissible = admissible_band(F, scales)
    lap("chambers")
    return RawDiagram(
        params,
        rng_range,
        h_min,
        branches,
        vertices,
        chambers,
        admissible,
        watch.seconds,
        len(seeds.z),
    )


def typed_branch(F: MomentumMap, branch: Branch, scales: Scales) -> TracedBranch:
    return TracedBranch(branch.z[:, :6], branch.hk, branch_types(F, branch.z, scales), branch.ends)


def clipped_runs(branch: TracedBranch, scales: Scales) -> list[TracedBranch]:
    """The runs of at least two points inside the energy range (continuation overshoots)."""
    slack = 1e-9 * scales.energy
    inside = (branch.hk[:, 0] >= scales.h_low - slack) & (branch.hk[:, 0] <= scales.h_high + slack)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(int), [0]])))
    runs = []
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        if b - a > 1:
            runs.append(
                TracedBranch(
                    branch.states[a:b], branch.hk[a:b], branch.types[a:b], branch.ends, branch.exact
                )
            )
    return runs


def name_vertex_ends(branch: TracedBranch, vertices: list[Vertex], scales: Scales) -> TracedBranch:
    """An end where the step collapsed is called ``vertex`` when it lies at a rank-zero
    point's image (within 0.2 % of the diagram): the family ends at a relative equilibrium
    or meets another family there."""
    ends = list(branch.ends)
    for side, hk in ((0, branch.hk[0]), (1, branch.hk[-1])):
        near = [np.linalg.norm(scales.image(hk - v.hk)) < 2e-3 for v in vertices]
        if ends[side] == "end" and any(near):
            ends[side] = "vertex"
    return replace(branch, ends=(ends[0], ends[1]))


def crossing_segments(
    branches: list[TracedBranch], h: float
) -> list[tuple[float, int, int, float]]:
    """``(k, branch index, i, w)`` for each crossing of a branch's polyline with the vertical
    line h, sorted: the crossing lies on the branch's segment from row ``i`` to ``i + 1``, a
    fraction ``w`` along it."""
    out = []
    for index, branch in enumerate(branches):
        hs, ks = branch.hk[:, 0], branch.hk[:, 1]
        side = np.sign(hs - h)
        for i in np.flatnonzero(side[:-1] * side[1:] < 0):
            w = (h - hs[i]) / (hs[i + 1] - hs[i])
            out.append((float(ks[i] + w * (ks[i + 1] - ks[i])), index, int(i), float(w)))
    return sorted(out)


def crossings(branches: list[TracedBranch], h: float) -> list[tuple[float, int]]:
    """``(k, branch index)`` where each branch's polyline crosses the vertical line h."""
    return [(k, index) for k, index, _, _ in crossing_segments(branches, h)]


def chamber_samples(
    F: MomentumMap, scales: Scales, counting: FlowCounting, count: bool = True
) -> list[Chamber]:
    """Every cell of the closed-form diagram in the energy range, however thin
    (:meth:`~chargedesign.topology.closed_form.ClosedForm.cells`), with its tori counted by
    the flow at its middle; a cell thinner than :data:`RESOLVED`, or every cell without
    ``count``, is not counted (None)."""
    out = []
    for cell in ClosedForm.of(F.params).cells(scales.h_low, scales.h_high):
        counted = count and cell.thickness >= RESOLVED
        found = count_by_flow(F, cell.h, cell.k, counting) if counted else None
        tori = None if found is None else found.tori
        out.append(Chamber(cell.h, cell.k, tori, cell.walls, cell.chamber, cell.b - cell.a, found))
    return out


def admissible_band(F: MomentumMap, scales: Scales, energies: int = 200) -> np.ndarray:
    """``(h, 0, ((h - h_min) / C)^2)``: the admissible region's bounds (proven, closed form),
    shape (energies, 3)."""
    closed = ClosedForm.of(F.params)
    h = np.linspace(max(scales.h_low, closed.h_min), scales.h_high, energies)
    return np.stack([h, np.zeros_like(h), [closed.upper(float(x)) for x in h]], axis=1)
