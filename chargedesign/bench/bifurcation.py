"""What the bifurcation diagram of the unit-scale case costs, stage by stage.

The unit-scale case (examples/scenes/unit_scale.toml: C = 1, c = 0.3, d = -0.4, n = 0.7,
K = 0.5, kappa = 0.9) with the command's default options and energy range. The first stage
includes compiling the exact gradients and Hessians (sympy, once per process). Goal: the
whole diagram under a minute on this machine.
"""

from __future__ import annotations

import time

from chargedesign.bench.common import BenchTable
from chargedesign.formatting import PRECISE, fmt
from chargedesign.params import Parameters
from chargedesign.topology.chambers import FlowCounting, LevelSampling
from chargedesign.topology.compute import DiagramOptions
from chargedesign.topology.diagram import bifurcation_diagram, chamber_labels

#: the unit-scale case's parameters
UNIT_SCALE = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)


def run(quick: bool = False) -> list[BenchTable]:
    options = (
        DiagramOptions(seeds=100, counting=FlowCounting(sampling=LevelSampling(1000, 32)))
        if quick
        else DiagramOptions()
    )
    t0 = time.perf_counter()
    diagram = bifurcation_diagram(UNIT_SCALE, None, options)
    total = time.perf_counter() - t0
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
    return [table]
