"""What the bifurcation diagram costs, stage by stage, and how firm its tori counts are.

The unit-scale case (examples/scenes/unit_scale.toml: C = 1, c = 0.3, d = -0.4, n = 0.7,
K = 0.5, kappa = 0.9) with the command's default options and energy range. The first stage
includes compiling the exact gradients and Hessians (sympy, once per process). Goal: the
whole diagram under a minute on this machine.

Then the generic case (kappa = 0.05, the rest the same: chambers of 2 and 4 tori): every
cell's count by the default flow counting beside a finer and longer one (2500 gammas x 64
angles, 64 trajectories a round to t = 400, another seed), which must agree.
"""

from __future__ import annotations

import time
from typing import Any

from chargedesign.bench.common import UNIT_SCALE, BenchTable, measured
from chargedesign.formatting import PRECISE, fmt
from chargedesign.topology.chambers import FlowCounting, LevelSampling, count_by_flow
from chargedesign.topology.compute import DiagramOptions
from chargedesign.topology.diagram import Reading, bifurcation_diagram, chamber_labels
from chargedesign.topology.equations import MomentumMap

#: the quick run's diagram options (a smoke run: fewer seeds, a coarser level sampling)
_QUICK_OPTIONS = DiagramOptions(seeds=60, counting=FlowCounting(sampling=LevelSampling(800, 32)))


def run(quick: bool = False) -> list[BenchTable]:
    options = _QUICK_OPTIONS if quick else DiagramOptions()
    diagram, total, _ = measured(bifurcation_diagram, UNIT_SCALE, None, options)
    raw = diagram.raw
    table = BenchTable(
        title="Bifurcation diagram of the unit-scale case: time per stage",
        columns=["stage", "seconds"],
        rows=[[stage, seconds] for stage, seconds in raw.seconds.items()] + [["total", total]],
        notes=[
            f"{len(diagram.branches)} branches, {sum(len(b.hk) for b in diagram.branches)} "
            f"points, {len(raw.vertices)} rank-zero points, {len(raw.chambers)} chamber "
            f"cells, tori per chamber {[c.tori for c in chamber_labels(raw.chambers)]}",
            f"energy range {fmt(raw.h_range[0], PRECISE)} .. {fmt(raw.h_range[1], PRECISE)} J; "
            f"{raw.seeds_found} seeds kept" + (" (quick options)" if quick else ""),
            "goal: total under 60 s; 'equations' includes compiling the exact derivatives",
        ],
    )
    return [table, _generic_counts(quick, diagram if quick else None)]


def _generic_counts(quick: bool, unit: Any = None) -> BenchTable:
    """Each cell of the generic case counted by the default and by a finer flow counting.

    ``unit``: the unit-scale case's diagram, whose first cell the quick run counts instead
    (a smoke run: no second diagram)."""
    generic = UNIT_SCALE if unit is not None else UNIT_SCALE.replace(kappa=0.05)
    reading = Reading.of(generic)
    F = MomentumMap(reading.unit())
    fine = (
        FlowCounting(sampling=LevelSampling(1500, 48), starts=24, t_end=200.0, samples=6000, seed=7)
        if quick
        else FlowCounting(
            sampling=LevelSampling(2500, 64), starts=64, t_end=400.0, samples=12000, seed=7
        )
    )
    t0 = time.perf_counter()
    diagram = (
        unit
        if unit is not None
        else bifurcation_diagram(generic, None, _QUICK_OPTIONS if quick else None)
    )
    seconds = time.perf_counter() - t0
    rows = []
    cells = diagram.raw.chambers[:1] if quick else diagram.raw.chambers
    for cell in cells:
        t1 = time.perf_counter()
        check = count_by_flow(F, reading.energy_unit(cell.h), cell.k / reading.s**4, fine)
        rows.append([cell.chamber, cell.h, cell.k, cell.tori, check.tori, time.perf_counter() - t1])
    agree = all(row[3] == row[4] for row in rows)
    which = (
        "the unit-scale case (--quick)" if unit is not None else "the generic case (kappa = 0.05)"
    )
    return BenchTable(
        title=f"Tori of {which}: default counting and a finer one",
        columns=["chamber", "h (J)", "k (1/s^4)", "tori", "tori (finer)", "seconds (finer)"],
        rows=rows,
        notes=[
            (
                "the diagram of the first table (not timed again); counts"
                if unit is not None
                else f"the whole diagram {fmt(seconds, PRECISE)} s; counts"
            )
            + (" agree in every cell" if agree else " DISAGREE in some cell"),
            *(
                [
                    "--quick: the unit-scale case's diagram (quick options), its first cell, "
                    "and a finer "
                    "counting of 1500 gammas x 48 angles, 24 trajectories to t = 200"
                ]
                if quick
                else []
            ),
        ],
    )
