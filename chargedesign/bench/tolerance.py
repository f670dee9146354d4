"""Tolerance benchmarks: the Monte Carlo of perturbed bodies and its batch simulation.

The default scene's body (designed once, not timed) with Gaussian position errors of 20 um:
1000 perturbed bodies (50 with ``quick``) integrated to t = 100 s (10 s) in one batch, their
mu, V and inertia errors, and the linear-response prediction. The baseline is the sensitivity
report alone (exact derivatives, no sampling).
"""

from __future__ import annotations

import time

import numpy as np

from chargedesign.bench.common import BenchTable


def run(quick: bool = False) -> list[BenchTable]:
    from chargedesign.design import design_from_scene
    from chargedesign.scene import load_scene
    from chargedesign.tolerance import ErrorModel, monte_carlo, tolerance_report

    design = design_from_scene(load_scene(None)).design
    bodies = 50 if quick else 1000
    t_end = 10.0 if quick else 100.0
    t0 = time.perf_counter()
    tolerance_report(design)
    base = time.perf_counter() - t0
    model = ErrorModel.parse(position="20um")
    t0 = time.perf_counter()
    result = monte_carlo(design, model, samples=bodies, t_end=t_end, levels=(1.0,))
    total = time.perf_counter() - t0
    mc = float(np.median(result.drift_mc[0]))
    lin = float(np.median(result.drift_linear[0]))
    s = result.seconds
    table = BenchTable(
        title=f"Tolerance Monte Carlo: {bodies} perturbed bodies to t = {t_end:g} s",
        columns=[
            "bodies",
            "t_end s",
            "total s",
            "simulation s",
            "errors s",
            "linear response s",
            "sensitivity s (baseline)",
            "total / baseline",
            "I4 drift median (MC)",
            "I4 drift median (linear)",
            "MC / linear",
        ],
        rows=[
            [
                bodies,
                t_end,
                total,
                s.get("simulation", float("nan")),
                s.get("errors", float("nan")),
                s.get("linear_drift", float("nan")),
                base,
                total / base,
                mc,
                lin,
                mc / lin,
            ]
        ],
        notes=[
            "default scene's body (25 charges, 4 dipoles, 6 masses), Gaussian position errors "
            "of 20 um per coordinate; one DOP853 batch (rtol = atol = 1e-10) for all bodies plus "
            "the nominal one",
            f"nominal body's own drift (integration floor): {result.nominal_drift:.2e}",
        ],
    )
    return [table]
