"""The diagram's stages for a case without a closed form: any polynomial case of (ep) with
two integrals (H, F) on a level I3 = g.

:func:`~chargedesign.topology.diagram.bifurcation_diagram` (the one route) runs these stages
for every case but the theorem's catalogue entry, whose structure its closed form gives
(:mod:`.compute`, :mod:`.closed_form`). They are the theorem's stages on
:class:`~.case_map.CaseMomentumMap`: seeds (random states of the level corrected by
Gauss-Newton), rank-zero points, continuation of every family, the stability type of every
point. What the theorem takes from its closed form is found here from the traced branches:

- **the degenerate set** ``dF = 0`` (where F vanishes to second order, e.g. Kowalevski's
  ``k = 0``, the Delone class): Newton converges badly on it (the Jacobian loses rank twice),
  so it is sampled directly (Gauss-Newton on ``dF = 0, I2 = 1, I3 = g`` from states of the
  level at energies across the range) and drawn as the segment of its images when F is
  constant on it;
- **the cells**: between consecutive breakpoint energies (vertices, branch ends, the
  branches' turning points and crossings) each gap between two walls (branches crossing the
  line h = const) is a cell, sampled at its middle and counted by the flow
  (:func:`~.chambers.count_by_flow`, the case's own equations); an empty level is 0 tori.

Where the case is Kowalevski's on I3 = 0 the branches are named by their Appelrot class
(:mod:`.kowalevski`).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.errors import InputError, SolverError
from chargedesign.formatting import CELL, fmt
from chargedesign.scene.bifurcation import check_h_range
from chargedesign.scene.case_file import Case
from chargedesign.topology.branches import Branch, distance_to_branch, trace_all
from chargedesign.topology.case_map import CaseMomentumMap, diagram_refusal
from chargedesign.topology.chambers import count_by_flow
from chargedesign.topology.compute import (
    STAGES,
    Chamber,
    DiagramOptions,
    Stopwatch,
    TracedBranch,
    Vertex,
    crossings,
    drawn_branches,
    resolve_range,
    typed_vertices,
)
from chargedesign.topology.critical import (
    CriticalPoints,
    Scales,
    critical_seeds,
    equilibria,
    gauss_newton,
    random_level_states,
    rank_zero,
)
from chargedesign.topology.kowalevski import appelrot_class, kowalevski_constants

#: a wall closer than this (diagram units) to another at the same energy is the same wall
SAME_WALL = 1e-6
#: two branches of one name closer than this (diagram units) at an energy are one wall
SAME_CURVE = 1e-2
#: a cell thinner than this (diagram units) is not counted
THIN_CELL = 1e-4


@dataclass
class CaseRaw:
    """What :func:`general_diagram` computes (the case's units: its numbers read in SI)."""

    case: Case
    level: Any
    h_range: tuple[float, float]
    h_min: float
    branches: list[TracedBranch]
    names: list[str]
    vertices: list[Vertex]
    chambers: list[Chamber]
    admissible: np.ndarray
    seconds: dict[str, float] = field(default_factory=dict)
    seeds_found: int = 0


def case_scales(F: CaseMomentumMap, h_range: tuple[float, float], count: int = 4000) -> Scales:
    """Diagram units: the energy span, and the largest |F| over states of the level sampled
    at energies across the range."""
    x = random_level_states(F, h_range[0], h_range[1], count, np.random.default_rng(1))
    spread = float(np.max(np.abs(F.values(x)[:, 1])))
    return Scales(h_range[1] - h_range[0], max(spread, 1e-12), h_range[0], h_range[1])


def degenerate_set(F: CaseMomentumMap, scales: Scales, count: int = 2000) -> CriticalPoints:
    """Points of the level where dF = 0 (Gauss-Newton on ``dF = 0, I2 = 1, I3 = g`` from
    states across the energy range), as solutions ``z`` with ``(a, b) = (0, 1)``."""
    x = random_level_states(F, scales.h_low, scales.h_high, count, np.random.default_rng(2))
    z = np.concatenate([x, np.full((count, 1), np.pi / 2), np.zeros((count, 2))], axis=1)
    z, residual = gauss_newton(F, z, scales)
    grads = F.gradients(z[:, :6])
    size = np.max(np.linalg.norm(F.gradients(x)[:, 1], axis=1))
    ok = (residual <= 1e-9) & (np.linalg.norm(grads[:, 1], axis=1) <= 1e-8 * size)
    ok &= np.abs(z[:, 7]) + np.abs(z[:, 8]) <= 1e-8
    return CriticalPoints(z[ok], F.values(z[ok, :6])[:, :2])


def _degenerate_branch(points: CriticalPoints, scales: Scales) -> TracedBranch | None:
    """The segment of the degenerate set's images when F is constant on it (None otherwise:
    such a set is not drawn, and the summary says so)."""
    if len(points.z) < 2:
        return None
    k = points.hk[:, 1]
    if np.ptp(k) > 1e-8 * scales.quartic:
        return None
    order = np.argsort(points.hk[:, 0])
    low, high = points.hk[order[0], 0], points.hk[order[-1], 0]
    if high - low <= 1e-6 * scales.energy:
        return None  # a point (Joukovsky's M = 0): a vertex, not a segment
    # sampled from states across the range: a set that reaches its top goes on above it
    if high >= scales.h_high - 0.05 * scales.energy:
        high = scales.h_high
    steps = int(np.ceil((high - low) / scales.energy / 0.02))
    h = np.linspace(low, high, max(2, steps + 1))
    hk = np.stack([h, np.full_like(h, float(np.median(k)))], axis=1)
    states = np.repeat(points.z[order[:1], :6], len(h), axis=0)
    top = "energy range" if high == scales.h_high else "sampled"
    return TracedBranch(states, hk, ["degenerate"] * len(h), ("sampled", top), True)


def _vertices(F: CaseMomentumMap, scales: Scales) -> list[Vertex]:
    return typed_vertices(F, equilibria(F, scales), scales)


def _breakpoints(
    branches: list[TracedBranch], names: list[str], vertices: list[Vertex], scales: Scales
) -> list[float]:
    """Energies where the walls may change: range ends, vertices, branch ends and crossings
    of branches on different curves (closer than 1e-3 of the range: one breakpoint)."""
    found = [scales.h_low, scales.h_high] + [float(v.hk[0]) for v in vertices]
    for b in branches:
        found += [float(b.hk[0, 0]), float(b.hk[-1, 0])]
    for i, a in enumerate(branches):
        for j in range(i + 1, len(branches)):
            if names[i] != names[j]:
                found += _crossing_energies(a.hk, branches[j].hk, scales)
    inside = sorted(h for h in found if scales.h_low <= h <= scales.h_high)
    out: list[float] = []
    for h in inside:
        if not out or h - out[-1] > 1e-3 * scales.energy:
            out.append(h)
    if out[-1] < scales.h_high:
        out[-1] = scales.h_high
    return out


def _crossing_energies(a: np.ndarray, b: np.ndarray, scales: Scales) -> list[float]:
    """Energies where two polylines cross (segments tested pairwise, in diagram units)."""
    pa, pb = scales.image(a), scales.image(b)
    out = []
    for i in range(len(pa) - 1):
        p0, d0 = pa[i], pa[i + 1] - pa[i]
        q0, d1 = pb[:-1], pb[1:] - pb[:-1]
        det = d0[0] * d1[:, 1] - d0[1] * d1[:, 0]
        good = np.abs(det) > 1e-14
        w = q0 - p0
        s = np.where(good, (w[:, 0] * d1[:, 1] - w[:, 1] * d1[:, 0]) / np.where(good, det, 1), -1)
        t = np.where(good, (w[:, 0] * d0[1] - w[:, 1] * d0[0]) / np.where(good, det, 1), -1)
        hit = good & (s > 0) & (s < 1) & (t > 0) & (t < 1)
        out += [float((p0[0] + si * d0[0]) * scales.energy) for si in s[hit]]
    return out


def cells(
    F: CaseMomentumMap,
    branches: list[TracedBranch],
    names: list[str],
    vertices: list[Vertex],
    scales: Scales,
    options: DiagramOptions,
    count: bool,
) -> list[Chamber]:
    """Every gap between two walls at the middle of each interval between breakpoints, with
    its tori counted by the flow (None: not counted or not resolved; 0: empty level)."""
    points = _breakpoints(branches, names, vertices, scales)
    out: list[Chamber] = []
    previous: dict[tuple[str, str], int] = {}
    for a, b in itertools.pairwise(points):
        h = 0.5 * (a + b)
        walls: list[tuple[float, int]] = []
        for k, index in crossings(branches, h):
            gap = (k - walls[-1][0]) / scales.quartic if walls else np.inf
            # two traced families on one curve: their polylines differ by the chords' error
            if gap > (SAME_CURVE if walls and names[walls[-1][1]] == names[index] else SAME_WALL):
                walls.append((k, index))
        current: dict[tuple[str, str], int] = {}
        for (k0, i0), (k1, i1) in itertools.pairwise(walls):
            pair = (names[i0], names[i1])
            number = previous.get(pair, len(out))
            current[pair] = number
            k = 0.5 * (k0 + k1)
            tori = None
            evidence = None
            if count and (k1 - k0) / scales.quartic > THIN_CELL:
                evidence = count_by_flow(F, h, k, options.counting)
                tori = 0 if evidence.points == 0 else evidence.tori
            out.append(Chamber(h, k, tori, pair, number, b - a, evidence))
        previous = current
    return out


def general_diagram(
    case: Case,
    level: Any = 0,
    h_range: tuple[float, float] | None = None,
    options: DiagramOptions | None = None,
    tally: Callable[[int, int], None] | None = None,
    count: bool = True,
) -> CaseRaw:
    """The critical set, its image and the cells of ``case``'s ``(H, F)`` on ``|gamma| = 1,
    I3 = level`` (the case's units); ``count``: tori of each cell by the flow (the slow
    stage); ``tally(done, total)`` is told the stages done of :data:`~.compute.STAGES`.

    Refused in one line (:class:`~chargedesign.errors.InputError`) before the seeds: a case
    without a diagram here (:func:`~.case_map.diagram_refusal`), an ``h_range`` that is not two
    finite energies LO < HI or has no admissible motion, and energies without a scale."""
    refusal = diagram_refusal(case)
    if refusal is not None:
        raise InputError(refusal)
    if h_range is not None:
        check_h_range(float(h_range[0]), float(h_range[1]))
    options = options or DiagramOptions()
    watch = Stopwatch(len(STAGES), tally)
    lap = watch.lap
    F = CaseMomentumMap(case, level)
    lap("equations")
    try:
        rng_range, h_min = resolve_range(F, h_range)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    if not rng_range[1] > rng_range[0]:
        raise InputError(
            f"case {case.name}: the energies on I3 = {level} have no scale (the least energy"
            f" and the top of the amended potential are both {fmt(rng_range[0], CELL)}): give"
            " --h-range LO HI"
        )
    scales = case_scales(F, rng_range)
    F.time_unit = float(np.sqrt(np.max(F.inertia()) / max(scales.energy, 1e-300)))
    lap("energy range")
    found = critical_seeds(F, scales, options.seeds, np.random.default_rng(options.seed))
    df = np.linalg.norm(F.gradients(found.z[:, :6])[:, 1], axis=1)
    typical = max(float(np.median(df)), 1e-300)
    keep = ~rank_zero(F, found.z[:, :6]) & (df > 1e-6 * typical)
    seeds = CriticalPoints(found.z[keep], found.hk[keep])
    vertices = _vertices(F, scales)
    lap("seeds")
    raw = trace_all(F, seeds, scales, options.continuation)
    degenerate = _degenerate_branch(degenerate_set(F, scales), scales)
    lap("continuation")
    # a family whose image is a point (at a vertex, to round-off) draws nothing
    moved = [b for b in raw if len(b.z) > 1 and np.ptp(scales.image(b.hk), axis=0).max() > 1e-6]
    branches = drawn_branches(F, moved, degenerate, vertices, scales)
    if not branches:
        raise SolverError(
            f"bifurcation: no critical curve of case {case.name} traced in"
            f" {fmt(rng_range[0], CELL)} .. {fmt(rng_range[1], CELL)}: widen --h-range"
        )
    names = _names(case, level, branches)
    lap("stability")
    chambers = cells(
        F, branches, curve_labels(branches, names, scales), vertices, scales, options, count
    )
    lap("chambers")
    return CaseRaw(
        case,
        level,
        rng_range,
        h_min,
        branches,
        names,
        vertices,
        chambers,
        _band(branches, scales),
        watch.seconds,
        len(seeds.z),
    )


def curve_labels(branches: list[TracedBranch], names: list[str], scales: Scales) -> list[str]:
    """One label per curve of the image: traced families whose images overlap (most points
    of one within 1e-3 diagram units of the other's polyline, e.g. a family and its mirror)
    share the label of the first; a named branch keeps its name."""
    labels = list(names)
    for j in range(len(branches)):
        if not labels[j].startswith("branch "):
            continue
        for i in range(j):
            near = [
                distance_to_branch(hk, _as_branch(branches[i]), scales) < 1e-3
                for hk in branches[j].hk
            ]
            if np.mean(near) > 0.5:
                labels[j] = labels[i]
                break
    return labels


def _as_branch(b: TracedBranch) -> Branch:
    return Branch(np.zeros((len(b.hk), 9)), b.hk, b.ends)


def _names(case: Case, level: Any, branches: list[TracedBranch]) -> list[str]:
    """Each branch's name: its Appelrot class for Kowalevski's case on I3 = 0, else its index."""
    constants = kowalevski_constants(case) if level == 0 else None
    if constants is None:
        return [f"branch {i}" for i in range(len(branches))]
    return [appelrot_class(b.hk, *constants) or f"branch {i}" for i, b in enumerate(branches)]


def _band(branches: list[TracedBranch], scales: Scales, energies: int = 200) -> np.ndarray:
    """``(h, lowest wall, highest wall)``: the admissible region lies between them (F on a
    compact level attains its extremes at critical points)."""
    rows = []
    for h in np.linspace(scales.h_low, scales.h_high, energies):
        ks = [k for k, _ in crossings(branches, float(h))]
        if len(ks) >= 2:
            rows.append((float(h), min(ks), max(ks)))
    return np.array(rows).reshape(-1, 3)
