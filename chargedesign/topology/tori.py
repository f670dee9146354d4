"""The number of Liouville tori over one point (h, k) of the diagram, at the user's parameters.

The point is read at the unit scale and n = 0 (:class:`~chargedesign.topology.diagram.Reading`:
the counting has no n in it) and the level is counted by the flow
(:func:`~chargedesign.topology.chambers.count_by_flow`). Outside the closed-form bounds
(``h`` below the least energy or ``k`` above ``((h - h_min) / C)^2``, or ``k < 0``) the level is
empty and nothing is sampled; on a branch (:class:`~chargedesign.topology.closed_form.ClosedForm`)
the level is singular and the count is refused in one line naming the branch.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.params import Parameters
from chargedesign.results import Result
from chargedesign.scene.bifurcation import (
    check_regular_value,
    check_tori_point,
    refuse_no_chamber,
    refuse_unresolved_chamber,
)
from chargedesign.topology.chambers import FlowCount, FlowCounting, count_by_flow
from chargedesign.topology.closed_form import Cell, ClosedForm
from chargedesign.topology.diagram import Reading, check_parameters, require_energy_in_scale
from chargedesign.topology.equations import MomentumMap


@dataclass(repr=False)
class ToriCount(Result):
    """Tori over ``(h, k)`` (J, 1/s^4) and how sure the count is.

    The count is constant over a chamber (its levels are diffeomorphic: a connected set of
    regular values), so it is counted where the chamber's tori are farthest apart, ``best``
    (the middle of its thickest cell, :func:`best_cell`), and at (h, k) itself as a check;
    ``middle`` and ``at_point`` are the two counts' evidence.
    """

    h: float
    k: float
    tori: int
    best: tuple[float, float] | None = None
    middle: FlowCount | None = None
    at_point: FlowCount | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"h": self.h, "k": self.k, "tori": self.tori}

    def _summary(self) -> dict[str, Any]:
        return self.to_dict()

    def _text(self) -> str:
        head = f"tori over h = {fmt(self.h, PLAIN)} J, k = {fmt(self.k, PLAIN)} 1/s^4: {self.tori}"
        e = self.middle
        if e is None or e.plateau is None or self.best is None:
            bound = "outside 0 <= k <= ((h - h_min) / C)^2 (the proven bound)"
            return f"{head}\n  the level is empty: {bound}\n"
        lines = [
            head,
            f"  counted by the flow at its chamber's thickest point (h = {fmt(self.best[0], CELL)}"
            f" J, k = {fmt(self.best[1], CELL)} 1/s^4), where its tori are farthest apart:"
            f" {e.points} samples, {e.trajectories} trajectories; the count holds for every join"
            f" distance from {fmt(e.plateau[0], CELL)} to {fmt(e.plateau[1], CELL)} (scaled"
            " states) with every sample passed by a trajectory",
        ]
        if e.separation is not None:
            lines.append(f"  the tori's samples there are at least {fmt(e.separation, CELL)} apart")
        p = self.at_point
        if p is not None:
            if p.tori == self.tori:
                lines.append(
                    f"  at (h, k) itself the flow gives the same count ({p.points} samples)"
                )
            else:
                found = "no count" if p.tori is None else str(p.tori)
                lines.append(
                    f"  at (h, k) itself the flow gives {found} (counts {p.counts} over join"
                    f" distances {p.deltas}): the tori there come closer together than the"
                    " counting resolves; the chamber's count is the level's"
                )
        return "\n".join(lines) + "\n"


def tori_at(
    params: Parameters, h: float, k: float, counting: FlowCounting | None = None
) -> ToriCount:
    """The number of tori of the level ``H = h, I4 = k`` on ``I3 = 0, |gamma| = 1``.

    Raises
    ------
    InputError
        Singular or degenerate parameters; ``(h, k)`` on a branch (a critical value); a
        chamber whose count no range of join distances supports.
    """
    closed = check_parameters(params)
    check_tori_point(h, k)
    check_regular_value(h, k, closed.branch_at(h, k))
    if h <= closed.h_min or k < 0.0 or k > closed.upper(h):
        return ToriCount(h, k, 0)
    require_energy_in_scale(closed, h, "--tori")
    best = best_cell(closed, h, k)
    reading = Reading.of(params)
    F = MomentumMap(reading.unit())
    middle = count_by_flow(F, reading.energy_unit(best.h), best.k / reading.s**4, counting)
    if middle.tori is None:
        refuse_unresolved_chamber(h, k, (best.h, best.k), middle.counts, middle.deltas)
    at_point = count_by_flow(F, reading.energy_unit(h), k / reading.s**4, counting)
    return ToriCount(h, k, middle.tori, (best.h, best.k), middle, at_point)


def best_cell(closed: ClosedForm, h: float, k: float) -> Cell:
    """The thickest cell (at its middle) of the chamber of the regular value (h, k) inside the
    admissible region: there the chamber's tori are farthest apart."""
    top = max(h, *closed.energies) + closed.energy_scale
    cells = closed.cells(closed.h_min, top)
    for cell in cells:
        if cell.a <= h <= cell.b:
            low, high = (closed.wall_value(name, h) for name in cell.walls)
            if low < k < high:
                return max(
                    (c for c in cells if c.chamber == cell.chamber), key=lambda c: c.thickness
                )
    refuse_no_chamber(h, k)
