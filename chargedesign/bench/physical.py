"""Physical design: constraint generation against the plain cvxpy program; a frontier point.

Baselines measured in the same run:

- the charges' stage of the default body at growing candidate counts, by constraint
  generation (LP with own-field bounds, tightened, then cones only where needed) against the
  same problem written as one cvxpy program with cones at every sample of every carrier
  (Clarabel); the plain program is run while its dense cone matrices stay below 0.5 GB;
- the whole physical design (both stages, with the design's acceptance) and one frontier
  point of the default scene, in the ``frame`` Larmor reading (the default with
  ``[medium]``: the body realises n = 0, only K's third moments need charges) beside the
  ``charges`` reading (the paper's (p6), the baseline of the ratios);
- the default scene's frontier point (``chargedesign frontier --json`` without the start-up:
  issue 20's goal of 10 s) stage by stage, wall and CPU time, and the limits check of its
  body with its direct Coulomb sum (the baseline of the ratio) beside the design's
  matrix-product kernel;
- the same frontier point with every cone program of the charges' stage sent to Clarabel
  (the baseline) beside the dense interior point that solves them first
  (:mod:`chargedesign.designer.cone_program`);
- the realised window (:mod:`chargedesign.physical.window`) beside the plain frontier point
  (the baseline), and the search of ``frontier --recommend`` on the default scene.
"""

from __future__ import annotations

import time
import tomllib
from functools import cache
from typing import Any
from unittest import mock

import numpy as np

from chargedesign.bench.common import BenchTable, measured
from chargedesign.designer.acceptance import forward_acceptance
from chargedesign.designer.assembly import build_design, design_at_rate, design_physical
from chargedesign.designer.charges import charge_program, design_charges
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.frontier import WindowOptions, find_frontier
from chargedesign.designer.masses import design_masses
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.designer.recommend import recommend
from chargedesign.physical import coulomb, limits
from chargedesign.scene import default_scene_text, load_scene, scene_from_dict
from chargedesign.scene.keys import KEY

#: candidate spacings (m) of the 5 cm default ball: 257 ... about 1e4 candidates
SPACINGS = (0.0125, 0.00833, 0.005, 0.0036)
PLAIN_SAMPLES = 26
#: the candidate spacing (m) of every table under --quick (81 candidates): a smoke run
QUICK_SPACING = 0.02
#: the frontier's bracket under --quick in the readings table (the default is 1 %)
QUICK_RTOL = 0.5
#: the plain program runs while its dense cone matrices stay below this (bytes); at 924
#: candidates (1.6 GB) Clarabel had not finished after 10 minutes on this machine
PLAIN_MEMORY_LIMIT = 5e8


#: the Larmor readings compared; the first is the baseline of the ratios
READINGS = ("charges", "frame")


def _setup(spacing: float, larmor: str = "charges") -> Any:
    data = tomllib.loads(default_scene_text())
    data["body"]["spacing"] = spacing
    data["body"][KEY.carrier_radius] = spacing / 4
    data.setdefault("design", {})["larmor"] = larmor
    return physical_setup_from_scene(
        scene_from_dict(data, f"<default, spacing {spacing}, {larmor}>")
    )


def table_constraint_generation(quick: bool) -> BenchTable:
    import cvxpy as cp

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
    if quick:
        table.notes.append(f"--quick: the default ball at spacing {QUICK_SPACING} m only")
    for spacing in (QUICK_SPACING,) if quick else SPACINGS:
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
        if size > PLAIN_MEMORY_LIMIT or quick:
            table.rows.append([n, "plain cvxpy", "not run", "", "", ""])
            table.notes.append(
                f"plain cvxpy at {n} candidates: not run "
                + ("(--quick)" if quick else f"(dense cones ~{size / 1e9:.1f} GB)")
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


@cache
def _quick_frontier() -> tuple[Any, tuple[float, float], Any, tuple[float, float]]:
    """The quick run's plain frontier point (frame reading at ``QUICK_SPACING``): its setup,
    the setup's (wall, CPU) seconds, the result and its (wall, CPU) seconds. Measured once
    and shared by the quick tables, whose baselines or rows are this same computation (the
    full run measures each table's own)."""
    setup, setup_wall, setup_cpu = measured(_setup, QUICK_SPACING, "frame")
    result, wall, cpu = measured(find_frontier, setup)
    return setup, (setup_wall, setup_cpu), result, (wall, cpu)


def table_readings(quick: bool) -> BenchTable:
    """The default body designed and its frontier located in both Larmor readings."""
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
    spacing = QUICK_SPACING if quick else SPACINGS[0]
    if quick:
        table.notes.append(
            f"--quick: the default ball at spacing {QUICK_SPACING} m, each frontier to "
            f"{QUICK_RTOL:.0%} (fewer bisection probes)"
        )
    for reading in READINGS:
        table.rows.append(_reading_row(reading, base, spacing, QUICK_RTOL if quick else None))
    return table


def _reading_row(
    reading: str, base: dict[str, float], spacing: float, rtol: float | None = None
) -> list[Any]:
    """One reading's design and frontier (to ``rtol``; None: the frontier's default), timed;
    the first reading sets ``base``, the charges reading the ratios are taken against."""
    setup = _setup(spacing, reading)
    t0 = time.perf_counter()
    design = design_physical(setup).design
    forward_acceptance(design)
    t_design = time.perf_counter() - t0
    if rtol is not None and reading == "frame" and spacing == QUICK_SPACING:
        # quick: the frame frontier is its direct step (one design, whatever rtol): the quick
        # run's shared plain frontier point
        result = _quick_frontier()[2]
    else:
        result = find_frontier(setup) if rtol is None else find_frontier(setup, rtol=rtol)
    if not base:
        base.update({"K_max": result.K_max, "seconds": result.seconds})
    return [
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


def _limits_kernel_ratio(design: Any) -> tuple[list[Any], list[Any]]:
    """The limits check's surface fields of ``design`` with the direct Coulomb sum in place
    of its kernel (the baseline) and by its own matrix-product kernel, timed: two rows."""
    args = (
        design.charge_positions,
        design.charge_values,
        design.carrier_radii(),
        design.field("electric"),
    )
    with mock.patch.object(limits, "coulomb_field_gemm", coulomb.coulomb_field):
        (direct, _), base_wall, base_cpu = measured(limits.carrier_surface_fields, *args)
    (fast, _), wall, cpu = measured(limits.carrier_surface_fields, *args)
    agree = float(np.max(np.abs(fast / direct - 1.0), initial=0.0))
    return (
        ["limits check surface fields: direct sum", base_wall, base_cpu, 1.0, ""],
        ["the same with matrix products (its kernel)", wall, cpu, cpu / base_cpu, agree],
    )


def table_frontier_point(quick: bool) -> BenchTable:
    """The default scene's frontier point (issue 20: within 10 s), stage by stage."""
    table = BenchTable(
        title="The default scene's frontier point (chargedesign frontier --json), by stage",
        columns=["stage", "wall_s", "cpu_s", "cpu_ratio", "fields_agree_rel"],
        notes=[
            "the default scene (frame reading) as `chargedesign frontier --json` runs it, "
            "without the interpreter's start-up and imports (about 3 s on this machine)",
            "cpu_s: the process's CPU time, less sensitive than wall time to other jobs on "
            "the machine; wall_s is what a user waits",
            "cpu_ratio of the stages: their share of the frontier point",
            "cpu_ratio of the kernels: the limits check's surface fields of the frontier's "
            "body (1000 samples per carrier, 4 refinements) by its matrix-product kernel "
            "over the direct sum in its place (the baseline, measured in the same run); "
            "fields_agree_rel: their largest relative difference",
        ],
    )
    if quick:
        table.notes.append(f"--quick: the default ball at spacing {QUICK_SPACING} m")
        setup, setup_times, result, (wall, cpu) = _quick_frontier()
    else:
        setup, setup_wall, setup_cpu = measured(physical_setup_from_scene, load_scene(None))
        setup_times = (setup_wall, setup_cpu)
        result, wall, cpu = measured(find_frontier, setup)
    table.rows.append(["scene to physical setup (conditions)", *setup_times, "", ""])
    table.rows.append([f"find_frontier ({result.evaluations} design)", wall, cpu, "", ""])
    total_wall = sum(float(row[1]) for row in table.rows)
    total_cpu = sum(float(row[2]) for row in table.rows)
    for row in table.rows:
        row[3] = float(row[2]) / total_cpu
    table.rows.append(["frontier point (setup + find_frontier)", total_wall, total_cpu, 1.0, ""])
    table.rows.extend(
        _limits_kernel_ratio(build_design(setup, design_at_rate(setup, result.s_max)))
    )
    return table


def table_cone_solvers(quick: bool) -> BenchTable:
    """The default scene's frontier point with the charges' cone programs by Clarabel (the
    baseline) and by the dense interior point (Clarabel only where it does not converge)."""
    table = BenchTable(
        title="The frontier point's cone programs: dense interior point against Clarabel",
        columns=["cone solver", "wall_s", "cpu_s", "cpu_ratio", "s_max", "s_max_rel_diff"],
        notes=[
            "find_frontier on the default scene's physical setup (built once, not timed)",
            "baseline: every cone program of the charges' stage (the minmax and the design's "
            "surface cones) by Clarabel (faer, tolerances 1e-8), measured in the same run",
            "s_max_rel_diff: against the baseline's; the two solvers stop at different points "
            "of the minmax's degenerate minimum, so the rates agree to the minmax's gap (1e-3)",
        ],
    )
    if quick:
        table.notes.append(
            f"--quick: the default ball at spacing {QUICK_SPACING} m; the dense row is the "
            "quick run's one plain frontier point (the frontier point's table)"
        )
        setup, _, dense, (wall, cpu) = _quick_frontier()
    else:
        setup = physical_setup_from_scene(load_scene(None))
    with mock.patch.object(ConeProgram, "solve", ConeProgram.solve_clarabel):
        baseline, base_wall, base_cpu = measured(find_frontier, setup)
    if not quick:
        dense, wall, cpu = measured(find_frontier, setup)
    table.rows.append(["Clarabel", base_wall, base_cpu, 1.0, baseline.s_max, 0.0])
    table.rows.append(
        [
            "dense interior point",
            wall,
            cpu,
            cpu / base_cpu,
            dense.s_max,
            abs(dense.s_max / baseline.s_max - 1.0) if baseline.s_max > 0 else "",
        ]
    )
    return table


def table_realised_window(quick: bool) -> BenchTable:
    """The realised window and its search on the default scene, against the plain frontier
    point in the same run."""
    table = BenchTable(
        title="The realised window and its search (frontier --recommend) on the default scene",
        columns=["what", "wall_s", "cpu_s", "cpu_ratio", "frontiers", "result"],
        notes=[
            "baseline: the default scene's plain frontier point (find_frontier), measured in "
            "the same run; the physical setup is built once, not timed",
            "the window: its laws from the body at s_max, solved on 801 rates, then bodies "
            "designed at its ends (none when it is empty)",
            "the search: coordinate-wise over a1 = 0, a2 x (0.03 ... 3), the magnets, the "
            "ballast, the size x (0.5 ... 4) and the medium, every point a frontier with its "
            "window (recommend, the scene written by --recommend)",
        ],
    )
    scene = load_scene(None)
    if quick:  # the baseline: the quick run's one plain frontier point
        setup, _, plain, (base_wall, base_cpu) = _quick_frontier()
    else:
        setup = physical_setup_from_scene(scene)
        plain, base_wall, base_cpu = measured(find_frontier, setup)
    table.rows.append(["plain frontier point", base_wall, base_cpu, 1.0, 1, plain.s_max])
    windowed, wall, cpu = measured(find_frontier, setup, window=WindowOptions())
    window = windowed.realised
    assert window is not None
    summary = (
        f"empty, missing x {window.missing:.2g}"
        if window.empty
        else f"[{window.s_low:.4g}, {window.s_high:.4g}]"
    )
    table.rows.append(["frontier point with its window", wall, cpu, cpu / base_cpu, 1, summary])
    if quick:
        table.notes.append(f"--quick: the default ball at spacing {QUICK_SPACING} m; no search")
        return table
    found, wall, cpu = measured(recommend, scene, WindowOptions())
    best = "; ".join(found.changes) or "the scene itself"
    table.rows.append(
        [
            "window search (--recommend)",
            wall,
            cpu,
            cpu / base_cpu,
            found.evaluations,
            f"{found.best.text()} ({best})",
        ]
    )
    return table


def run(quick: bool = False) -> list[BenchTable]:
    return [
        table_constraint_generation(quick),
        table_readings(quick),
        table_frontier_point(quick),
        table_cone_solvers(quick),
        table_realised_window(quick),
    ]
