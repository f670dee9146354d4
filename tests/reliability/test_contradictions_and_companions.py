"""Minor items of issue 43: a key that contradicts another is refused, not half-honoured
(``bearing = "full_sphere"`` with ``tilt_limit_deg = 30`` gave 180 in testbed.json, with
source "the scene's tilt_limit_deg", while its tilt map used 30), and an option that needs a
companion is refused without it (``--scheduler-timeout`` without ``--scheduler`` was
accepted and ignored)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from reliability_support import refused

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_a_full_sphere_with_a_tilt_limit_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    head, table = (EXAMPLES / "scenes" / "testbed.toml").read_text().split("\n[testbed]\n")
    keys = {"bearing": "full_sphere", "tilt_limit_deg": 30.0}
    lines = [ln for ln in table.splitlines() if ln.split("=")[0].strip() not in keys]
    lines += [f"{k} = {json.dumps(v)}" for k, v in keys.items()]
    scene = tmp_path / "scene.toml"
    scene.write_text(head + "\n[testbed]\n" + "\n".join(lines) + "\n")
    argv = ["testbed", str(scene), "--out", str(tmp_path / "out"), "--quiet"]
    line = refused(argv, "testbed", capsys, tmp_path)
    assert "testbed.tilt_limit_deg" in line and "full_sphere" in line, line


def test_scheduler_timeout_needs_a_scheduler(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sweep = EXAMPLES / "sweeps" / "design_spacing.sweep"
    argv = ["sweep", str(sweep), "--out", str(tmp_path / "out"), "--scheduler-timeout", "3"]
    line = refused(argv, "sweep", capsys, tmp_path)
    assert "--scheduler-timeout: needs --scheduler" in line, line


@pytest.mark.parametrize(
    ("argv", "command", "needs"),
    [
        (["simulate", "--orbits", "5"], "simulate", "give --atlas too"),
        (["simulate", "--fli"], "simulate", "give --atlas too"),
        (["show", "design.json", "--frames", "10"], "show", "give --animate TRAJ.npz too"),
        (["show", "design.json", "--fps", "5"], "show", "give --animate TRAJ.npz too"),
    ],
)
def test_an_option_without_its_companion_is_refused_before_any_work(
    argv: list[str], command: str, needs: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--orbits and --fli set the atlas, --frames and --fps the animation: alone they were
    silently ignored; now one line names the option and its companion, before any work (the
    design.json named here does not exist: the refusal comes first)."""
    line = refused([*argv], command, capsys, tmp_path)
    assert line.split(": error: ")[1].startswith(argv[-2] if argv[-1][0].isdigit() else argv[-1])
    assert needs in line, line
