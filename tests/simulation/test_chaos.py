"""Poincare atlas and the fast Lyapunov indicator."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.simulation import chaos, taylor
from chargedesign.simulation.system import Body, RigidBodySystem

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
ENERGY = 1.3338772

pytestmark = pytest.mark.skipif(not taylor.available(), reason="heyoka is not installed")


def _system() -> RigidBodySystem:
    return RigidBodySystem(Body(parameters=PARAMS), ["theorem"])


def test_section_starts_lie_on_the_energy_and_level() -> None:
    system = _system()
    for level in (0.0, 0.5):
        starts = chaos.section_starts(system, ENERGY, level, 5)
        integrals = system.integrals(starts)
        assert np.max(np.abs(integrals[:, 0] - ENERGY)) <= 1e-13
        assert np.max(np.abs(integrals[:, 2] - level)) <= 1e-13


def test_atlas_records_sections_without_stopping_orbits(tmp_path: Path) -> None:
    atlas = chaos.poincare_atlas(_system(), orbits=4, t_end=40.0)
    assert atlas.levels == (0.0, 0.5) and len(atlas.points) == 2
    for orbits in atlas.points:
        assert len(orbits) == 4
        assert all(len(p) >= 2 for p in orbits)  # every orbit crosses several times
        for pts in orbits:
            assert np.max(np.abs(pts[:, 6])) <= 1e-13  # on gamma3 = 0
    atlas.write_csv(tmp_path / "atlas.csv")
    header = (tmp_path / "atlas.csv").read_text().splitlines()[0]
    assert header == "level,orbit,t,p,q,r,gamma1,gamma2,gamma3,phi"
    from matplotlib.figure import Figure

    fig = Figure()
    axes = fig.subplots(1, 2)
    assert atlas.plot(axes) is fig


def test_fli_separates_a_torus_from_a_chaotic_orbit() -> None:
    system = _system()
    regular = chaos.section_state(system, 1.0, 0.3, ENERGY, 0.0, 1.0)
    chaotic = chaos.section_state(system, 1.0, 0.3, ENERGY, 0.5, 1.0)
    assert regular is not None and chaotic is not None
    fli = chaos.fast_lyapunov_indicator(system, np.array([regular, chaotic]), 200.0)
    # measured 5.3 (log t growth on the torus) against 31 (exponential growth)
    assert fli[0] <= 8.0
    assert fli[1] >= 2.0 * fli[0]


def _shadow_lyapunov(system: RigidBodySystem, y0: np.ndarray, t_end: int) -> np.ndarray:
    """Benettin by finite differences: two DOP853 trajectories 1e-8 apart, renormalised every
    second (no variational equations)."""
    import math

    from scipy.integrate import solve_ivp

    f = system.rhs_function(1)
    x, v, total, out = y0.copy(), chaos.TANGENT_START.copy(), 0.0, []
    for k in range(1, t_end + 1):
        ends = [
            solve_ivp(f, (k - 1, k), start, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
            for start in (x, x + 1e-8 * v)
        ]
        d = (ends[1] - ends[0]) / 1e-8
        total += math.log(np.linalg.norm(d))
        v, x = d / np.linalg.norm(d), ends[0]
        out.append(total / k)
    return np.array(out)


def test_lyapunov_exponent_agrees_with_shadow_orbits_and_separates_torus_from_chaos() -> None:
    system = _system()
    regular = chaos.section_state(system, 1.0, 0.3, ENERGY, 0.0, 1.0)
    chaotic = chaos.section_state(system, 1.0, 0.3, ENERGY, 0.5, 1.0)
    assert regular is not None and chaotic is not None
    times, estimates = chaos.lyapunov_exponent(system, np.array([regular, chaotic]), 200.0)
    assert times[0] == 1.0 and times[-1] == 200.0 and estimates.shape == (2, 200)
    for row, start in zip(estimates, (regular, chaotic), strict=True):
        shadow = _shadow_lyapunov(system, start, 200)
        np.testing.assert_allclose(row[:100], shadow[:100], rtol=1e-5)
        np.testing.assert_allclose(row[-1], shadow[-1], rtol=0.05)
    # measured 0.0257 on the torus (falling like log t / t), 0.152 off the level
    assert estimates[0, -1] < 0.04 and estimates[0, -1] < 0.7 * estimates[0, 99]
    assert estimates[1, -1] > 0.1


def test_lyapunov_exponent_refuses_bad_durations() -> None:
    system = _system()
    start = chaos.section_state(system, 1.0, 0.3, ENERGY, 0.0, 1.0)
    with pytest.raises(InputError, match=r"^interval: expected a duration of at most t_end"):
        chaos.lyapunov_exponent(system, start, 10.0, interval=20.0)
    with pytest.raises(InputError, match=r"^t_end: expected a finite number"):
        chaos.lyapunov_exponent(system, start, float("nan"))
    with pytest.raises(InputError, match=r"^interval: expected a number > 0"):
        chaos.lyapunov_exponent(system, start, 10.0, interval=0.0)
