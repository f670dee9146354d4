"""Tolerance benchmarks: the Monte Carlo of perturbed bodies and its batch simulation.

The unit-scale body (``examples/scenes/unit_scale.toml``: the motion has a time scale of
seconds, so t = 100 s is many turns; the embedded SI default turns once in about 1e6 s),
designed once and not timed, with Gaussian position errors of 20 um:
1000 perturbed bodies (50 with ``quick``) integrated to t = 100 s (10 s) in one batch, their
mu, V and inertia errors, and the linear-response prediction. The baseline is the sensitivity
report alone (exact derivatives, no sampling).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from chargedesign.bench.common import UNIT_SCALE, BenchTable
from chargedesign.designer import design_from_scene
from chargedesign.formatting import AGREEMENT, PLAIN, fmt
from chargedesign.scene import scene_from_dict
from chargedesign.tolerancing import ErrorModel, monte_carlo, tolerance_report

#: examples/scenes/unit_scale.toml, inline so the bench runs from an installed package
UNIT_SCENE = {
    "parameters": UNIT_SCALE.as_dict(),
    "fields": {"magnetic": {"a1": 1.0, "a2": 0.5}, "gravity": {"legendre": [9.81]}},
    "body": {"shape": "ball", "radius": 1.0, "spacing": 0.25},
    "design": {"realise": ["mu", "V", "inertia"]},
}


def run(quick: bool = False) -> list[BenchTable]:
    design = design_from_scene(scene_from_dict(UNIT_SCENE)).design
    bodies = 50 if quick else 1000
    t_end = 10.0 if quick else 100.0
    t0 = time.perf_counter()
    tolerance_report(design)
    base = time.perf_counter() - t0
    model = ErrorModel.parse(position="20um")
    t0 = time.perf_counter()
    result = monte_carlo(design, model, samples=bodies, t_end=t_end, levels=(1.0,))
    total = time.perf_counter() - t0
    return [_monte_carlo_table(design, result, bodies, t_end, total, base)]


def _monte_carlo_table(
    design: Any, result: Any, bodies: int, t_end: float, total: float, base: float
) -> BenchTable:
    """The Monte Carlo's times against the linear baseline, and its drifts against the linear."""
    mc = float(np.median(result.drift_mc[0]))
    lin = float(np.median(result.drift_linear[0]))
    s = result.seconds
    return BenchTable(
        title=f"Tolerance Monte Carlo: {bodies} perturbed bodies to t = {fmt(t_end, PLAIN)} s",
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
            f"unit-scale body ({len(design.charge_values)} charges, "
            f"{len(design.dipole_moments)} dipoles, {len(design.mass_values)} masses), Gaussian "
            "position errors of 20 um per coordinate; one DOP853 batch (rtol = atol = 1e-10) for "
            "all bodies plus the nominal one",
            f"nominal body's own drift (integration floor): {fmt(result.nominal_drift, AGREEMENT)}",
        ],
    )
