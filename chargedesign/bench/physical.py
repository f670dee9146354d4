"""Physical design: constraint generation against the plain cvxpy program; a frontier point.

Baselines measured in the same run:

- the charges' stage of the default body at growing candidate counts, by constraint
  generation (LP with own-field bounds, tightened, then cones only where needed) against the
  same problem written as one cvxpy program with cones at every sample of every carrier
  (Clarabel); the plain program is run while its dense cone matrices stay below 0.5 GB;
- the whole physical design (both stages) and one frontier point of the default scene.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from chargedesign.bench.common import BenchTable

#: candidate spacings (m) of the 5 cm default ball: 257 ... about 1e4 candidates
SPACINGS = (0.0125, 0.00833, 0.005, 0.0036)
PLAIN_SAMPLES = 26
#: the plain program runs while its dense cone matrices stay below this (bytes); at 924
#: candidates (1.6 GB) Clarabel had not finished after 10 minutes on this machine
PLAIN_MEMORY_LIMIT = 5e8


def _setup(spacing: float) -> Any:
    import tomllib

    from chargedesign.design.pipeline import physical_setup_from_scene
    from chargedesign.scene import default_scene_text, scene_from_dict

    data = tomllib.loads(default_scene_text())
    data["body"]["spacing"] = spacing
    data["body"]["carrier_radius"] = spacing / 4
    return physical_setup_from_scene(scene_from_dict(data, f"<default, spacing {spacing}>"))


def table_constraint_generation(quick: bool) -> BenchTable:
    import cvxpy as cp

    from chargedesign.design.physical import charge_program, design_charges, design_masses

    table = BenchTable(
        title="Physical design of the default body: constraint generation vs plain cvxpy",
        columns=["candidates", "method", "charges_s", "whole_design_s", "sum_abs_q_C", "ratio"],
        notes=[
            "baseline: the same charges' problem as one cvxpy program with second-order cones "
            f"at {PLAIN_SAMPLES} samples on every candidate carrier, solved by Clarabel",
            "constraint generation: HiGHS LP with each carrier's own-field bound, tightened "
            "where neighbours add to the field, then cones only at the carriers near their limit",
            "whole_design_s: charges, then magnets and ballast (one Clarabel program)",
            "ratio: plain time over constraint-generation time for the charges' stage",
        ],
        plot={"x": "candidates", "y": ["charges_s"], "group": "method", "logx": True, "logy": True},
    )
    for spacing in SPACINGS[:1] if quick else SPACINGS:
        setup = _setup(spacing)
        n = len(setup.points)
        t0 = time.perf_counter()
        fast = design_charges(setup, 1.0)
        t_fast = time.perf_counter() - t0
        design_masses(setup, 1.0, fast.sites)
        t_whole = time.perf_counter() - t0
        table.rows.append(
            [n, "constraint generation", t_fast, t_whole, float(np.sum(np.abs(fast.charges))), 1.0]
        )
        size = n * PLAIN_SAMPLES * 3 * n * 8 * 3  # G, its copy and cvxpy's canonical form
        if size > PLAIN_MEMORY_LIMIT or (quick and n > 300):
            table.rows.append([n, "plain cvxpy", "not run", "", "", ""])
            table.notes.append(
                f"plain cvxpy at {n} candidates: not run (dense cones ~{size / 1e9:.1f} GB)"
            )
            continue
        t0 = time.perf_counter()
        program = charge_program(setup, 1.0, samples=PLAIN_SAMPLES)
        program.problem.solve(solver=cp.CLARABEL)
        t_plain = time.perf_counter() - t0
        q = np.asarray(program.q.value) * program.charge_scale
        table.rows.append(
            [n, "plain cvxpy", t_plain, "", float(np.sum(np.abs(q))), t_plain / t_fast]
        )
    return table


def table_frontier(quick: bool) -> BenchTable:
    from chargedesign.design.frontier import find_frontier

    table = BenchTable(
        title="One frontier point of the default body (largest time rate within the limits)",
        columns=["candidates", "s_max", "n_max_1_per_s", "probes", "seconds", "binding"],
        notes=["bisection in log s to 1 %, with upward restarts; each probe is a full design"],
    )
    setup = _setup(SPACINGS[0])
    result = find_frontier(setup)
    table.rows.append(
        [
            len(setup.points),
            result.s_max,
            result.n_max,
            result.evaluations,
            result.seconds,
            result.binding.stage,
        ]
    )
    return table


def run(quick: bool = False) -> list[BenchTable]:
    return [table_constraint_generation(quick), table_frontier(quick)]
