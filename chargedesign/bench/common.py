"""Shared pieces of the benchmarks (and the tests): a result table, timers, a random body."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.formatting import fmt
from chargedesign.params import Parameters
from chargedesign.simulation import Body

#: the unit-scale case (examples/scenes/unit_scale.toml): the parameters most tables time
UNIT_SCALE = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)


@dataclass
class BenchTable:
    """One benchmark table: ``rows`` are lists aligned with ``columns``."""

    title: str
    columns: list[str]
    rows: list[list[Any]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    #: optional picture: {"x": column, "y": [columns], "logx": bool, "logy": bool}
    plot: dict[str, Any] | None = None

    def to_markdown(self) -> str:
        def cell(v: Any) -> str:
            return fmt(v) if isinstance(v, float) else str(v)

        lines = [f"### {self.title}", "", "| " + " | ".join(self.columns) + " |"]
        lines.append("|" + "---|" * len(self.columns))
        lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in self.rows]
        lines += [""] + [f"- {n}" for n in self.notes]
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "columns": self.columns,
            "rows": self.rows,
            "notes": self.notes,
            "plot": self.plot,
        }


def measured(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> tuple[Any, float, float]:
    """``fn(*args, **kwargs)`` once: its value, wall seconds and the process's CPU seconds (the
    benchmarks' one timer; CPU time is less sensitive than wall time to other jobs)."""
    wall, cpu = time.perf_counter(), time.process_time()
    value = fn(*args, **kwargs)
    return value, time.perf_counter() - wall, time.process_time() - cpu


def best_time(fn: Callable[[], Any], repeat: int = 3) -> tuple[float, Any]:
    """Smallest wall time of ``repeat`` calls (seconds) and the last result."""
    best = float("inf")
    result = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def random_body(
    seed: int,
    parameters: Parameters,
    fields: dict[str, tuple[float, ...]],
    n_charges: int,
    n_masses: int | None = None,
    n_dipoles: int | None = None,
) -> Body:
    """A body of random elements of every kind (no symmetry at all), for tests and timings.

    Positions uniform in the cube [-1, 1]^3 m, charges and dipole moments standard normal
    (C, A m^2), masses uniform in [0, 1] kg; ``n_masses`` and ``n_dipoles`` default to
    ``n_charges``. It realises nothing: the simulation's routes are compared on it.
    """
    n_masses = n_charges if n_masses is None else n_masses
    n_dipoles = n_charges if n_dipoles is None else n_dipoles
    rng = np.random.default_rng(seed)
    return Body(
        parameters=parameters,
        fields=fields,
        charge_positions=rng.uniform(-1, 1, (n_charges, 3)),
        charge_values=rng.normal(size=n_charges),
        mass_positions=rng.uniform(-1, 1, (n_masses, 3)),
        mass_values=rng.uniform(0, 1, n_masses),
        dipole_positions=rng.uniform(-1, 1, (n_dipoles, 3)),
        dipole_moments=rng.normal(size=(n_dipoles, 3)),
        has_elements=True,
    )
