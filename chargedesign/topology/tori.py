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

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.params import Parameters
from chargedesign.results import Result
from chargedesign.topology.chambers import FlowCount, FlowCounting, count_by_flow
from chargedesign.topology.closed_form import RESOLVED, ClosedForm
from chargedesign.topology.diagram import Reading, check_parameters
from chargedesign.topology.equations import MomentumMap


@dataclass(repr=False)
class ToriCount(Result):
    """Tori over ``(h, k)`` (J, 1/s^4) and how sure the count is."""

    h: float
    k: float
    tori: int
    reason: str  # "bound" (outside the closed-form bounds: empty) or "flow"
    evidence: FlowCount | None

    def to_dict(self) -> dict[str, Any]:
        return {"h": self.h, "k": self.k, "tori": self.tori}

    def _summary(self) -> dict[str, Any]:
        return {"h": self.h, "k": self.k, "tori": self.tori}

    def _text(self) -> str:
        head = f"tori over h = {fmt(self.h, PLAIN)} J, k = {fmt(self.k, PLAIN)} 1/s^4: {self.tori}"
        e = self.evidence
        if e is None:
            bound = "outside 0 <= k <= ((h - h_min) / C)^2 (the proven bound)"
            return f"{head}\n  the level is empty: {bound}\n"
        assert e.plateau is not None
        lines = [
            head,
            f"  by the flow: {e.points} samples of the level, {e.trajectories} trajectories;"
            f" the count holds for every join distance from {fmt(e.plateau[0], CELL)} to"
            f" {fmt(e.plateau[1], CELL)} (scaled states) with every sample passed by a"
            " trajectory",
        ]
        if e.separation is not None:
            lines.append(
                f"  the tori's samples are at least {fmt(e.separation, CELL)} apart"
                f" ({fmt(e.separation / e.plateau[1], CELL)} times the largest join distance)"
            )
        return "\n".join(lines) + "\n"


def tori_at(
    params: Parameters, h: float, k: float, counting: FlowCounting | None = None
) -> ToriCount:
    """The number of tori of the level ``H = h, I4 = k`` on ``I3 = 0, |gamma| = 1``.

    Raises
    ------
    InputError
        Singular or degenerate parameters; ``(h, k)`` on a branch (a critical value); a count
        that no range of join distances supports (the level too close to a branch).
    """
    check_parameters(params)
    if not (np.isfinite(h) and np.isfinite(k)):
        raise InputError(f"--tori: expected two finite numbers H K, got {h} {k}")
    closed = ClosedForm.of(params)
    branch = closed.branch_at(h, k)
    if branch is not None:
        raise InputError(
            f"--tori: (h, k) = ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) is a critical value, on the"
            f" {branch}: the level is not a union of tori"
        )
    if h <= closed.h_min or k < 0.0 or k > closed.upper(h):
        return ToriCount(h, k, 0, "bound", None)
    nearest, name = closed.distance(h, k)
    if nearest < RESOLVED:
        raise InputError(
            f"--tori: (h, k) = ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) is within"
            f" {fmt(nearest, CELL)} of the energy spread from the {name}: its tori are closer"
            f" together than the counting resolves (it needs {fmt(RESOLVED, CELL)})"
        )
    reading = Reading.of(params)
    F = MomentumMap(reading.unit())
    found = count_by_flow(F, reading.energy_unit(h), k / reading.s**4, counting)
    if found.points == 0:
        raise InputError(
            f"--tori: no state of the level ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) found on the"
            " sampled conics although it lies inside the proven bounds: not counted"
        )
    if found.tori is None:
        pairs = zip(found.counts, found.deltas, strict=True)
        counts = ", ".join(f"{c} at {fmt(d, CELL)}" for c, d in pairs)
        raise InputError(
            f"--tori: the count at ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) is not resolved: no count"
            f" holds over a factor 2 of join distances with every sample covered ({counts});"
            " the level is too close to a branch for this sampling"
        )
    return ToriCount(h, k, found.tori, "flow", found)
