"""The testbed for a case of (ep) (issue 34 item 6): the wheels apply the case's torques.

Independent routes: the wheels' torque on a Kowalevski platform against the hand formula of
the weight's torque ``M g gamma x r_c`` (gamma up, the centre of mass r_c on the x axis,
``M g x_c = C a``) and the hand Euler equations of that heavy top; the case's F against the
hand Kowalevski integral; the noise-free closed loop against ``simulate`` of a body of
masses designed for the same case (a different model: masses in uniform gravity,
integrated by the simulation's own route); refusals in one line before any work.
"""

from __future__ import annotations

import json
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from case_tables import kowalevski_table

import chargedesign as cd
from chargedesign.airbearing.dynamics import Plant, case_model, flight_refusal
from chargedesign.airbearing.loop import LoopSettings, initial_state, run_loop
from chargedesign.cli import main
from chargedesign.params import Parameters
from chargedesign.scene.case_file import case_from_table, read_case

CASES = Path(str(resources.files("chargedesign").joinpath("data/cases")))

#: a Kowalevski top at testbed scale: C = 0.5 kg m^2, a = 0.1 1/s^2 (V = 0.05 gamma1 J)
C, A_COEF = 0.5, 0.1
CASE = kowalevski_table("kowalevski-testbed", C, A_COEF)
START = {"initial_gamma": [-1.0, 0.25, 0.3], "initial_p": 0.0, "initial_q": 0.0}
TINY = {
    "platform_mass_kg": 6.0,
    "platform_radius_m": 0.3,
    "ballast_material": "brass",
    "t_end_s": 0.4,
    "rate_Hz": 20.0,
    "seeds": 2,
    "requirement_rates_Hz": [20.0],
    "requirement_seeds": 1,
}


def _scene(tmp_path: Path, case: str = CASE, testbed: dict | None = None) -> Path:
    table = {**TINY, **START} if testbed is None else testbed
    lines = [f"{k} = {json.dumps(v)}" for k, v in table.items()]
    path = tmp_path / "case_testbed.toml"
    path.write_text(case + "\n[testbed]\n" + "\n".join(lines) + "\n", "utf-8")
    return path


def _states(count: int, seed: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    gamma = rng.standard_normal((count, 3))
    gamma /= np.linalg.norm(gamma, axis=1, keepdims=True)
    return rng.standard_normal((count, 3)), gamma, 0.1 * rng.standard_normal((count, 3))


def test_kowalevski_wheel_torque_is_the_weight_torque_by_hand() -> None:
    """J = I: the wheels' reaction ``-h'`` is the heavy top's weight torque plus ``omega x h``
    (the wheels' own gyroscopic term), for the catalogue's Kowalevski case (C = 1.5, a = 0.7)."""
    case = read_case(CASES / "kowalevski.toml")
    model = case_model(case)
    C_cat, a_cat = 1.5, 0.7
    inertia = np.diag([2 * C_cat, 2 * C_cat, C_cat])
    plant = Plant(Parameters(C=C_cat), inertia, inertia, model)
    omega, gamma, h = _states(50)
    h_dot = plant.command(np.hstack([omega, gamma, h]))
    Mg_rc = np.array([C_cat * a_cat, 0.0, 0.0])  # M g x_c = C a
    weight_torque = np.cross(gamma, Mg_rc)  # r_c x (-M g gamma)
    np.testing.assert_allclose(-h_dot - np.cross(omega, h), weight_torque, rtol=0, atol=1e-14)


def test_the_closed_loop_moves_a_platform_of_other_inertia_as_the_heavy_top() -> None:
    """The wheels supply what the platform's own inertia J does not: with J != I the
    platform's omega' under the command is the hand Euler equation of the heavy top,
    ``I^-1 (M g gamma x r_c - omega x I omega)``."""
    model = case_model(case_from_table(_table(CASE)))
    body = np.diag([2 * C, 2 * C, C])
    J = body + np.array([[0.3, 0.02, -0.01], [0.02, 0.25, 0.03], [-0.01, 0.03, 0.4]])
    plant = Plant(Parameters(C=C), J, J, model)
    omega, gamma, h = _states(40, seed=5)
    x = np.hstack([omega, gamma, h])
    rates = plant.ideal_rates(x)
    torque = np.cross(gamma, np.array([C * A_COEF, 0.0, 0.0]))
    euler = (torque - np.cross(omega, omega @ body)) / np.diag(body)
    np.testing.assert_allclose(rates[:, 0:3], euler, rtol=0, atol=1e-13)
    np.testing.assert_allclose(rates[:, 3:6], np.cross(gamma, omega), rtol=0, atol=1e-15)


def _table(text: str) -> dict:
    return tomllib.loads(text)["case"]


def test_the_monitored_integral_is_the_hand_kowalevski_F_and_I3() -> None:
    model = case_model(case_from_table(_table(CASE)))
    omega, gamma, _ = _states(30, seed=9)
    p, q, r = omega.T
    g1, g2, g3 = gamma.T
    I3, F = model.invariants(np.hstack([omega, gamma]))
    hand_F = (p**2 - q**2 - A_COEF * g1) ** 2 + (2 * p * q - A_COEF * g2) ** 2
    np.testing.assert_allclose(F, hand_F, rtol=1e-14, atol=1e-16)
    np.testing.assert_allclose(I3, 2 * C * (p * g1 + q * g2) + C * r * g3, rtol=1e-14)
    # the window's scaling: the motion s times faster and inertia m times larger reads F at
    # omega / s, I3 times m s
    s, m = 3.0, 0.4
    I3_s, F_s = model.scaled(s, m).invariants(np.hstack([s * omega, gamma]))
    np.testing.assert_allclose(F_s, hand_F, rtol=1e-13)
    np.testing.assert_allclose(I3_s, m * s * I3, rtol=1e-13)


def test_the_case_start_lies_on_the_level_of_a_conditional_case() -> None:
    """Sretensky's gyrostat is claimed on I3 = 0 only; a copy at level 3/10 with A = B = 2C
    keeps r solved from I3 = 3/10 (the hand I3 = 2C(p g1 + q g2) + C r g3 + l . gamma)."""
    text = CASE.replace('level = "general"', "level = 0.3").replace(
        'l = ["0", "0", "0"]', 'l = ["0", "0", "C*k"]'
    )
    text = text.replace("[case.parameters]", "[case.parameters]\nk = 0.2")
    model = case_model(case_from_table(_table(text)))
    x0 = initial_state(Parameters(C=C), np.array([0.2, -0.3, 0.9]), 0.1, -0.05, model)
    p, q, r, g1, g2, g3 = x0
    hand_I3 = 2 * C * (p * g1 + q * g2) + C * r * g3 + C * 0.2 * g3
    assert hand_I3 == pytest.approx(0.3, abs=1e-14)
    assert model.conditional and model.invariants(x0[None])[0][0] == pytest.approx(0, abs=1e-14)


def test_the_noise_free_loop_keeps_F_and_follows_simulate_of_a_body_of_masses(
    tmp_path: Path,
) -> None:
    """Reduced model flown by the loop against ``simulate`` of the same case designed as
    masses in uniform gravity (its own equations and integrator): 5 s, 50 Hz, predictive."""
    case = case_from_table(_table(CASE))
    model = case_model(case)
    body = np.diag([2 * C, 2 * C, C])
    plant = Plant(Parameters(C=C), body, body, model)
    x0 = initial_state(Parameters(C=C), np.array(START["initial_gamma"]), 0.0, 0.0, model)
    settings = LoopSettings(rate_Hz=50.0, delay_s=0.001, t_end_s=5.0, command="predictive")
    run = run_loop(plant, x0, settings, keep_states=True)
    assert run.I4_drift[0] <= 1e-6  # F's relative drift, the stated tolerance
    # the level kept (I3 = 0) to the sampled command's error, 4e-7 of |I omega| ~ 0.05 J s
    assert run.I3_max[0] <= 1e-7

    scene = tmp_path / "body.toml"
    g = x0[3:6]
    scene.write_text(
        CASE
        + '\n[body]\nshape = "ball"\nradius = 0.5\nspacing = 0.125\n'
        + f"\n[initial]\ngamma = {list(map(float, g))}\nomega = {list(map(float, x0[:3]))}\n",
        "utf-8",
    )
    sim = cd.simulate(str(scene), t_end=5.0, samples=251)
    assert sim.times[-1] == pytest.approx(5.0)
    loop_gamma = run.states[0, :, 3:6]
    loop_times = run.times
    assert loop_times[-1] == pytest.approx(5.0)
    # both sampled every 0.02 s
    np.testing.assert_allclose(sim.times, loop_times, atol=1e-12)
    np.testing.assert_allclose(sim.gamma, loop_gamma, rtol=0, atol=1e-6)
    np.testing.assert_allclose(sim.omega, run.states[0, :, 0:3], rtol=0, atol=1e-6)


@pytest.mark.parametrize(
    ("case_file", "message"),
    [
        ("goriachev_chaplygin.toml", "is not realisable by the platform"),
        ("lagrange.toml", "is not realisable by the platform"),
    ],
)
def test_a_case_of_another_inertia_is_refused_in_one_line(case_file: str, message: str) -> None:
    reason = flight_refusal(read_case(CASES / case_file))
    assert reason is not None and message in reason and "\n" not in reason


def test_a_singular_potential_is_refused_in_one_line() -> None:
    text = CASE.replace('V = "C*a*gamma1"', 'V = "C*a*(gamma1 + 1/gamma3**2)"')
    text = text.replace('integral = "(p**2', 'integral = "p + (p**2').replace(
        'level = "general"', "level = 0"
    )
    reason = flight_refusal(case_from_table(_table(text)))
    assert reason is not None and "singular on gamma3 = 0" in reason and "\n" not in reason


@pytest.mark.parametrize(
    ("testbed", "message"),
    [
        (TINY, "give initial_gamma, initial_p and initial_q"),
        ({**TINY, **START, "initial_gamma": [1.0, 0.2, 0.3]}, "deg of tilt"),
        ({**TINY, **START, "initial_gamma": [1.0, 0.2, 0.0]}, "gamma3 != 0"),
    ],
)
def test_the_command_refuses_a_case_it_cannot_fly_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], testbed: dict, message: str
) -> None:
    out = tmp_path / "out"
    code = main(["testbed", str(_scene(tmp_path, testbed=testbed)), "--out", str(out)])
    error = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and message in error[-1] and not out.exists()


def test_the_command_flies_a_case_and_says_which(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    assert main(["testbed", str(_scene(tmp_path)), "--out", str(out), "--quiet", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    data = json.loads((out / "testbed.json").read_text())
    assert data["case"]["name"] == "kowalevski-testbed" == printed["case"]["name"]
    assert data["case"]["monitored_integral"] == "F" and data["case"]["level"] == "general"
    assert data["case"]["inertia_kg_m2"] == [2 * C, 2 * C, C]
    # the contract's keys, as for the theorem
    assert {"verdict", "state_of_the_art", "bearing", "results", "window"} <= set(data)
    assert data["verdict"]["buildable"] in (True, False)
    np.testing.assert_allclose(
        data["inertia_total_kg_m2"], np.diag([2 * C, 2 * C, C]), rtol=0, atol=1e-12
    )
    assert data["results"]["predictive_noise_free"]["I4_relative_drift"] <= 1e-6
    assert data["window"]["recommended_recomputed"]["largest_law_error"] <= 1e-6
    report = (out / "report.md").read_text()
    assert "case kowalevski-testbed" in report
    assert not (out / "tilt_map.png").exists()  # a case has no tilt map yet: said in the report
    assert "tilt map" in report


def test_the_theorem_entered_as_a_case_is_flown_as_the_theorem() -> None:
    """The catalogue's Yehia-Elmandouh case file at the example testbed scene's parameters
    (lambda = rho = 0): the case route's wheel command, I3 and F equal the theorem's own
    route (compiled evaluators of the derived model, not the case file) at random states."""
    table = tomllib.loads((CASES / "yehia_elmandouh.toml").read_text())["case"]
    theorem = {"C": 0.5, "c": 0.3, "d": -0.4, "n": 0.21, "K": 0.15, "kappa": 0.081}
    table["parameters"] = {**theorem, "lambda": 0, "rho": 0}
    model = case_model(case_from_table(table))
    assert model.conditional and model.level == 0.0
    params = Parameters(**theorem)
    body = np.diag([1.0, 1.0, 0.5])
    J = body + np.diag([0.1, 0.2, 0.05])
    by_case, by_theorem = Plant(params, J, J, model), Plant(params, J, J)
    omega, gamma, h = _states(60, seed=11)
    x = np.hstack([omega, gamma, h])
    np.testing.assert_allclose(by_case.command(x), by_theorem.command(x), rtol=0, atol=1e-13)
    I3_case, F = by_case.invariants(x[:, 0:6])
    I3, I4 = by_theorem.invariants(x[:, 0:6])
    np.testing.assert_allclose(I3_case, I3, rtol=0, atol=1e-14)
    np.testing.assert_allclose(F, I4, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(
        by_case.reduced_rhs(x[:, 0:6]), by_theorem.reduced_rhs(x[:, 0:6]), rtol=0, atol=1e-13
    )


def test_the_kernel_takes_a_refused_case_as_a_callers_error() -> None:
    """The testbed's options refuse the case first (InputError); case_model given it anyway
    raises a plain ValueError with the same reason."""
    case = read_case(CASES / "lagrange.toml")
    with pytest.raises(ValueError, match="is not realisable by the platform") as error:
        case_model(case)
    assert type(error.value) is ValueError
