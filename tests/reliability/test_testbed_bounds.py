"""`chargedesign testbed`: every run has a bound checked before the work, and the outputs say
what was computed (issue 32's testbed items): one line naming the key, no output folder."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from reliability_support import refused, run_cli

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "testbed.toml"
QUICK = {"seeds": 2, "requirement_seeds": 1}


def _scene(folder: Path, testbed: dict, parameters: dict | None = None) -> Path:
    """The example testbed scene with ``testbed`` keys set and ``parameters`` replaced."""
    head, table = EXAMPLE.read_text().split("\n[testbed]\n")
    lines = [ln for ln in table.splitlines() if ln.split("=")[0].strip() not in testbed]
    lines += [f"{k} = {json.dumps(v)}" for k, v in testbed.items()]
    for name, value in (parameters or {}).items():
        head = "\n".join(
            f"{name} = {value!r}" if ln.split("=")[0].strip() == name else ln
            for ln in head.splitlines()
        )
    path = folder / "scene.toml"
    path.write_text(head + "\n[testbed]\n" + "\n".join(lines) + "\n")
    return path


def _refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    testbed: dict,
    parameters: dict | None = None,
) -> str:
    scene = _scene(tmp_path, testbed, parameters)
    line = refused(
        ["testbed", str(scene), "--out", str(tmp_path / "out"), "--quiet"],
        "testbed",
        capsys,
        tmp_path,
    )
    assert not (tmp_path / "out").exists()
    return line


START = {"initial_gamma": [0.36, 0.48, 0.8], "initial_p": 0.18, "initial_q": -0.12}


@pytest.mark.parametrize(
    "start",
    [
        {**START, "initial_gamma": [0.6, 0.8, 2e-8]},
        {**START, "initial_gamma": [0.6, 0.8, 1e-6]},
        {**START, "initial_p": 1e4},
        {**START, "initial_p": 1e3, "initial_q": -1e3},
    ],
)
def test_a_start_too_fast_for_the_step_cap_names_the_start_and_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], start: dict
) -> None:
    line = _refused(tmp_path, capsys, start)
    assert "the start (initial_gamma, initial_p, initial_q)" in line
    assert "testbed.max_loop_steps" in line


@pytest.mark.parametrize(("name", "cause"), [("n", "parameters n"), ("c", "c, d")])
def test_parameters_whose_scale_swamps_the_loop_are_refused_by_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, cause: str
) -> None:
    line = _refused(tmp_path, capsys, {}, {name: 1e8})
    assert cause in line and "testbed.max_loop_steps" in line


@pytest.mark.parametrize("rates", [[1e-30], [0.0], [1e9]])
def test_requirement_rates_have_a_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], rates: list
) -> None:
    assert "testbed.requirement_rates_Hz" in _refused(
        tmp_path, capsys, {"requirement_rates_Hz": rates}
    )


@pytest.mark.parametrize("spacing", [1e-3, 1e-6])
def test_a_ballast_grid_past_the_memory_cap_names_ballast_spacing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], spacing: float
) -> None:
    line = _refused(tmp_path, capsys, {"ballast_spacing_m": spacing})
    assert "testbed.ballast_spacing_m" in line and "MB" in line


@pytest.mark.parametrize("t_end", [1e-9, 1e-30, 0.01])
def test_a_horizon_shorter_than_a_control_period_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], t_end: float
) -> None:
    line = _refused(tmp_path, capsys, {"t_end_s": t_end})
    assert "testbed.t_end_s" in line and "shorter than one control period" in line


@pytest.mark.parametrize(
    ("table", "key"),
    [
        ({"torque_resolution_N_m": 10.0, "max_torque_N_m": 1.0}, "testbed.torque_resolution_N_m"),
        ({"torque_resolution_N_m": 1.0}, "testbed.torque_resolution_N_m"),
        ({"max_torque_N_m": 1e30}, "testbed.max_torque_N_m"),
    ],
)
def test_a_torque_step_above_the_range_is_refused_not_run_open(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], table: dict, key: str
) -> None:
    line = _refused(tmp_path, capsys, {**QUICK, **table})
    assert key in line and "open loop" in line


def test_the_horizon_simulated_is_the_one_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """0.3 Hz over 5 s is 1.5 periods: the loop runs 2 (6.67 s) and says so."""
    table = {**QUICK, "rate_Hz": 0.3, "t_end_s": 5.0, "requirement_rates_Hz": [0.3]}
    scene = _scene(tmp_path, table)
    code, out, err = run_cli(
        ["testbed", str(scene), "--out", str(tmp_path / "out"), "--quiet"], capsys
    )
    assert code == 0, err
    data = json.loads((tmp_path / "out" / "testbed.json").read_text())
    assert data["results"]["t_simulated_s"] == pytest.approx(2 / 0.3, rel=1e-12)
    said = " ".join(out.split())  # the terminal wraps its lines at 160 characters
    assert "6.66667 s simulated" in said and "rounded to whole control periods" in said
