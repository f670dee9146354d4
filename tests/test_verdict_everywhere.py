"""One verdict, said once and the same everywhere (issue 38): a body designed from a scene with
``[medium]`` has its verdict recorded in design.json, and every output says that state: the
report's first lines, ``design``'s terminal summary, ``check --json`` (its own recomputation,
which agrees), the API's ``repr`` and HTML, and a sweep's summary.csv. The embedded default
scene (NOT buildable) is read the same way through the command line."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

import chargedesign as cd
from chargedesign.cli import main
from chargedesign.vocabulary import VERDICT_STATES

#: a small K = 0 body in vacuum (the Chaplygin example at a coarse spacing): designed in a few
#: seconds, buildable and realised, its air-bearing support open
SMALL_SCENE = """
[parameters]
C = 2.0e-5
c = 0.3
d = -0.4
n = 0.0
K = 0.0
kappa = 64.0

[fields.magnetic]
a1 = 0.0
a2 = 0.03
max = 1.0

[medium]
name = "vacuum"
safety = 0.5

[magnets]
material = "ndfeb"

[ballast]
material = "fused-silica"

[body]
shape = "ball"
radius = 0.05
spacing = 0.025

[design]
realise = ["mu", "V", "inertia"]
"""

SWEEP = """
scene = "scene.toml"
command = "design"
[grid]
"body.radius" = [0.05]
"""


def _report_state(report: str) -> str:
    """The state the report's first lines say (``**Verdict: STATE** ...``)."""
    head = "\n".join(report.splitlines()[:4])
    said = [s for s in VERDICT_STATES if f"**Verdict: {s}" in head]
    assert len(said) == 1, head
    return said[0]


def _terminal_state(out: str) -> str:
    first = out.splitlines()[0]
    said = [s for s in VERDICT_STATES if first.startswith(f"Verdict: {s}")]
    assert len(said) == 1, first
    return said[0]


def _cli_outputs(scene: str | None, out: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    """design (terminal), design.json, report.md and check --json of one scene."""
    args = ["design", *([scene] if scene else []), "--out", str(out), "--no-picture", "--quiet"]
    assert main(args) == 0
    stdout = capsys.readouterr().out
    lines = stdout.splitlines()
    assert len(lines) <= 40 and max(len(x) for x in lines) <= 160
    design = json.loads((out / "design.json").read_text())
    report = (out / "report.md").read_text()
    main(["check", str(out / "design.json"), "--json", "--orientations", "200"])
    check = json.loads(capsys.readouterr().out)
    main(["check", str(out / "design.json"), "--orientations", "200"])
    check_text = capsys.readouterr().out
    assert max(len(x) for x in check_text.splitlines()) <= 160
    assert "PASSED" not in check_text
    return {
        "design.json": design["verdict"]["state"],
        "report.md": _report_state(report),
        "design stdout": _terminal_state(stdout),
        "check --json": check["verdict"]["state"],
        "check text": next(
            s
            for s in VERDICT_STATES
            if f"verdict (recomputed from the written parts): {s}" in check_text
        ),
        "check agrees": check["verdict_agrees"],
        "buildable renamed": "buildable" not in design["buildability"]
        if "buildability" in design
        else True,
    }


def test_one_state_in_every_output_of_a_physical_design(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text(SMALL_SCENE)
    said = _cli_outputs(str(scene), tmp_path / "out", capsys)
    assert said.pop("check agrees") is True and said.pop("buildable renamed") is True

    result = cd.design(str(scene))
    said["repr"] = next(s for s in VERDICT_STATES if f"verdict='{s}'" in repr(result))
    html = result._repr_html_()
    said["html"] = next(s for s in VERDICT_STATES if s in html)
    said["str"] = _terminal_state(str(result))

    (tmp_path / "grid.sweep").write_text(SWEEP)
    assert main(["sweep", str(tmp_path / "grid.sweep"), "--out", str(tmp_path / "sweep")]) == 0
    capsys.readouterr()
    with open(tmp_path / "sweep" / "summary.csv", newline="") as f:
        (row,) = list(csv.DictReader(f))
    said["summary.csv"] = row["verdict"]

    assert len(set(said.values())) == 1, said
    assert said["design.json"] in VERDICT_STATES[:3]  # judged for buildability


def test_one_state_in_every_output_of_the_embedded_scene(tmp_path, capsys):
    said = _cli_outputs(None, tmp_path / "out", capsys)
    assert said.pop("check agrees") is True and said.pop("buildable renamed") is True
    assert set(said.values()) == {"NOT buildable"}, said
