"""Simulation scenes, the theorem's reduced model, events, integrators, outputs and the CLI."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from unit_scene import UNIT_SCENE

from chargedesign.body import Design, write_design
from chargedesign.cli import main
from chargedesign.errors import InputError, SolverError
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.scene import scene_from_dict
from chargedesign.simulation import (
    Body,
    RigidBodySystem,
    quaternion_gamma,
    quaternion_rotation,
    simulate,
    simulate_batch,
)

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
SINGULAR = PARAMS.replace(rho=0.2)
START = {"gamma": [0.36, 0.48, 0.8], "p": 0.6, "q": -0.4}


def test_default_scene_simulates_its_designed_body() -> None:
    result = simulate(UNIT_SCENE, t_end=3.0)
    summary = result.summary()
    assert list(summary)[:3] == ["I4_rel_drift", "I3_max", "effects"]
    assert summary["effects"] == ["lorentz", "electric", "magnetization", "gravity"]
    assert summary["body"]["designed_from_scene"] is True
    assert summary["level"] == "I3=0"
    assert summary["I3_max"] <= 1e-10
    assert result.completed and result.times[-1] == 3.0
    # the theorem effect alone is the reduced model of the same scene (nothing designed)
    theorem = simulate(UNIT_SCENE, t_end=3.0, effects=["theorem"]).summary()
    assert theorem["effects"] == ["theorem"]
    assert theorem["body"]["designed_from_scene"] is False
    assert theorem["level"] == "I3=0" and theorem["I3_max"] <= 1e-10


def test_reduced_model_matches_the_derived_equations() -> None:
    system = RigidBodySystem(Body(SINGULAR), ["theorem"])
    rng = np.random.default_rng(1)
    quats = rng.normal(size=(4, 4))
    omega = rng.normal(size=(4, 3))
    d = system.derivatives(np.hstack([omega, quats]))
    gamma = quaternion_gamma(quats)
    expected = evaluators.rhs(np.hstack([omega, gamma]), SINGULAR)
    assert np.max(np.abs(d[:, :3] - expected[:, :3])) <= 1e-12 * np.max(np.abs(expected))
    # gamma' from the quaternion kinematics, by central differences along quaternion'
    h = 1e-6
    dgamma = (quaternion_gamma(quats + h * d[:, 3:]) - quaternion_gamma(quats - h * d[:, 3:])) / (
        2 * h
    )
    assert np.max(np.abs(dgamma - expected[:, 3:])) <= 1e-8
    # the single-state hot path is the same function
    fun = system.rhs_function(1)
    for k in range(4):
        y = np.concatenate([omega[k], quats[k]])
        assert np.max(np.abs(fun(0.0, y) - d[k])) <= 1e-13 * np.max(np.abs(d[k]))


def test_theorem_i4_conserved_on_the_level_only() -> None:
    kw = {"t_end": 20.0, "rtol": 1e-12, "atol": 1e-12}
    on = simulate(PARAMS, initial={**START, "level": "I3=0"}, **kw).summary()
    off = simulate(PARAMS, initial={**START, "level": "I3=0.5"}, **kw).summary()
    # off the level I4 is no integral: no number unless asked for
    assert off["I4_rel_drift"] is None and "off the level" in off["I4_reason"]
    off = simulate(PARAMS, initial={**START, "level": "I3=0.5"}, monitors=["I4"], **kw).summary()
    assert on["I4_rel_drift"] <= 1e-10
    assert off["I4_rel_drift"] >= 1e-2
    for s in (on, off):
        assert s["I1_rel_drift"] <= 1e-10
        assert s["I3_max_dev"] <= 1e-10
        assert s["I2_max_dev"] <= 1e-14


def test_singular_plane_is_a_terminal_event() -> None:
    # with rho > 0 the potential pulls the body into the plane gamma3 = 0
    result = simulate(SINGULAR, t_end=50.0, initial={"gamma": [0.6, 0.0, 0.8], "omega": [0, 0, 0]})
    assert not result.completed
    (event,) = result.events
    assert event["kind"] == "singular_plane" and event["terminal"]
    assert abs(abs(event["gamma3"]) - 0.01) <= 1e-8
    assert result.times[-1] == event["t"] < 50.0
    assert np.all(np.abs(result.gamma[:, 2]) >= 0.01 - 1e-8)
    assert np.all(np.isfinite(result.integrals))
    assert any("singular plane" in n for n in result.notes)
    summary = result.summary()
    assert summary["events"][0]["kind"] == "singular_plane" and not summary["completed"]


def test_singular_start_is_refused() -> None:
    with pytest.raises(InputError, match=r"initial\.gamma"):
        simulate(SINGULAR, t_end=1.0, initial={"gamma": [1.0, 0.0, 0.005], "omega": [0, 0, 0]})


def test_regular_parameters_cross_the_plane() -> None:
    result = simulate(PARAMS, t_end=5.0, initial={"gamma": [0.6, 0.0, 0.8], "omega": [0, 0, 3]})
    assert result.completed and not result.events


def test_gauss_legendre_conserves_the_quaternion_norm() -> None:
    result = simulate(
        PARAMS, t_end=5.0, method="gauss-legendre", step=0.02, initial={**START, "level": "I3=0"}
    )
    s = result.summary()
    assert s["quaternion_norm_max_dev"] <= 1e-14
    assert s["I4_rel_drift"] <= 1e-8 and s["I3_max"] <= 1e-9
    assert s["steps"] == 250


def test_gauss_legendre_reports_failure_near_the_plane() -> None:
    with pytest.raises(SolverError, match="gauss-legendre"):
        simulate(
            SINGULAR,
            t_end=5.0,
            method="gauss-legendre",
            step=0.01,
            initial={"gamma": [0.6, 0.0, 0.8], "omega": [0, 0, 0]},
        )


def test_solver_failure_raises(monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib
    from types import SimpleNamespace

    # the package's `integrate` attribute is the function: take the module itself
    integrate_module = importlib.import_module("chargedesign.simulation.integrate")

    def failing(*args: object, **kwargs: object) -> SimpleNamespace:
        return SimpleNamespace(success=False, message="Required step size is too small", t=[0.5])

    monkeypatch.setattr(integrate_module, "solve_ivp", failing)
    with pytest.raises(SolverError, match=r"DOP853 failed near t = 0\.5 s: Required step"):
        simulate(UNIT_SCENE, t_end=1.0, method="DOP853")


def test_batch_equals_separate_runs() -> None:
    states = np.array(
        [[0.6, -0.4, 0.3, 0.36, 0.48, 0.8], [0.1, 0.2, -0.5, 0.0, 0.6, 0.8], [1, 0, 0, 0, 0, 1]]
    )
    kw = {"t_end": 3.0, "rtol": 1e-12, "atol": 1e-12}
    batch = simulate_batch(PARAMS, states, **kw)
    assert len(batch) == 3
    for k, res in enumerate(batch):
        alone = simulate(PARAMS, initial=states[k], **kw)
        assert np.max(np.abs(res.omega[-1] - alone.omega[-1])) <= 1e-9
        assert np.max(np.abs(res.gamma[0] - states[k, 3:] / np.linalg.norm(states[k, 3:]))) <= 1e-15


def test_progress_is_reported() -> None:
    seen: list[float] = []
    simulate(UNIT_SCENE, t_end=2.0, progress=seen.append)
    assert seen[-1] == 1.0 and seen == sorted(seen) and len(seen) >= 3


def test_rotation_and_gamma_agree() -> None:
    result = simulate(UNIT_SCENE, t_end=2.0, initial={**START, "level": "I3=0", "precession": 0.7})
    R = result.rotation
    assert np.max(np.abs(np.einsum("tji,tjk->tik", R, R) - np.eye(3))) <= 1e-14
    assert np.max(np.abs(R[:, 2, :] - result.gamma)) <= 1e-15
    assert np.max(np.abs(R - quaternion_rotation(result.quaternion))) == 0.0


def _charge_design(**fields: tuple[float, ...]) -> Design:
    rng = np.random.default_rng(4)
    return Design(
        parameters=PARAMS,
        fields=dict(fields),
        charge_positions=rng.uniform(-1, 1, (5, 3)),
        charge_values=rng.normal(size=5),
    )


def test_effects_without_a_source_are_skipped() -> None:
    design = _charge_design(magnetic=(1.0, 1.0), electric=(0.0, 0.0))
    result = simulate(
        design, t_end=0.5, effects=["lorentz", "electric", "gravity", "magnetization"]
    )
    assert result.effects == ["lorentz"]
    notes = " ".join(result.notes)
    assert "electric: skipped, the electric field is zero" in notes
    assert "gravity: skipped, the body has no masses" in notes
    assert "magnetization: skipped, the body has no dipoles" in notes
    default = simulate(design, t_end=0.5)
    assert default.effects == ["lorentz"]


def test_level_of_a_body_uses_its_physical_momentum() -> None:
    design = _charge_design(magnetic=(1.0, 1.0))
    result = simulate(design, t_end=0.5, initial={**START, "level": "I3=0.25"})
    system = RigidBodySystem(Body.from_design(design), ["lorentz"])
    state = np.concatenate([result.omega[0], result.quaternion[0]])[None]
    assert abs(system.integrals(state, route="direct")[0, 2] - 0.25) <= 1e-14
    assert abs(result.integrals[0, 2] - 0.25) <= 1e-14


@pytest.mark.parametrize(
    ("tables", "key"),
    [
        ({"simulation": {"tend": 1.0}}, "simulation.tend"),
        ({"simulation": {"rtol": -1.0}}, "simulation.rtol"),
        ({"simulation": {"t_end": "long"}}, "simulation.t_end"),
        ({"simulation": {"method": "euler"}}, "simulation.method"),
        ({"simulation": {"effects": ["magic"]}}, "simulation.effects"),
        ({"simulation": {"effects": "lorentz"}}, "simulation.effects"),
        ({"simulation": {"route": "fast"}}, "simulation.route"),
        ({"simulation": {"samples": 1}}, "simulation.samples"),
        ({"initial": {"omega": [0, 0, 1]}}, "initial"),
        ({"initial": {"gamma": [0, 0, 1], "level": "I4=0", "p": 0, "q": 0}}, "initial.level"),
        ({"initial": {"gamma": [0, 0, 1], "level": "I3=0", "p": 0}}, "'q'"),
        ({"initial": {"gamma": [0, 0, 1], "level": "I3=0", "omega": [0, 0, 1]}}, "initial"),
        ({"initial": {"gamma": [0, 0, 0], "omega": [0, 0, 1]}}, "initial.gamma"),
        ({"initial": {"gamma": [0, 1], "omega": [0, 0, 1]}}, "initial.gamma"),
        ({"initial": {"gamma": [0, 0, 1], "omega": [0, 0, 1], "spin": 1}}, "initial.spin"),
        ({"output": {"plot": "yes"}}, "output.plot"),
        ({"output": {"poincare_axes": ["p"]}}, "output.poincare_axes"),
        ({"output": {"folder": "x"}}, "output.folder"),
        ({"body": {"design": "no/such/design.json"}}, "no/such/design.json"),
        ({"body": {"charges": {"positions": [[0, 0, 1]], "values": [1, 2]}}}, "charges.values"),
        ({"body": {"masses": {"where": []}}}, "body.masses.where"),
    ],
)
def test_bad_scene_keys_give_one_line_errors(tables: dict, key: str) -> None:
    scene = scene_from_dict({"parameters": {"n": 0.7}, **tables}, "scene.toml")
    with pytest.raises(InputError) as info:
        simulate(scene, t_end=0.1)
    message = str(info.value)
    assert key in message and "\n" not in message


def test_scene_with_inline_body_and_design_path(tmp_path: Path) -> None:
    design = _charge_design(magnetic=(1.0, 0.5))
    write_design(design, tmp_path / "design.json")
    text = """
[parameters]
n = 0.7
[fields.electric]
legendre = [0.0, 1.0]
[body]
design = "design.json"
[initial]
gamma = [0.0, 0.6, 0.8]
omega = [0.1, 0.2, 0.3]
[simulation]
t_end = 0.5
effects = ["lorentz", "electric"]
"""
    (tmp_path / "scene.toml").write_text(text)
    result = simulate(str(tmp_path / "scene.toml"))
    assert result.effects == ["lorentz", "electric"]  # the scene's electric field was added
    assert np.allclose(result.omega[0], [0.1, 0.2, 0.3], rtol=0, atol=0)
    inline = scene_from_dict(
        {
            "fields": {"gravity": {"legendre": [9.81]}},
            # a bob above O and a ring making A = B = 2C; no [parameters]: C from the masses
            "body": {
                "masses": {
                    "positions": [
                        [0, 0, 0.5],
                        [0.5, 0, 0],
                        [-0.5, 0, 0],
                        [0, 0.5, 0],
                        [0, -0.5, 0],
                    ],
                    "values": [1.0, 1 / 6, 1 / 6, 1 / 6, 1 / 6],
                }
            },
            "initial": {"gamma": [0.6, 0.0, 0.8], "omega": [0, 0, 0]},
            "simulation": {"t_end": 0.5},
        }
    )
    result = simulate(inline)
    assert result.effects == ["gravity"]
    assert result.omega[-1, 1] != 0.0  # the pendulum swings about body y


def test_outputs_are_written(tmp_path: Path) -> None:
    result = simulate(UNIT_SCENE, t_end=10.0, poincare="gamma1")
    files = result.write(tmp_path / "run")
    names = sorted(p.name for p in files)
    assert names == sorted(
        ["trajectory.npz", "trajectory.csv", "integrals.png", "poincare.png", "summary.json"]
    )
    with np.load(tmp_path / "run" / "trajectory.npz") as data:
        assert {"t", "omega", "gamma", "rotation", "integrals"} <= set(data.files)
        assert data["rotation"].shape == (len(data["t"]), 3, 3)
        assert np.array_equal(data["integrals"], result.integrals)
    with open(tmp_path / "run" / "trajectory.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:7] == ["t", "p", "q", "r", "gamma1", "gamma2", "gamma3"]
    assert len(rows) == len(result.times) + 1
    assert float(rows[-1][0]) == result.times[-1]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert list(summary)[:3] == ["I4_rel_drift", "I3_max", "effects"]
    assert (tmp_path / "run" / "integrals.png").read_bytes()[:4] == b"\x89PNG"
    # Poincare points lie on the section gamma1 = 0, crossing upwards
    assert result.poincare is not None and len(result.poincare) >= 1
    assert np.max(np.abs(result.poincare[:, 4])) <= 1e-9


def test_cli_json_keys(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", str(UNIT_SCENE), "--t-end", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out)[:3] == ["I4_rel_drift", "I3_max", "effects"]
    for key in ("I1_rel_drift", "I2_max_dev", "steps", "seconds", "events", "notes", "body"):
        assert key in out
    assert out["effects"] == ["lorentz", "electric", "magnetization", "gravity"]


def test_cli_design_file_and_outputs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write_design(_charge_design(magnetic=(1.0, 0.5)), tmp_path / "d.json")
    code = main(
        ["simulate", str(tmp_path / "d.json"), "--t-end", "1", "--out", str(tmp_path / "o")]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "simulated: lorentz" in text and "I4 relative drift" in text
    assert (tmp_path / "o" / "summary.json").is_file()
    assert (tmp_path / "o" / "trajectory.npz").is_file()
    code = main(["simulate", str(tmp_path / "d.json"), "--t-end", "1", "--effects", "theorem"])
    assert code == 0 and "simulated: theorem" in capsys.readouterr().out


def test_cli_failures_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", str(tmp_path / "missing.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("chargedesign simulate: error:") and "\n" not in err
    bad = tmp_path / "bad.toml"
    bad.write_text("[simulation]\nrtol = 0\n")
    assert main(["simulate", str(bad)]) == 2
    assert "simulation.rtol" in capsys.readouterr().err
    assert main(["simulate", str(UNIT_SCENE), "--t-end", "-1"]) == 2
