"""A scene with ``[case]`` (workbench, second step): loaded through the case file's validation,
designed as masses in gravity (``chargedesign design``), checked against the case's own V and
inertia (``chargedesign check``) and simulated with the case's integral monitored.

The held-out cases are written here (not in the repository's catalogue); the design.json is
read with ``json`` alone and its inertia and first moments recomputed by plain sums."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from case_tables import kowalevski_table

from chargedesign.cli import main
from chargedesign.errors import InputError
from chargedesign.scene import load_scene
from chargedesign.scene.keys import key_names
from chargedesign.schemas import schema

#: a Kowalevski top the catalogue does not hold: C = 0.3 kg m^2, a = 2.5 1/s^2, so
#: V = C a gamma1 = 0.75 gamma1 J
BODY = '\n[body]\nshape = "ball"\nradius = 0.5\nspacing = 0.125\n'
KOWALEVSKI = kowalevski_table("kowalevski-held-out", 0.3, 2.5) + BODY
TIGHT = 1e-12


def _write(tmp_path: Path, text: str, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, "utf-8")
    return path


def _design(tmp_path: Path, text: str = KOWALEVSKI) -> Path:
    """``chargedesign design`` of the case scene ``text`` (must succeed): its out folder."""
    out = tmp_path / "out"
    scene = _write(tmp_path, text)
    assert main(["design", str(scene), "--out", str(out), "--no-picture", "--quiet"]) == 0
    return out


def test_a_scene_reads_its_case_through_the_case_file_validation(tmp_path: Path) -> None:
    scene = load_scene(_write(tmp_path, KOWALEVSKI))
    assert scene.case is not None and scene.case.name == "kowalevski-held-out"
    assert [str(m) for m in scene.case.inertia] == ["3/5", "3/5", "3/10"]
    assert str(scene.case.V) == "3*gamma1/4"
    assert load_scene(None).case is None


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (KOWALEVSKI + "\n[parameters]\nC = 1.0\n", "[parameters] and [case] together"),
        (KOWALEVSKI.replace('"C*a*gamma1"', '"__import__(1)"'), "case.V: a call"),
        (KOWALEVSKI.replace('name = "kowalevski-held-out"\n', ""), "case.name: missing"),
        (KOWALEVSKI.replace('level = "general"', "levels = 0"), "case.levels: expected one of"),
    ],
)
def test_a_bad_case_scene_is_refused_in_one_line(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(InputError) as caught:
        load_scene(_write(tmp_path, text))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_the_scene_schema_declares_the_case_table() -> None:
    table = schema("scene")["properties"]["case"]
    assert set(table["properties"]) == set(key_names("case"))
    assert table["additionalProperties"] is False


def test_design_check_and_simulate_a_held_out_kowalevski_top(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = _design(tmp_path)
    capsys.readouterr()
    report = (out / "report.md").read_text("utf-8")
    assert "Realises the case's V" in report and "holds exactly" in report
    data = json.loads((out / "design.json").read_text("utf-8"))
    assert data["realises"] == ["V", "inertia"]
    assert data["fields"]["gravity"]["legendre"] == [9.80665]
    record = data["case"]
    assert record["name"] == "kowalevski-held-out" and record["level"] == "general"
    assert record["certificate"]["holds"] is True and record["certificate"]["independent"]
    x = np.array(data["masses"]["positions"])
    m = np.array(data["masses"]["values"])
    assert np.all(m > 0)
    inertia = sum(
        mi * (xi @ xi * np.eye(3) - np.outer(xi, xi)) for xi, mi in zip(x, m, strict=True)
    )
    C = 0.3
    assert np.max(np.abs(inertia - np.diag([2 * C, 2 * C, C]))) <= TIGHT * 2 * C
    # the centre of mass gives exactly the case's linear potential: g M x_cm = (C a, 0, 0)
    first = 9.80665 * (m @ x)
    assert abs(first[0] - C * 2.5) <= TIGHT * C * 2.5
    assert np.max(np.abs(first[1:])) <= TIGHT * C * 2.5
    # and in exact arithmetic of the written numbers, to the rounding of the sum
    exact = sum(Fraction(mi) * Fraction(xi[0]) for xi, mi in zip(x, m, strict=True)) * Fraction(
        "9.80665"
    )
    assert abs(float(exact) - 0.75) <= 4e-16 * 0.75

    assert main(["check", str(out / "design.json"), "--json"]) == 0
    checked = json.loads(capsys.readouterr().out)
    assert checked["V_rel_err"] <= 1e-12 and checked["inertia_rel_err"] <= 1e-12

    assert main(["simulate", str(out / "design.json"), "--t-end", "10", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["F_rel_drift"] <= 1e-12
    # an independent route: the project's own Kowalevski monitor, built from the body's
    # polynomial bank (not from the case's expressions), has the same value at t = 0
    kowalevski = run["monitors"]["kowalevski"]
    assert run["monitors"]["F"]["initial"] == pytest.approx(kowalevski["initial"], rel=1e-12)
    # the theorem's I4 is not this body's integral: no drift is reported as if it were
    assert run["I4_rel_drift"] is None
    assert run["monitors"]["I4"]["integral"] is False
    assert "realises the case kowalevski-held-out" in run["monitors"]["I4"]["reason"]


def test_check_compares_with_the_case_not_the_theorem(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same body against a case record whose V is twice as large fails check."""
    out = _design(tmp_path)
    capsys.readouterr()
    data = json.loads((out / "design.json").read_text("utf-8"))
    data["case"]["table"]["V"] = "2*C*a*gamma1"
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps(data), "utf-8")
    assert main(["check", str(wrong), "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["V_rel_err"] > 0.1


def test_a_wrong_integral_drifts(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A case scene simulated directly; its claimed integral with a wrong coefficient (a = 2
    where the potential has 2.5) is refuted by the certificate and drifts in the run."""
    text = KOWALEVSKI.replace("a*gamma1)**2", "2*gamma1)**2").replace("a*gamma2", "2*gamma2")
    scene = _write(tmp_path, text)
    assert main(["simulate", str(scene), "--t-end", "10", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["F_rel_drift"] > 1e-3
    assert run["monitors"]["kowalevski"]["drift"] <= 1e-12


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("yehia-gyrostat", "gyrostat's rotor"),
        ("goriachev", "singular"),
        ("degree-5", "degree 5"),
    ],
)
def test_cases_no_supported_field_realises_are_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, reason: str
) -> None:
    tables = {
        "yehia-gyrostat": 'inertia = [2, 2, 1]\nV = "gamma1"\nl = ["0", "0", "k"]\n'
        'integral = "r"\n[case.parameters]\nk = 0.5\n',
        "goriachev": 'inertia = [4, 4, 1]\nV = "gamma1 + 1/gamma3**2"\nintegral = "r"\nlevel = 0\n',
        "degree-5": 'inertia = [2, 2, 1]\nV = "gamma1**5"\nintegral = "r"\n',
    }
    text = f'[case]\nname = "{name}"\n{tables[name]}' + BODY
    out = tmp_path / "out"
    assert main(["design", str(_write(tmp_path, text)), "--out", str(out), "--quiet"]) == 2
    error = capsys.readouterr().err.strip()
    assert reason in error and "\n" not in error
    assert not out.exists()


def test_simulate_moves_a_case_design_of_another_inertia(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Euler's top diag(3, 2, 1) designed as masses: simulate moves it with the case's inertia
    (its |I omega|^2 drifted by 0.09 when the body model was diag(2C, 2C, C))."""
    text = (
        '[case]\nname = "euler-312"\ninertia = [3, 2, 1]\nV = "0"\n'
        'integral = "9*p**2 + 4*q**2 + r**2"\n' + BODY
    )
    out = _design(tmp_path, text)
    assert main(["check", str(out / "design.json")]) == 0
    capsys.readouterr()
    assert main(["simulate", str(out / "design.json"), "--t-end", "10", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["F_rel_drift"] <= 1e-12 and run["I1_rel_drift"] <= 1e-12
    # masses that are not the case's inertia are refused in one line, before any run
    data = json.loads((out / "design.json").read_text("utf-8"))
    data["case"]["table"]["inertia"] = [3, 2, 2]
    (out / "other.json").write_text(json.dumps(data), "utf-8")
    assert main(["simulate", str(out / "other.json"), "--t-end", "1"]) == 2
    error = capsys.readouterr().err.strip()
    assert "but the case asks for diag(3, 2, 2)" in error and "\n" not in error


def test_conditions_of_a_case_scene_are_the_masses_in_gravity(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["conditions", str(_write(tmp_path, KOWALEVSKI)), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["case"] == "kowalevski-held-out" and "parameters" not in out
    masses = out["masses"]
    # M_x = C a / g; second moments (B + C - A)/2 = C/2 twice and (A + B - C)/2 = 3C/2
    assert masses["x"] == pytest.approx(0.75 / 9.80665, rel=1e-15)
    assert (masses["xx"], masses["yy"], masses["zz"]) == pytest.approx((0.15, 0.15, 0.45))
    assert masses["xy"] == masses["xz"] == masses["yz"] == masses["y"] == masses["z"] == 0.0


def test_the_frontier_of_a_case_scene_without_medium_is_refused_as_the_theorems(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """frontier takes a [case] scene (its parts and rate: tests/designer/
    test_general_case_parts.py); without [medium] nothing limits it, in one line."""
    assert main(["frontier", str(_write(tmp_path, KOWALEVSKI))]) == 2
    error = capsys.readouterr().err.strip()
    assert "the scene has no [medium] table, so nothing limits it" in error
    assert "\n" not in error


def test_tolerance_refuses_a_case_design(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = _design(tmp_path)
    capsys.readouterr()
    assert main(["tolerance", str(out / "design.json")]) == 2
    assert "tolerance takes a design of the theorem" in capsys.readouterr().err
