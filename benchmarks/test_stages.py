"""One benchmark per stage, each calling the package's own entry point (no copies).

pytest-benchmark; not part of ``make test`` (its testpaths is ``tests``). Run from the
repository root: ``python -m pytest benchmarks --benchmark-only``. Each benchmark calls a
stage once per round (the stages take seconds: ``benchmark.pedantic`` with few rounds, not
pytest-benchmark's calibration loop), on the repository's example scenes at small sizes, so
the folder runs in a few minutes on two cores. ``chargedesign bench`` keeps the user's
tables with their baselines and ratios (docs/benchmarks.md).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import chargedesign as cd
from chargedesign.scene.case_file import read_case
from chargedesign.topology.case_map import CaseMomentumMap, case_trajectories

os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parents[1]
#: the theorem's parameters at unit scale, point elements (the mathematical case)
UNIT_SCALE = ROOT / "examples" / "scenes" / "unit_scale.toml"
#: a Kowalevski top entered as a [case]
KOWALEVSKI_CASE = ROOT / "examples" / "scenes" / "kowalevski_case.toml"


@pytest.fixture(scope="module")
def unit_design() -> Any:
    """The unit-scale scene designed once (the input of check and simulate)."""
    return cd.design(str(UNIT_SCALE))


def _once(benchmark: Any, stage: Any, *args: Any, rounds: int = 1, **kwargs: Any) -> Any:
    """The stage timed ``rounds`` times, one call per round; its last result."""
    return benchmark.pedantic(stage, args=args, kwargs=kwargs, rounds=rounds, iterations=1)


def test_design(benchmark: Any) -> None:
    result = _once(benchmark, cd.design, str(UNIT_SCALE), rounds=2)
    assert result.design is not None


def test_check(benchmark: Any, unit_design: Any) -> None:
    report = _once(benchmark, cd.check, unit_design.design, rounds=2)
    assert math.isfinite(report.to_dict()["mu_rel_err"])


def test_simulate(benchmark: Any, unit_design: Any) -> None:
    result = _once(benchmark, cd.simulate, unit_design, t_end=20.0, samples=201, rounds=3)
    assert math.isfinite(result.to_dict()["I4_rel_drift"])


def test_frontier_point(benchmark: Any) -> None:
    result = _once(benchmark, cd.frontier)  # the embedded default scene (it has a [medium])
    assert result.to_dict()["s_max"] > 0.0


def test_testbed(benchmark: Any) -> None:
    result = _once(benchmark, cd.testbed, None, t_end_s=5.0, seeds=2)
    assert "verdict" in result.to_dict()


def test_bifurcation(benchmark: Any) -> None:
    diagram = _once(benchmark, cd.bifurcation, str(UNIT_SCALE))
    assert diagram.to_dict()


def test_case_flow_through_the_integrator_service(benchmark: Any) -> None:
    """The flow counting's trajectories of a case (heyoka on its sympy equations; the first
    call, outside the timing, compiles)."""
    F = CaseMomentumMap(read_case(KOWALEVSKI_CASE))
    rng = np.random.default_rng(1)
    gamma = rng.standard_normal((8, 3))
    starts = np.hstack(
        [0.5 * rng.standard_normal((8, 3)), gamma / np.linalg.norm(gamma, axis=1)[:, None]]
    )
    case_trajectories(F, starts, 1.0, 11)
    states = _once(benchmark, case_trajectories, F, starts, 20.0, 201, rounds=5)
    values = F.values(states.reshape(-1, 6)).reshape(8, 201, 4)
    assert np.abs(values - values[:, :1]).max() < 1e-10
