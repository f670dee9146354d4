"""The diagram in closed form: the branches are parabolas ``k = ((h - h_j) / C)^2``.

With ``s = c (gamma1^2 - gamma2^2) + 2 d gamma1 gamma2``, ``a0 = sqrt(c^2 + d^2)`` and
``A = kappa + K^2 s``, the potential at n = 0 is (tested symbolically)

    ``V / C = A^2 / (2 K^2) + K^2 a0^2 gamma3^4 / 2 + e_*``,  ``e_* = -kappa^2/(2K^2) - K^2 c^2/2``

and on the equator ``gamma3 = 0`` it is ``kappa s + K^2 s^2 / 2 - K^2 c^2 / 2`` with ``s`` in
``[-a0, a0]``. Its critical energies are the equator family's vertices: ``s = +-a0`` (always)
and ``s = -kappa / K^2`` when ``|kappa| < K^2 a0`` (the switch between the diagram's two
shapes). Over each of them a family of periodic motions (``gamma`` on the equator at the
critical angle, ``r = 0``, ``omega`` horizontal and perpendicular to ``gamma``) has
``I4 = |p + i q|^4 = ((H - h_j) / C)^2`` and is critical (the multipliers are found in closed
form, tests/topology/test_closed_form.py). The least of them, ``h_min``, bounds the quartic:
``I4 <= ((H - h_min) / C)^2`` on the whole level (docs/bifurcation.md derives it), so
``k = ((h - h_min) / C)^2`` is the elliptic upper boundary; every other ``h_j`` gives a
hyperbolic arc from the upper boundary at ``(h_min + h_j) / 2``, touching ``k = 0`` at
``h_j``. With n the energies are shifted by ``C n^2`` (Larmor), and the parameters enter
only through ``C``, ``K^2 a0^2``-type products: ``(c, d, K, kappa) -> (t c, t d, K / t,
kappa / t)`` leaves every term unchanged.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from chargedesign.formatting import CELL, fmt
from chargedesign.params import Parameters

#: a point of the plane closer than this (relative to the diagram's energy scale, in h and in
#: sqrt(k)) to a branch is on it
ON_BRANCH = 1e-9
#: a level closer than this to a branch (same units) is not counted: its tori are closer
#: together than the flow counting's samples resolve
RESOLVED = 1e-5
#: the name of the wall k = 0
ZERO_WALL = "degenerate k = 0 (the equator family and the zero sheets of I4)"


@dataclass(frozen=True)
class Parabola:
    """One branch ``k = ((h - h_j) / C)^2`` for ``h >= start`` (J, 1/s^4)."""

    h_j: float
    start: float
    type: str  # "elliptic" (the upper boundary) or "hyperbolic"
    s: float  # the value of s on the equator at the critical angle
    C: float
    a0: float  # sqrt(c^2 + d^2)
    kappa: float

    def k(self, h: float | np.ndarray) -> float | np.ndarray:
        return ((np.asarray(h) - self.h_j) / self.C) ** 2

    @property
    def name(self) -> str:
        """The branch's short name: its type and critical point on the equator, with the sign
        of kappa (which of ``s = +-a0`` is the boundary depends on it); the same at any scale.
        Said with ``u`` for the equator coordinate ``s`` (the docs' glossary: in output text
        ``s`` is the rate factor alone)."""
        if abs(abs(self.s) - self.a0) > 1e-12 * self.a0:
            where = "u = -kappa/K^2"
        else:
            where = f"u = {'+' if self.s > 0 else '-'}a0"
        sign = "kappa > 0" if self.kappa > 0 else ("kappa < 0" if self.kappa < 0 else "kappa = 0")
        return f"{self.type} (equator at {where}, {sign})"

    @property
    def label(self) -> str:
        """The name with the closed form."""
        return f"{self.name} k = ((h - h_j)/C)^2, h_j = {fmt(self.h_j, CELL)} J"


@dataclass(frozen=True)
class Cell:
    """One gap between two walls between two consecutive vertex energies ``a < b`` (J): its
    walls' names, its middle ``(h, k)`` (in h, and in sqrt(k), where the walls are straight),
    its thickness there (``C`` times the gap in sqrt(k), over the energy spread) and the
    chamber it belongs to."""

    a: float
    b: float
    walls: tuple[str, str]
    h: float
    k: float
    thickness: float
    chamber: int


@dataclass(frozen=True)
class ClosedForm:
    """The branches of the diagram of ``params`` in closed form (SI)."""

    params: Parameters
    h_min: float
    parabolas: tuple[Parabola, ...]
    spread: float  # the spread of the critical energies, J (computed before the Larmor shift)

    @classmethod
    def of(cls, params: Parameters) -> ClosedForm:
        C, c, d, K, kappa = params.C, params.c, params.d, params.K, params.kappa
        a0 = math.hypot(c, d)
        shift = C * params.n**2
        candidates = [a0, -a0]
        if abs(kappa) < K * K * a0:
            candidates.append(-kappa / (K * K))

        def unshifted(s: float) -> float:
            return C * (kappa * s + 0.5 * K * K * s * s - 0.5 * K * K * c * c)

        spread = max(map(unshifted, candidates)) - min(map(unshifted, candidates))

        def energy(s: float) -> float:
            return unshifted(s) + shift

        levels: dict[float, float] = {}
        for s in candidates:
            h = energy(s)
            if all(abs(h - other) > 1e-14 * max(1.0, abs(h)) for other in levels):
                levels[h] = s
        h_min = min(levels)
        parabolas = [Parabola(h_min, h_min, "elliptic", levels[h_min], C, a0, kappa)]
        for h in sorted(levels):
            if h != h_min:
                start = 0.5 * (h_min + h)
                parabolas.append(Parabola(h, start, "hyperbolic", levels[h], C, a0, kappa))
        return cls(params, h_min, tuple(parabolas), spread)

    @property
    def energies(self) -> list[float]:
        """The critical energies ``h_j`` of the equator family (J), least first."""
        return [p.h_j for p in self.parabolas]

    @property
    def energy_scale(self) -> float:
        """The spread of the critical energies ``h_j`` (J; positive for every parameter set
        with a diagram): the diagram's unit of h."""
        return self.spread

    def upper(self, h: float) -> float:
        """The largest I4 at energy h (1/s^4): ``((h - h_min) / C)^2``, 0 below h_min."""
        return float(self.parabolas[0].k(max(h, self.h_min)))

    def walls(self, h: float) -> list[tuple[float, str]]:
        """The critical values of k at energy h, ascending, named: ``k = 0`` (degenerate)
        and each parabola active there (empty below the least energy)."""
        if h < self.h_min:
            return []
        out = [(0.0, ZERO_WALL)]
        for p in self.parabolas:
            if h >= p.start:
                out.append((float(p.k(h)), p.name))
        return sorted(out)

    def wall_value(self, name: str, h: float) -> float:
        """The value of the wall named ``name`` (see :meth:`walls`) at energy h (1/s^4)."""
        for p in self.parabolas:
            if p.name == name:
                return float(p.k(h))
        return 0.0

    def breakpoints(self, lo: float, hi: float) -> list[float]:
        """Energies in (lo, hi) where the walls meet or begin: the vertices' energies."""
        points = {self.h_min}
        hyperbolic = [p for p in self.parabolas if p.type == "hyperbolic"]
        for p in hyperbolic:
            points.update((p.start, p.h_j))
            for q in hyperbolic:
                middle = 0.5 * (p.h_j + q.h_j)
                if q.h_j > p.h_j and middle >= max(p.start, q.start):
                    points.add(middle)
        return sorted(h for h in points if lo < h < hi)

    def cells(self, lo: float, hi: float) -> list[Cell]:
        """Every cell between the energies lo and hi (J), however thin, with its chamber: two
        cells on either side of a vertex energy are one chamber when their gaps overlap there
        (a wall starting on the boundary, or two arcs crossing, splits; a wall ending on
        ``k = 0`` separates)."""
        low = max(lo, self.h_min)
        cuts = [low, *self.breakpoints(low, hi), hi]
        found: list[tuple[float, float, tuple[str, str], float, float, float]] = []
        for a, b in itertools.pairwise(cuts):
            h = 0.5 * (a + b)
            for (k_a, name_a), (k_b, name_b) in itertools.pairwise(self.walls(h)):
                root_a, root_b = math.sqrt(k_a), math.sqrt(k_b)
                thickness = (root_b - root_a) * self.params.C / self.energy_scale
                found.append((a, b, (name_a, name_b), h, (0.5 * (root_a + root_b)) ** 2, thickness))
        parent = list(range(len(found)))

        def root(i: int) -> int:
            while parent[i] != i:
                i = parent[i]
            return i

        tol = 1e-9 * self.upper_scale
        for i, (_, b, left, *_rest) in enumerate(found):
            for j, (a, _, right, *_more) in enumerate(found):
                if a != b:
                    continue
                low_k = max(self.wall_value(left[0], b), self.wall_value(right[0], b))
                high_k = min(self.wall_value(left[1], b), self.wall_value(right[1], b))
                if high_k - low_k > tol:
                    parent[root(j)] = root(i)
        roots = sorted({root(i) for i in range(len(found))})
        return [Cell(*cell, roots.index(root(i))) for i, cell in enumerate(found)]

    def branch_at(self, h: float, k: float) -> str | None:
        """The branch through (h, k) (to :data:`ON_BRANCH` of the scale), or None."""
        scale = self.energy_scale
        if abs(h - self.h_min) <= ON_BRANCH * scale and k <= ON_BRANCH * self.upper_scale:
            return f"vertex (h_min = {fmt(self.h_min, CELL)} J, k = 0)"
        labels = {p.name: p.label for p in self.parabolas}
        for value, name in self.walls(h):
            # compare sqrt(k): the parabolas are straight lines there
            if abs(math.sqrt(max(k, 0.0)) - math.sqrt(value)) * self.params.C <= ON_BRANCH * scale:
                return labels.get(name, name)
        return None

    @property
    def upper_scale(self) -> float:
        return (self.energy_scale / self.params.C) ** 2
