"""Number literals are read from their text and refused by their size before they are built
(issue 43 item 1): ``1e99999999`` once built a number of 10^8 digits before its magnitude
was checked (over 60 s), ``0e99999999`` skipped the check, and ``--level 1e9999999`` ended
in Python's integer-conversion limit, naming neither the option nor the reason."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from case_scene import case_scene
from reliability_support import refused

from chargedesign.errors import InputError
from chargedesign.scene.expressions import parse_expression
from chargedesign.validation import exact_decimal

HUGE = ["1e99999999", "1e-99999999", "0e99999999", "1e9_9999_999", "1E+99999999"]
INTERNALS = ("int_max_str_digits", "4300", "ComplexInfinity", "zoo", "Traceback")


def _clean(line: str) -> None:
    assert not any(word in line for word in INTERNALS), line


@pytest.mark.parametrize("literal", HUGE)
def test_a_huge_exponent_in_v_is_refused_naming_the_key(
    literal: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = case_scene(tmp_path, V=f'"{literal}*gamma1"')
    line = refused(["verify", str(scene), "--json"], "verify", capsys, tmp_path)
    assert "case.V" in line and "exponent" in line, line
    _clean(line)


@pytest.mark.parametrize("literal", HUGE)
def test_a_huge_exponent_in_a_parameter_value_is_refused(
    literal: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = case_scene(tmp_path, a=f'"{literal}"')
    line = refused(["verify", str(scene)], "verify", capsys, tmp_path)
    assert "case.parameters.a" in line, line
    _clean(line)


@pytest.mark.parametrize("command", ["check", "simulate", "export"])
def test_a_huge_literal_in_a_design_tables_v_is_refused(
    command: str, case_design: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    table = {
        "name": "k",
        "inertia": ["2*C", "2*C", "C"],
        "V": "1e99999999*gamma1",
        "l": ["0", "0", "0"],
        "integral": "p",
        "level": "general",
        "parameters": {"C": 0.3},
    }
    design = json.loads(json.dumps(case_design))
    design["case"]["table"] = table
    path = tmp_path / "design.json"
    path.write_text(json.dumps(design))
    argv = [command, str(path)] + (
        ["--out", str(tmp_path / "o.csv")] if command == "export" else []
    )
    line = refused(argv, command, capsys, tmp_path)
    assert "case.table.V" in line, line
    _clean(line)


@pytest.mark.parametrize("level", ["1e99999999", "1e9999999", "1/0", "1e31", "1/2/3", "x"])
def test_bifurcation_level_is_read_by_its_text(
    level: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = case_scene(tmp_path)
    argv = ["bifurcation", str(scene), f"--level={level}", "--out", str(tmp_path / "o")]
    line = refused(argv, "bifurcation", capsys, tmp_path)
    assert "--level" in line, line
    _clean(line)


@pytest.mark.parametrize(
    ("text", "value"),
    [("0.1", "1/10"), ("2.5e-3", "1/400"), ("1_000", "1000"), (".5", "1/2"), ("1e30", "1e30")],
)
def test_ordinary_literals_stay_exact(text: str, value: str) -> None:
    from fractions import Fraction

    expected = Fraction(value) if "e" not in value else Fraction(10**30)
    assert exact_decimal(text, "x") == expected
    assert parse_expression(f"{text}*gamma1", "x").as_coeff_Mul()[0] == expected


def test_a_fraction_is_read_only_where_one_is_allowed() -> None:
    from fractions import Fraction

    assert exact_decimal("2/5", "x", fraction=True) == Fraction(2, 5)
    with pytest.raises(InputError, match="x: expected a decimal number"):
        exact_decimal("2/5", "x")


def test_export_validates_the_case_record_as_check_does(
    case_design: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 43 item 7: ``export`` wrote a design.json whose ``case.table.V`` is an
    ``__import__`` call, which ``check`` and ``simulate`` refuse."""
    design = json.loads(json.dumps(case_design))
    design["case"]["table"]["V"] = "__import__('os').getcwd()"
    path = tmp_path / "design.json"
    path.write_text(json.dumps(design))
    for command in ("check", "export"):
        argv = [command, str(path)] + (["--out", str(tmp_path / "o.csv")] * (command == "export"))
        line = refused(argv, command, capsys, tmp_path)
        assert "design.case.table.V: a call" in line, line
