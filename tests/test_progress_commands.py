"""Every command whose work can pass 5 s says its progress on stderr: the count against its
total ("k/N") and an estimate of the time left, a line every few seconds without a terminal
(here: every 0.05 s), nothing with --quiet. Small scenes; stderr captured (not a terminal)."""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path

import pytest

from chargedesign.airbearing import run as testbed_run
from chargedesign.cli import main
from chargedesign.commands import progress as progress_module
from chargedesign.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
UNIT = ROOT / "examples" / "scenes" / "unit_scale.toml"
TESTBED = ROOT / "examples" / "scenes" / "testbed.toml"
DESIGN = ROOT / "tests" / "tolerancing" / "data" / "default_design.json"
TINY_TESTBED = {
    "t_end_s": 0.4,
    "rate_Hz": 20.0,
    "seeds": 2,
    "requirement_rates_Hz": [20.0],
    "requirement_seeds": 1,
}


@pytest.fixture(autouse=True)
def often(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(progress_module, "FIRST_AFTER", 0.0)
    monkeypatch.setattr(progress_module, "EVERY", 0.05)


def counted(err: str, label: str, unit: str) -> list[tuple[int, int, str]]:
    """The progress lines of ``label``: (k, N, the rest of the line)."""
    pattern = re.compile(rf"^{re.escape(label)}: (\d+)/(\d+) {unit}\b(.*)$")
    return [(int(m[1]), int(m[2]), m[3]) for line in err.splitlines() if (m := pattern.match(line))]


def assert_progress(err: str, label: str, unit: str) -> None:
    lines = counted(err, label, unit)
    assert lines, err
    # some line gives a count short of its total and the time left it estimates
    assert any(0 < k < n and re.search(r"about .+ left$", rest) for k, n, rest in lines), err
    k, n, rest = lines[-1]
    assert k == n and rest.endswith("done"), lines[-1]
    assert all(k <= n for k, n, _ in lines)


def tiny_testbed(tmp_path: Path) -> Path:
    text = TESTBED.read_text()
    table = {**tomllib.loads(text)["testbed"], **TINY_TESTBED}
    path = tmp_path / "tiny.toml"
    body = "\n".join(f"{k} = {json.dumps(v)}" for k, v in table.items())
    path.write_text(text.split("\n[testbed]\n")[0] + "\n[testbed]\n" + body + "\n")
    return path


def test_design_counts_its_stages(tmp_path, capsys):
    assert main(["design", str(UNIT), "--out", str(tmp_path / "o"), "--no-picture"]) == 0
    assert_progress(capsys.readouterr().err, "design", "stages")


def test_testbed_counts_its_sampled_runs(tmp_path, capsys):
    # the tiny scene's eight runs can all end within one 0.05 s beat on a fast machine, so
    # the command's lines are checked for their count and end, and the counts the testbed
    # reports (what the bar says between beats) are recorded through its tally
    scene = tiny_testbed(tmp_path)
    assert main(["testbed", str(scene), "--out", str(tmp_path / "o")]) == 0
    lines = counted(capsys.readouterr().err, "testbed", "runs")
    assert lines and all(k <= n for k, n, _ in lines)
    # 2 noise-free runs, 2 nominal seeds, 4 gyro grades x 1 rate x 1 seed
    assert lines[-1][:2] == (8, 8) and lines[-1][2].endswith("done")
    told: list[tuple[int, int]] = []

    def tally(done: int, total: int) -> None:
        told.append((done, total))

    testbed_run.testbed_from_scene(load_scene(scene), tally=tally)
    assert told[0] == (0, 8) and told[-1] == (8, 8)
    assert any(0 < done < total for done, total in told)
    assert [done for done, _ in told] == sorted(done for done, _ in told)


def test_tolerance_counts_its_monte_carlo_bodies(capsys):
    argv = ["tolerance", str(DESIGN), "--position", "2um", "--samples", "12", "--t-end", "5"]
    assert main([*argv, "--levels", "1"]) == 0
    err = capsys.readouterr().err
    assert_progress(err, "tolerance", "bodies")
    # 12 drawn for the distributions, then the nominal and 12 perturbed bodies simulated
    assert counted(err, "tolerance", "bodies")[-1][:2] == (25, 25)


def test_bifurcation_counts_its_stages(tmp_path, capsys):
    assert main(["bifurcation", str(UNIT), "--out", str(tmp_path / "o")]) == 0
    assert_progress(capsys.readouterr().err, "bifurcation", "stages")


def test_quiet_says_nothing(capsys):
    argv = ["tolerance", str(DESIGN), "--position", "2um", "--samples", "4", "--t-end", "2"]
    assert main([*argv, "--levels", "1", "--quiet"]) == 0
    assert capsys.readouterr().err == ""
