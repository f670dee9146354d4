"""`chargedesign testbed` and `cd.testbed`: the contract's testbed.json, the report, the
result protocol, the scene's [testbed] table and its schema (tiny settings)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

import chargedesign as cd
from chargedesign.airbearing.actuators import catalogue
from chargedesign.airbearing.run import default_testbed_scene
from chargedesign.cli import main
from chargedesign.physical.sources import rows
from chargedesign.scene.keys import table_schema
from chargedesign.scene.testbed import TestbedOptions
from chargedesign.schemas import schema

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "testbed.toml"
TINY = {
    "t_end_s": 0.4,
    "rate_Hz": 20.0,
    "seeds": 2,
    "requirement_rates_Hz": [20.0],
    "requirement_seeds": 1,
}


def _tiny_scene(tmp_path: Path) -> Path:
    text = EXAMPLE.read_text()
    data = tomllib.loads(text)
    lines = [f"{k} = {json.dumps(v)}" for k, v in {**data["testbed"], **TINY}.items()]
    head = text.split("\n[testbed]\n")[0]
    path = tmp_path / "tiny.toml"
    path.write_text(head + "\n[testbed]\n" + "\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("testbed")
    out = tmp / "out"
    assert main(["testbed", str(_tiny_scene(tmp)), "--out", str(out), "--quiet"]) == 0
    return out


def test_testbed_json_has_the_contract_keys(written: Path) -> None:
    data = json.loads((written / "testbed.json").read_text())
    assert set(data["parameters"]) >= {"C", "c", "d", "n", "K", "kappa"}
    assert np.shape(data["platform"]["inertia_kg_m2"]) == (3, 3)
    assert {"mass_kg", "com_m"} <= set(data["platform"])
    assert {"positions", "masses", "radii", "material"} <= set(data["ballast"])
    assert {"axes", "max_torque_N_m", "max_momentum_N_m_s"} <= set(data["wheels"])
    assert data["control"]["rate_Hz"] == 20.0 and "delay_s" in data["control"]
    assert {"gyro_arw_rad_per_sqrt_s", "gyro_bias_rad_per_s", "attitude_noise_rad"} <= set(
        data["sensors"]
    )
    assert {"imbalance_m", "drag_N_m_s"} <= set(data["disturbances"])
    C = data["parameters"]["C"]
    assert np.allclose(data["inertia_total_kg_m2"], np.diag([2 * C, 2 * C, C]), atol=1e-12)
    r = data["results"]
    assert len(r["initial_state"]) == 6 and r["t_end_s"] == 0.4
    assert (
        r["zoh_noise_free"]["I4_relative_drift"] > r["predictive_noise_free"]["I4_relative_drift"]
    )
    assert {"I4_relative_drift_median", "I4_relative_drift_p95"} <= set(r["nominal"])
    assert r["wheel_momentum_max_N_m_s"] > 0 and r["wheel_torque_max_N_m"] > 0
    assert r["wheel_torque_max_N_m"] <= data["wheels"]["max_torque_N_m"] * (1 + 1e-12)
    assert r["wheel_momentum_max_N_m_s"] <= data["wheels"]["max_momentum_N_m_s"] * (1 + 1e-12)
    planned = r["planned_motions"]
    assert len(planned) == TestbedOptions().planned_motions
    assert planned[0]["initial_state"] == r["initial_state"]
    most = max(range(len(planned)), key=lambda k: planned[k]["momentum_N_m_s"])
    assert r["wheel_needs"]["momentum_motion"] == most
    assert r["wheel_needs"]["momentum_N_m_s"] == planned[most]["momentum_N_m_s"]


def test_testbed_json_names_its_actuators_and_the_binding_figure(written: Path) -> None:
    """The contract's ``actuators`` (the catalogue the window searched) and
    ``verdict.binding_source``; every requirement names the table keys it rests on."""
    data = json.loads((written / "testbed.json").read_text())
    assert [a["name"] for a in data["actuators"]] == [a.name for a in catalogue()]
    for a in data["actuators"]:
        assert a["kind"] in ("reaction_wheel", "cmg") and isinstance(a["checked"], bool)
        assert a["torque_N_m"] > 0 and a["momentum_N_m_s"] > 0 and a["mass_kg"] > 0
    source = data["verdict"]["binding_source"]
    assert set(source) == {"key", "checked"}
    named = data["verdict"]["binding"]
    binding = next((r for r in data["state_of_the_art"] if r["name"] == named), None)
    if binding is not None:  # (None: buildable, every requirement decides)
        assert source["checked"] == (not binding["unverified"])
    if not source["checked"]:
        assert "not checked" in data["verdict"]["line"] or "rests on" in data["verdict"]["line"]
    for r in data["state_of_the_art"]:
        assert {"keys", "origin", "unverified"} <= set(r)
        assert all(k in {row.key for row in rows()} for k in r["keys"])
    drag = next(r for r in data["state_of_the_art"] if r["name"] == "bearing_drag_N_m_s")
    assert drag["parts"]["film_thin_m"] < drag["parts"]["film_thick_m"]
    assert drag["best"] > drag["parts"]["drag_at_thick_film_N_m_s"]  # the worst end decides


def test_written_parts_give_the_inertia(written: Path) -> None:
    """testbed.json's own numbers: the platform plus each written sphere is the total."""
    data = json.loads((written / "testbed.json").read_text())
    b = data["ballast"]
    total = np.array(data["platform"]["inertia_kg_m2"])
    for r, m, a in zip(np.array(b["positions"]), b["masses"], b["radii"], strict=True):
        total += m * (r @ r * np.eye(3) - np.outer(r, r)) + 0.4 * m * a * a * np.eye(3)
    assert np.abs(total - np.array(data["inertia_total_kg_m2"])).max() < 1e-12


def test_report_and_pictures(written: Path) -> None:
    report = (written / "report.md").read_text()
    assert "# Air-bearing testbed" in report and "## Requirements" in report
    assert "from memory" not in report and "## Actuator catalogue" in report
    sources = report[report.index("\n## Sources\n") :]  # the last section: the figures cited
    assert "| key | figure | source | locator | checked |" in sources
    # inline the key alone; its status in the sources section
    assert "[bearings.tabletop.tilt_limit_deg]" in report and ", unverified]" not in report
    (row,) = [
        x for x in sources.splitlines() if x.startswith("| bearings.tabletop.tilt_limit_deg |")
    ]
    assert row.endswith("| no (unverified) |")
    for name in ("drift_vs_rate.png", "drift_time.png", "wheels.png", "window.png", "motion.gif"):
        assert (written / name).stat().st_size > 1000


def test_python_function_and_result_protocol() -> None:
    result = cd.testbed(EXAMPLE, **{**TINY, "seeds": 1})
    assert repr(result).startswith("TestbedResult(") and len(repr(result)) <= 300
    assert "<table" in result._repr_html_()
    assert "I4 relative drift" in str(result)
    data = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert {"I4_relative_drift_median", "I4_relative_drift_p95"} <= set(
        data["results"]["nominal"]
    )  # one seed is still an ensemble


def test_example_scene_table_is_valid_and_embedded() -> None:
    data = tomllib.loads(EXAMPLE.read_text())
    TestbedOptions.from_table(data["testbed"])
    assert default_testbed_scene().read_text() == EXAMPLE.read_text()


def test_scene_schema_carries_the_closed_testbed_table() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    fragment = schema("scene")["properties"]["testbed"]
    assert fragment == table_schema("testbed", fragment["description"])
    assert fragment["additionalProperties"] is False
    assert fragment["properties"]["planned_motions"]["type"] == "integer"
    jsonschema.validate({"testbed": {"planned_motions": 3}}, schema("scene"))
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"testbed": {"planned_motions": 0}}, schema("scene"))
    jsonschema.validate(tomllib.loads(EXAMPLE.read_text()), schema("scene"))
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"testbed": {"colour": 1}}, schema("scene"))


def test_bad_scene_value_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    scene = tmp_path / "bad.toml"
    scene.write_text("[parameters]\nC = 0.5\n[testbed]\nrate_Hz = 0.0\n")
    assert main(["testbed", str(scene), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "testbed.rate_Hz" in err


def test_testbed_json_meets_its_schema(written: Path) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    data = json.loads((written / "testbed.json").read_text())
    jsonschema.validate(data, schema("testbed"))
    del data["results"]["nominal"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(data, schema("testbed"))
