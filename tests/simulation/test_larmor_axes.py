"""A frame body simulated from its own elements and read in turning axes (Larmor's theorem).

The body realises the theorem with n = 0; read in axes turning at n about Z its motion is the
theorem's with n. Checked by independent routes: the reduced models with n = 0 and with n
(heyoka), the charges body that realises n with its own charges, and I4 at the wrong rate.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from unit_scene import UNIT_SCENE, unit_design

from chargedesign.body import Design, write_design
from chargedesign.cli import main
from chargedesign.errors import InputError
from chargedesign.larmor import LarmorReading, from_turning_axes, to_turning_axes
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.scene import scene_from_dict
from chargedesign.simulation import simulate, simulate_ensemble

RATE = 0.7
START = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 0.6, "q": -0.4}


@pytest.fixture(scope="module")
def frame() -> Design:
    """The unit-scale body designed at n = 0, recorded as a frame body turning at 0.7."""
    design = unit_design(0.0)
    design.parameters = dataclasses.replace(design.parameters, n=RATE)
    design.larmor = LarmorReading("frame", RATE)
    return design


@pytest.fixture(scope="module")
def charges() -> Design:
    """The same scene at n = 0.7: the paper's (p6) charges realise n."""
    return unit_design(RATE)


def _i4(omega: np.ndarray, gamma: np.ndarray, params: Parameters) -> np.ndarray:
    return np.asarray(evaluators.integrals(np.hstack([omega, gamma]), params), dtype=float)[:, 3]


def test_the_n_zero_reduced_model_in_turning_axes_is_the_n_model() -> None:
    """heyoka: the n = 0 trajectory mapped by omega0 - n gamma against the n-model's own."""
    params = Parameters(C=1.0, c=0.3, d=-0.4, n=RATE, K=0.5, kappa=0.9)
    gamma0 = np.array(START["gamma"])
    omega0 = np.array([0.6, -0.4, 0.3])
    zero = simulate(
        dataclasses.replace(params, n=0.0),
        effects=["theorem"],
        initial=np.concatenate([omega0, gamma0]),
        t_end=40.0,
        samples=401,
    )
    with_n = simulate(
        params,
        effects=["theorem"],
        initial=to_turning_axes(np.concatenate([omega0, gamma0]), RATE),
        t_end=40.0,
        samples=401,
    )
    # a few periods: gamma3 turns over several times
    assert np.count_nonzero(np.diff(np.sign(zero.gamma[:, 0]))) >= 4
    mapped = to_turning_axes(np.hstack([zero.omega, zero.gamma]), RATE)
    own = np.hstack([with_n.omega, with_n.gamma])
    assert np.max(np.abs(mapped - own)) < 1e-12


def test_a_frame_body_conserves_i4_with_n_in_turning_axes(frame: Design) -> None:
    turning = simulate(frame, initial=START, t_end=50.0, samples=501)
    assert turning.axes == "turning" and turning.axes_rate == RATE
    assert turning.parameters.n == RATE  # the integrals are the theorem's with n
    summary = turning.summary()
    assert summary["axes"] == "turning" and summary["larmor"] == {"reading": "frame", "rate": RATE}
    assert summary["I4_rel_drift"] < 1e-12  # measured 1.0e-14
    assert summary["I3_max"] < 1e-12 and summary["I1_rel_drift"] < 1e-12
    # the start is given in the turning axes
    np.testing.assert_allclose(turning.omega[0, :2], [0.6, -0.4], rtol=0, atol=1e-15)

    # the same motion as integrated (the start given in inertial axes: omega + n gamma)
    start0 = from_turning_axes(np.concatenate([turning.omega[0], turning.gamma[0]]), RATE)
    inertial = simulate(frame, initial=start0, t_end=50.0, samples=501, axes="inertial")
    assert inertial.axes == "inertial" and inertial.parameters.n == 0.0
    assert inertial.summary()["I4_rel_drift"] < 1e-12  # the body's own I4, n = 0
    # the same motion: omega differs by n gamma, gamma is the same
    # (two integrations from starts equal to rounding: measured 1.1e-14)
    np.testing.assert_allclose(inertial.gamma, turning.gamma, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        inertial.omega - RATE * inertial.gamma, turning.omega, rtol=0, atol=1e-12
    )
    # read at the wrong rate (inertial states, I4 with n) I4 drifts by O(1): measured 1.0
    wrong = _i4(inertial.omega, inertial.gamma, turning.parameters)
    assert np.max(np.abs(wrong - wrong[0])) / abs(wrong[0]) > 0.1


def test_the_frame_body_in_turning_axes_is_the_charges_body(frame: Design, charges: Design) -> None:
    """Two designs, two readings of n: the same motion (attitude included) on one start."""
    turning = simulate(frame, initial=START, t_end=50.0, samples=501)
    lorentz = simulate(charges, initial=START, t_end=50.0, samples=501)
    assert lorentz.axes == "inertial"
    assert lorentz.larmor == {"reading": "charges", "rate": RATE}  # the design writes it
    # measured 7e-14 (both bodies realise the theorem to ~1e-14, see check)
    assert np.max(np.abs(turning.omega - lorentz.omega)) < 1e-11
    assert np.max(np.abs(turning.gamma - lorentz.gamma)) < 1e-11
    assert np.max(np.abs(turning.rotation - lorentz.rotation)) < 1e-11
    np.testing.assert_allclose(turning.integrals[:, 3], lorentz.integrals[:, 3], rtol=1e-11)
    # I3 is the same in both readings; I1 up to V's additive constant
    np.testing.assert_allclose(turning.integrals[:, 2], lorentz.integrals[:, 2], atol=1e-11)
    shift = turning.integrals[:, 0] - lorentz.integrals[:, 0]
    assert np.ptp(shift) < 1e-11


def test_outputs_say_which_axes(frame: Design, tmp_path: Path) -> None:
    result = simulate(frame, initial=START, t_end=2.0, samples=11)
    result.write(tmp_path / "run", plot=False)
    with open(tmp_path / "run" / "trajectory.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:7] == ["t", "p", "q", "r", "gamma1", "gamma2", "gamma3"]
    assert rows[0][-1] == "axes_rate" and float(rows[1][-1]) == RATE
    with np.load(tmp_path / "run" / "trajectory.npz") as data:
        assert str(data["axes"]) == "turning" and float(data["axes_rate"]) == RATE
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["axes"] == "turning" and summary["axes_rate"] == RATE
    assert "axes: turning at n = 0.7" in str(result)


def test_an_ensemble_of_a_frame_body_is_read_in_turning_axes(frame: Design) -> None:
    states = [[0.6, -0.4, 0.2, 0.36, 0.48, 0.8], [0.3, 0.1, -0.2, 0.0, 0.6, 0.8]]
    ens = simulate_ensemble(frame, states=states, t_end=5.0, samples=51)
    np.testing.assert_allclose(ens.states[:, 0, :3], np.array(states)[:, :3], atol=1e-15)
    drift = [m["I3"]["drift"] for m in ens.monitors]
    assert max(drift) < 1e-12


def test_bad_axes_are_one_line(
    charges: Design, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "charges.json"
    write_design(charges, path)
    assert main(["simulate", str(path), "--axes", "sideways"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--axes" in err and "sideways" in err
    # a charges body has only the inertial reading: turning is refused, inertial accepted
    assert main(["simulate", str(path), "--axes", "turning", "--t-end", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "frame" in err
    assert main(["simulate", str(path), "--axes", "inertial", "--t-end", "1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["axes"] == "inertial"
    with pytest.raises(InputError, match=r"simulation\.axes"):
        data = tomllib.loads(UNIT_SCENE.read_text())
        data["simulation"] = {"axes": "spinning", "effects": ["theorem"]}
        simulate(scene_from_dict(data), t_end=1.0)
    with pytest.raises(InputError, match="axes: turning needs a frame body"):
        simulate(Parameters(C=1.0, n=RATE), effects=["theorem"], axes="turning", t_end=1.0)


def test_turning_integrals_are_the_theorems_with_n() -> None:
    """RigidBodySystem.integrals(rate=n) of the n = 0 reduced model, at turning-axes states,
    against the compiled evaluators of the theorem with n (no additive constant for V)."""
    from chargedesign.simulation.system import (
        Body,
        RigidBodySystem,
        attitude_from_gamma,
        rotation_quaternion,
    )

    params = Parameters(C=1.3, c=0.3, d=-0.4, n=RATE, K=0.5, kappa=0.9, lam=0.2, rho=0.05)
    system = RigidBodySystem(Body(parameters=dataclasses.replace(params, n=0.0)), ["theorem"])
    rng = np.random.default_rng(7)
    gamma = rng.normal(size=(40, 3)) + np.array([0.0, 0.0, 2.0])
    gamma /= np.linalg.norm(gamma, axis=1)[:, None]
    omega = rng.normal(size=(40, 3))
    quats = np.array([rotation_quaternion(attitude_from_gamma(g, 0.3)) for g in gamma])
    ours = system.integrals(np.hstack([omega, quats]), rate=RATE)
    theirs = np.asarray(evaluators.integrals(np.hstack([omega, gamma]), params), dtype=float)
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)


def test_a_physical_frame_body_in_turning_axes() -> None:
    """The small buildable body of tests/physical (air, 5 cm) designed at n = 0."""
    from chargedesign.checker import check_design
    from chargedesign.designer import design_from_scene

    data = tomllib.loads((Path(__file__).parents[1] / "physical" / "small.toml").read_text())
    rate = data["parameters"]["n"]
    data["parameters"]["n"] = 0.0
    design = design_from_scene(scene_from_dict(data), frontier=False).design
    design.parameters = dataclasses.replace(design.parameters, n=rate)
    design.larmor = LarmorReading("frame", rate)
    assert check_design(design).passed
    period = 2.0 * np.pi / np.sqrt(design.parameters.kappa)
    start = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 4.2 * rate, "q": -2.8 * rate}
    turning = simulate(design, initial=start, t_end=20.0 * period, samples=2001)
    assert turning.axes == "turning"
    assert turning.summary()["I4_rel_drift"] < 1e-12  # measured 6.9e-15
    start0 = from_turning_axes(np.concatenate([turning.omega[0], turning.gamma[0]]), rate)
    inertial = simulate(design, initial=start0, t_end=20.0 * period, samples=2001, axes="inertial")
    wrong = _i4(inertial.omega, inertial.gamma, turning.parameters)
    assert np.max(np.abs(wrong - wrong[0])) / abs(wrong[0]) > 0.05  # measured 0.19


def test_a_frame_body_at_rate_zero_reads_the_same_in_both_axes(frame: Design) -> None:
    still = dataclasses.replace(
        frame,
        parameters=dataclasses.replace(frame.parameters, n=0.0),
        larmor=LarmorReading("frame", 0.0),
    )
    turning = simulate(still, initial=START, t_end=5.0, samples=51)
    inertial = simulate(still, initial=START, t_end=5.0, samples=51, axes="inertial")
    assert turning.axes == "turning" and turning.axes_rate == 0.0
    assert inertial.axes == "inertial"
    np.testing.assert_array_equal(turning.omega, inertial.omega)
    np.testing.assert_array_equal(turning.integrals, inertial.integrals)
