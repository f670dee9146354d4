"""The command line's new paths: ensembles from a scene, the atlas, monitors in --json."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chargedesign.cli import main
from chargedesign.simulation import taylor

pytestmark = pytest.mark.skipif(not taylor.available(), reason="heyoka is not installed")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_cli_ensemble_scene(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "states.csv").write_text(
        "p,q,r,gamma1,gamma2,gamma3\n0.6,-0.4,0.1,0.36,0.48,0.8\n0.1,0.2,0.3,0,0.6,0.8\n"
    )
    (tmp_path / "scene.toml").write_text(
        "[parameters]\nC = 1.0\nc = 0.3\nd = -0.4\nn = 0.7\nK = 0.5\nkappa = 0.9\n"
        '[initial]\nfile = "states.csv"\n[simulation]\nt_end = 2.0\nsamples = 3\n'
    )
    out_dir = tmp_path / "out"
    assert main(["simulate", str(tmp_path / "scene.toml"), "--json", "--out", str(out_dir)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out)[:3] == ["I4_rel_drift", "I3_max", "effects"]
    assert out["trajectories"] == 2 and out["method"] == "taylor"
    assert (out_dir / "ensemble.csv").is_file() and (out_dir / "summary.json").is_file()


def test_cli_atlas_writes_picture_and_points(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the unit-scale case (the embedded default scene may be a slowed-down buildable body)
    scene = tmp_path / "unit.toml"
    scene.write_text("[parameters]\nC = 1.0\nc = 0.3\nd = -0.4\nn = 0.7\nK = 0.5\nkappa = 0.9\n")
    args = ["simulate", str(scene), "--atlas", "--orbits", "3", "--t-end", "20"]
    assert main([*args, "--out", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["levels"] == [0.0, 0.5] and out["orbits"] == 3
    assert min(out["points"]) >= 3
    assert (tmp_path / "atlas.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "atlas.csv").read_text().startswith("level,orbit,t,")


def test_cli_kowalevski_example_reports_why_not_i4(capsys: pytest.CaptureFixture[str]) -> None:
    scene = str(EXAMPLES / "simulate_kowalevski.toml")
    assert main(["simulate", scene, "--t-end", "50", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["I4_rel_drift"] is None and out["I4_reason"].startswith("I4 is no integral")
    assert out["monitors"]["kowalevski"]["drift"] <= 1e-13
    assert out["monitors"]["lagrange"]["requested"] is True
    assert main(["simulate", scene, "--t-end", "5"]) == 0
    text = capsys.readouterr().out
    assert "I4 relative drift not reported: I4 is no integral" in text
    assert "kowalevski: drift" in text
