"""Tests of `chargedesign conditions` (JSON keys, default scene, exact values, errors)."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import pytest
from unit_scene import UNIT_SCENE

from chargedesign.cli import main
from chargedesign.scene import load_scene

SCENE = """
[parameters]
C = 2.0
c = 0.5
d = 0.25
n = -0.4
K = 0.3
kappa = 0.1

[fields.magnetic]
a1 = 0.8
a2 = -0.25

[design]
realise = ["mu", "V", "inertia"]
"""


def _write(tmp_path: Path, text: str) -> str:
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_default_scene_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["conditions", str(UNIT_SCENE), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out)[:3] == ["charges", "dipoles", "masses"]
    p = load_scene(UNIT_SCENE).parameters
    a1 = load_scene(UNIT_SCENE).fields["magnetic"][0]
    charges = out["charges"]
    assert charges["xx"] == pytest.approx(-p.C * p.n / a1, rel=1e-15)
    assert charges["zz"] == pytest.approx(-3 * p.C * p.n / a1, rel=1e-15)
    for key in ("xy", "xz", "yz", "xxx", "xxy", "xyy", "xzz", "yyy", "yzz", "zzz"):
        assert charges[key] == 0.0
    assert charges["xxz"] == pytest.approx(-charges["yyz"], rel=1e-15)
    assert out["masses"]["zz"] == pytest.approx(1.5 * p.C, rel=1e-15)
    for key in ("combinations", "fields", "notes", "conditions", "realise", "parameters"):
        assert key in out
    assert out["fields"]["electric"]["origin"] == "derived"
    assert all(row["provenance"] for row in out["conditions"])


def test_scene_file_exact(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["conditions", _write(tmp_path, SCENE), "--json", "--exact"]) == 0
    out = json.loads(capsys.readouterr().out)
    rows = {
        next(iter(row["coefficients"])): row
        for row in out["conditions"]
        if row["source"] == "charges" and len(row["coefficients"]) == 1
    }
    # (p6): I_xx = -C n / a1, 6 a2 I_xyz = c C K, with the scene's decimals read exactly
    assert Fraction(rows["xx"]["exact_value"]) == -Fraction("2.0") * Fraction("-0.4") / Fraction(
        "0.8"
    )
    assert Fraction(rows["xyz"]["exact_value"]) == Fraction("0.5") * 2 * Fraction("0.3") / (
        6 * Fraction("-0.25")
    )


def test_human_output(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["conditions", str(UNIT_SCENE)]) == 0
    text = capsys.readouterr().out
    assert "charges:" in text and "dipoles:" in text and "masses:" in text
    assert "I_xx = -0.7" in text
    assert "notes:" in text


@pytest.mark.parametrize(
    ("replace", "words"),
    [
        (("a1 = 0.8", "a1 = 0.0"), ["a1 = 0"]),
        (('realise = ["mu", "V", "inertia"]', 'realise = ["mu", "torque"]'), ["design.realise"]),
        (("lambda", "lambda"), []),
    ],
)
def test_errors_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], replace: tuple[str, str], words: list[str]
) -> None:
    text = SCENE.replace(*replace)
    if not words:  # a singular parameter
        text = text.replace("kappa = 0.1", "kappa = 0.1\nlambda = 0.2")
        words = ["lambda", "singular"]
    assert main(["conditions", _write(tmp_path, text)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    for word in words:
        assert word in err


def test_missing_scene_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["conditions", str(tmp_path / "nope.toml")]) == 2
    assert "no such scene file" in capsys.readouterr().err


def test_default_strength_is_chosen_for_the_scene_body(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The body's size (largest distance of a candidate from O) sets the default e4."""
    big = SCENE + '\n[body]\nshape = "ball"\nradius = 100.0\nspacing = 25.0\n'
    assert main(["conditions", _write(tmp_path, big), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    defaults = out["default_strengths"]
    assert defaults["length_m"] == 100.0 and defaults["length_assumed"] is False
    e4 = out["fields"]["electric"]["legendre"][3]
    assert defaults["values"] == {"electric e4": e4}
    assert main(["conditions", _write(tmp_path, big.replace("100.0", "1.0")), "--json"]) == 0
    small = json.loads(capsys.readouterr().out)
    # mu fixes charges of size C n / (a1 L^2) with fourth moments ~ C n L^2 / a1: e4 ~ L^-2
    assert small["fields"]["electric"]["legendre"][3] == pytest.approx(e4 * 1e4, rel=1e-12)


def test_unreadable_body_is_not_an_error_for_the_conditions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = SCENE + '\n[body]\nshape = "ball"\nradius = -1.0\n'
    assert main(["conditions", _write(tmp_path, bad)]) == 0
    text = capsys.readouterr().out
    assert "body length 1 m assumed: [body] not usable (body.radius" in text
