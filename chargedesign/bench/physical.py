"""Physical design: constraint generation against the plain cvxpy program; a frontier point.

Baselines measured in the same run:

- the charges' stage of the default body at growing candidate counts, by constraint
  generation (LP with own-field bounds, tightened, then cones only where needed) against the
  same problem written as one cvxpy program with cones at every sample of every carrier
  (Clarabel); the plain program is run while its dense cone matrices stay below 0.5 GB;
- the whole physical design (both stages, with the design's acceptance) and one frontier
  point of the default scene, in the ``frame`` Larmor reading (the default with
  ``[medium]``: the body realises n = 0, only K's third moments need charges) beside the
  ``charges`` reading (the paper's (p6), the baseline of the ratios).
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


#: the Larmor readings compared; the first is the baseline of the ratios
READINGS = ("charges", "frame")


def _setup(spacing: float, larmor: str = "charges") -> Any:
    import tomllib

    from chargedesign.designer.pipeline import physical_setup_from_scene
    from chargedesign.scene import default_scene_text, scene_from_dict

    data = tomllib.loads(default_scene_text())
    data["body"]["spacing"] = spacing
    data["body"]["carrier_radius"] = spacing / 4
    data.setdefault("design", {})["larmor"] = larmor
    return physical_setup_from_scene(
        scene_from_dict(data, f"<default, spacing {spacing}, {larmor}>")
    )


def table_constraint_generation(quick: bool) -> BenchTable:
    import cvxpy as cp

    from chargedesign.designer.physical import charge_program, design_charges, design_masses

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


def table_readings(quick: bool) -> BenchTable:
    """The default body designed and its frontier located in both Larmor readings."""
    from chargedesign.designer.acceptance import forward_acceptance
    from chargedesign.designer.frontier import find_frontier
    from chargedesign.designer.physical import design_physical

    table = BenchTable(
        title="The default body in both Larmor readings: the design and one frontier point",
        columns=[
            "reading",
            "candidates",
            "carriers",
            "design_s",
            "s_max",
            "K_max_1_per_s",
            "n_max_1_per_s",
            "probes",
            "frontier_s",
            "s_per_probe",
            "binding",
            "K_max_ratio",
            "frontier_time_ratio",
        ],
        notes=[
            "design_s: both stages, the limits check, the realism budget and the forward check "
            "(the design's acceptance) at the scene's rate",
            "frontier: the charges' limit s_c from their minmax (one SOCP), then the design at "
            "s_c (1 - rtol/4) and s_c / (1 + rtol); where those are refused, bisection in "
            "log s to 1 %, with upward restarts and the check at (1 +- 2 %) s_max; each probe "
            "is the design's per-rate acceptance (both stages, the balance), the limits check "
            "and the forward check; probes: the designs run (rates above a proved refusal, "
            "and above s_c, are refused without one)",
            "ratios against the charges reading (the paper's (p6)), measured in the same run",
            "frame: n is free (a rotation of axes), so n_max has no meaning there",
        ],
    )
    base: dict[str, float] = {}
    for reading in READINGS:
        setup = _setup(SPACINGS[0], reading)
        t0 = time.perf_counter()
        design = design_physical(setup).design
        forward_acceptance(design)
        t_design = time.perf_counter() - t0
        result = find_frontier(setup)
        if not base:
            base = {"K_max": result.K_max, "seconds": result.seconds}
        table.rows.append(
            [
                reading,
                len(setup.points),
                len(design.charge_values),
                t_design,
                result.s_max,
                result.K_max,
                result.n_max if result.n_max is not None else "free",
                result.evaluations,
                result.seconds,
                result.seconds / max(result.evaluations, 1),
                result.binding.stage,
                result.K_max / base["K_max"] if base["K_max"] > 0 else "",
                result.seconds / base["seconds"],
            ]
        )
    return table


def run(quick: bool = False) -> list[BenchTable]:
    return [table_constraint_generation(quick), table_readings(quick)]
