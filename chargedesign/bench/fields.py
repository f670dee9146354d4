"""Throughput of the body-axes field evaluations (``AxisymmetricField.gradient_body``).

Baselines measured in the same run: filling an output-sized (m, n, 3) array once (the memory
traffic any evaluation must pay) and a straightforward per-orientation loop (rotate the points
to space axes, call ``gradient``, rotate back).
"""

from __future__ import annotations

import numpy as np

from chargedesign.bench.common import BenchTable, best_time
from chargedesign.fields import AxisymmetricField
from chargedesign.simulation import attitude_from_gamma


def run(quick: bool = False) -> list[BenchTable]:
    """Evaluations per second of ``gradient_body`` for fields of degree 1, 2, 4 and 6."""
    rng = np.random.default_rng(0)
    m, n = (100, 1000) if quick else (1000, 1000)
    repeat = 2 if quick else 5
    points = rng.normal(size=(n, 3))
    gammas = rng.normal(size=(m, 3))
    gammas /= np.linalg.norm(gammas, axis=1)[:, None]
    t_fill, _ = best_time(lambda: np.full((m, n, 3), 1.0), repeat)
    loop_m = min(m, 50)
    rotations = [attitude_from_gamma(g) for g in gammas[:loop_m]]
    table = BenchTable(
        title=f"gradient_body: {m} orientations x {n} points",
        columns=[
            "degree",
            "evaluations per s",
            "time / (filling the output)",
            "speed-up over per-orientation loop",
        ],
    )
    for degree in (1, 2, 4, 6):
        field = AxisymmetricField(tuple(rng.uniform(-1.0, 1.0, size=degree)))

        def fast(f: AxisymmetricField = field) -> np.ndarray:
            return f.gradient_body(points, gammas)

        t_fast, _ = best_time(fast, repeat)

        def loop(f: AxisymmetricField = field) -> list[np.ndarray]:
            return [f.gradient(points @ R.T) @ R for R in rotations]

        t_loop, _ = best_time(loop, repeat)
        per_pair_loop = t_loop / (loop_m * n)
        per_pair_fast = t_fast / (m * n)
        table.rows.append([degree, m * n / t_fast, t_fast / t_fill, per_pair_loop / per_pair_fast])
    table.notes.append(
        "evaluations = orientation-point pairs; best of several runs; 2-core machine shared "
        "with other work, so absolute rates vary by tens of percent."
    )
    return [table]
