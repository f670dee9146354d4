"""The check of a frame body: its elements against the theorem with n = 0."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from unit_scene import unit_design

from chargedesign.body import Design, write_design
from chargedesign.checker import check_design
from chargedesign.cli import main
from chargedesign.larmor import LarmorReading

RATE = 0.7


@pytest.fixture(scope="module")
def elements_at_n_zero() -> Design:
    """The unit-scale body designed with n = 0, recorded with the theorem's n = 0.7."""
    design = unit_design(0.0)
    design.parameters = dataclasses.replace(design.parameters, n=RATE)
    design.larmor = None  # as a file without the key: the charges reading, with n = 0.7
    return design


def test_a_frame_body_passes_against_the_theorem_with_n_zero(elements_at_n_zero: Design) -> None:
    frame = dataclasses.replace(elements_at_n_zero, larmor=LarmorReading("frame", RATE))
    report = check_design(frame)
    assert report.passed, report.failures
    assert report.quantities["mu"].rel_err < 1e-12 and report.quantities["V"].rel_err < 1e-12
    assert report.larmor == {"reading": "frame", "rate": RATE, "checked_n": 0.0}
    assert report.to_dict()["larmor"]["checked_n"] == 0.0
    text = str(report)
    assert "frame reading: elements checked against the theorem with n = 0" in text
    assert "n = 0.7 1/s is the rate of the turning axes" in text


def test_the_same_elements_read_as_charges_fail(elements_at_n_zero: Design) -> None:
    """Without the frame reading they are compared with n = 0.7, which they do not realise."""
    report = check_design(elements_at_n_zero)
    assert not report.passed
    assert {"mu", "V"} <= set(report.failures)
    assert report.larmor is None and "larmor" not in report.to_dict()


def test_a_charges_body_is_checked_as_before() -> None:
    """An explicit charges reading changes no number of the check."""
    design = unit_design(RATE)
    assert design.larmor == LarmorReading("charges", RATE)  # the design writes its reading
    plain = check_design(dataclasses.replace(design, larmor=None)).to_dict()
    labelled = check_design(
        dataclasses.replace(design, larmor=LarmorReading("charges", RATE))
    ).to_dict()
    assert labelled.pop("larmor") == {"reading": "charges", "rate": RATE, "checked_n": RATE}
    assert labelled == plain and plain["passed"] is True


def test_check_cli_says_frame(
    elements_at_n_zero: Design, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "frame.json"
    write_design(dataclasses.replace(elements_at_n_zero, larmor=LarmorReading("frame", RATE)), path)
    assert main(["check", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["passed"] is True and data["larmor"]["reading"] == "frame"
    assert any(n.startswith("frame reading") for n in data["notes"])
    assert main(["check", str(path)]) == 0
    assert "larmor reading: frame (rate 0.7 1/s); compared with the theorem at n = 0" in (
        capsys.readouterr().out
    )
