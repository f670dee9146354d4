"""Ensembles (batch integrators) against single runs; section events; state-set validation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.scene import load_scene
from chargedesign.scene.states import load_states, parse_states
from chargedesign.simulation import chaos, simulate, taylor
from chargedesign.simulation.ensemble import simulate_ensemble
from chargedesign.simulation.system import Body, RigidBodySystem, quaternion_gamma

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
ENERGY = 1.3338772  # the default start's energy (J)

needs_heyoka = pytest.mark.skipif(not taylor.available(), reason="heyoka is not installed")


def _system(params: Parameters = PARAMS) -> RigidBodySystem:
    return RigidBodySystem(Body(parameters=params), ["theorem"])


@needs_heyoka
def test_batch_lanes_equal_single_runs() -> None:
    system = _system()
    starts = chaos.section_starts(system, ENERGY, 0.0, 6, seed=2)
    grid = np.linspace(0.0, 20.0, 5)
    ens = taylor.propagate_many(system, starts, grid, batch=4, threads=2)
    assert ens.states.shape == (6, 5, 7) and not np.any(ens.stopped)
    for i in range(6):
        single = taylor.integrate_taylor(system, starts[i : i + 1], 20.0, samples=5)
        assert np.max(np.abs(single.states[0] - ens.states[i])) <= 1e-12


@needs_heyoka
def test_ensemble_of_bodies_of_one_structure() -> None:
    bodies = [_system(PARAMS.replace(kappa=k)) for k in (0.9, 0.5, 0.1)]
    starts = chaos.section_starts(bodies[0], ENERGY, 0.0, 3, seed=1)
    grid = np.array([0.0, 10.0])
    ens = taylor.propagate_many(bodies, starts, grid)
    for system, y0, row in zip(bodies, starts, ens.states, strict=True):
        single = taylor.integrate_taylor(system, y0[None], 10.0, samples=2)
        assert np.max(np.abs(single.states[0, -1] - row[-1])) <= 1e-12


@needs_heyoka
def test_simulate_ensemble_from_a_scene_file(tmp_path: Path) -> None:
    states = [[0.6, -0.4, 0.1, 0.36, 0.48, 0.8], [0.1, 0.2, 0.3, 0.0, 0.6, 0.8]]
    np.save(tmp_path / "states.npy", np.array(states))
    (tmp_path / "scene.toml").write_text(
        "[parameters]\nC = 1.0\nc = 0.3\nd = -0.4\nn = 0.7\nK = 0.5\nkappa = 0.9\n"
        '[initial]\nfile = "states.npy"\n[simulation]\nt_end = 5.0\nsamples = 3\n'
    )
    result = simulate_ensemble(str(tmp_path / "scene.toml"))
    assert result.states.shape == (2, 3, 7)
    s = result.summary()
    assert s["trajectories"] == 2 and s["I4_rel_drift"] is None  # neither starts on I3 = 0
    assert "2 of 2 trajectories: I4 is no integral off the level I3 = 0" == s["I4_reason"]
    assert s["energy_max_drift"] <= 1e-13
    single = simulate(
        PARAMS, t_end=5.0, samples=3, initial={"omega": states[1][:3], "gamma": states[1][3:]}
    )
    assert np.max(np.abs(single.omega[-1] - result.states[1, -1, :3])) <= 1e-12
    files = result.write(tmp_path / "out")
    assert [f.name for f in files] == ["ensemble.csv", "summary.json"]
    assert len((tmp_path / "out" / "ensemble.csv").read_text().splitlines()) == 3


@needs_heyoka
def test_section_events_are_located_to_1e_12_in_time() -> None:
    system = _system()
    y0 = chaos.section_starts(system, ENERGY, 0.0, 1, seed=4)
    # start just after a crossing so that every event is a later upward crossing
    result = simulate(
        PARAMS,
        t_end=30.0,
        initial=np.concatenate([y0[0, :3], quaternion_gamma(y0[:, 3:])[0]]),
        poincare="gamma3",
    )
    points = result.poincare
    assert points is not None and len(points) >= 2
    omega, gamma = points[:, 1:4], points[:, 4:7]
    rate = gamma[:, 0] * omega[:, 1] - gamma[:, 1] * omega[:, 0]  # gamma3' > 0 upwards
    assert np.all(rate > 0.0)
    # |gamma3| / gamma3' bounds the error in the event time
    assert np.max(np.abs(gamma[:, 2]) / rate) <= 1e-12
    # an independent run stopped at each event time finds gamma3 = 0 there too
    for t_event in points[:3, 0]:
        start = result.omega[0].tolist() + result.gamma[0].tolist()
        again = simulate(PARAMS, t_end=float(t_event), samples=2, initial=start)
        g, w = again.gamma[-1], again.omega[-1]
        assert abs(g[2]) / (g[0] * w[1] - g[1] * w[0]) <= 1e-12


def test_state_sets_are_validated(tmp_path: Path) -> None:
    good = parse_states([[0, 0, 1, 0, 0, 1], [0.1, 0.2, 0.3, 1, 0, 0]])
    assert good.shape == (2, 6)
    cases = [
        ([[0, 0, 1, 0, 0, True]], r"initial\.states\[0\]\[5\]: expected a number"),
        ([[0, 0, 1, 0, 0, float("nan")]], r"initial\.states\[0\]\[5\]: expected a finite"),
        ([[0, 0, 1, 0, 0]], r"initial\.states\[0\]: expected 6 numbers"),
        ([[0, 0, 1, 0, 0, 0]], r"initial\.states\[0\]: expected a non-zero gamma"),
        ([], r"initial\.states: expected a non-empty list"),
        ([[0, 0, 1, 0, 0, "1"]], r"initial\.states\[0\]\[5\]: expected a number"),
    ]
    for value, pattern in cases:
        with pytest.raises(InputError, match=pattern):
            parse_states(value)
    (tmp_path / "s.csv").write_text("p,q,r,gamma1,gamma2,gamma3\n0,0,1,0,0,1\n0.1,0,0,1,0,0\n")
    assert load_states(tmp_path / "s.csv").shape == (2, 6)
    (tmp_path / "bad.csv").write_text("0,0,1,0,0,true\n")
    with pytest.raises(InputError, match=r"initial\.file row 1 column 6: expected a number"):
        load_states(tmp_path / "bad.csv")
    np.save(tmp_path / "b.npy", np.ones((2, 6), dtype=bool))
    with pytest.raises(InputError, match=r"initial\.file"):
        load_states(tmp_path / "b.npy")
    (tmp_path / "x.txt").write_text("0,0,1,0,0,1\n")
    with pytest.raises(InputError, match=r"initial\.file: expected a \.csv or \.npy"):
        load_states(tmp_path / "x.txt")
    (tmp_path / "scene.toml").write_text("[initial]\nstates = [[0, 0, 1, 0, 0, 1]]\np = 0.1\n")
    with pytest.raises(InputError, match=r"initial\.p: not used with a set of states"):
        simulate(load_scene(tmp_path / "scene.toml"))


@needs_heyoka
def test_terminal_event_stops_only_its_own_trajectory() -> None:
    system = _system(PARAMS.replace(rho=0.2))
    states = [[0, 0, 0, 0.6, 0, 0.8], [0.1, 0.2, 0.3, 0.1, 0.2, 0.9], [0, 0, 0, 0.3, 0, 0.95]]
    from chargedesign.simulation.api import initial_state

    y0 = np.array([initial_state(system, s)[0] for s in states])
    ens = taylor.propagate_many(system, y0, np.linspace(0.0, 50.0, 6), gamma3_min=0.01)
    assert np.all(ens.stopped)
    for i in range(3):
        single = taylor.integrate_taylor(system, y0[i : i + 1], 50.0, samples=6, gamma3_min=0.01)
        assert abs(single.events[0]["t"] - ens.t_stop[i]) <= 1e-12
    assert len(set(np.round(ens.t_stop, 6))) == 3  # each at its own time
