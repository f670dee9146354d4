"""A parameter's value is substituted, then checked (issue 43 item 2): ``z = 0`` with
``V = "C*a*gamma1/z"`` (or in the integral, in l, the level or the inertia) gave tracebacks
in every command (sympy's ``zoo`` reached the polynomial ring, the float printer and the
designer). Every term that becomes infinite or undefined is refused at the boundary, in one
line naming the key and the parameter."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from case_scene import case_scene
from reliability_support import refused

INTERNALS = ("zoo", "ComplexInfinity", "nan", "oo ", "Traceback")

CASES = [
    ({"V": '"C*a*gamma1/z"'}, "case.V"),
    ({"integral": '"p**2/z"'}, "case.integral"),
    ({"l": '["0", "0", "gamma3/z"]'}, "case.l[2]"),
    ({"level": '"1/z"'}, "case.level"),
    ({"inertia": '["2*C", "2*C", "C + 1/z"]'}, "case.inertia[2]"),
]


@pytest.mark.parametrize(("changes", "key"), CASES)
@pytest.mark.parametrize("command", ["verify", "design", "simulate", "testbed", "bifurcation"])
def test_a_zero_parameter_in_a_denominator_is_refused_naming_key_and_parameter(
    changes: dict[str, str],
    key: str,
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    scene = case_scene(tmp_path, z="0", **changes)
    argv = [command, str(scene)]
    if command != "verify":
        argv += ["--out", str(tmp_path / "out")]
    line = refused(argv, command, capsys, tmp_path)
    assert f"{key}: becomes infinite or undefined with z = 0" in line, line
    assert not any(word in line for word in INTERNALS), line


def test_two_parameters_that_cancel_are_both_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = case_scene(tmp_path, V='"C*gamma1/(a - b)"', b="2.5")
    line = refused(["verify", str(scene)], "verify", capsys, tmp_path)
    assert "case.V: becomes infinite or undefined with a = 5/2, b = 5/2" in line, line


@pytest.mark.parametrize("command", ["check", "simulate", "export"])
def test_a_zero_parameter_in_a_design_tables_denominator_is_refused(
    command: str, case_design: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    design = json.loads(json.dumps(case_design))
    design["case"]["table"]["V"] = "C*a*gamma1/z"
    design["case"]["table"]["parameters"]["z"] = 0
    path = tmp_path / "design.json"
    path.write_text(json.dumps(design))
    argv = [command, str(path)] + (["--out", str(tmp_path / "o.csv")] * (command == "export"))
    line = refused(argv, command, capsys, tmp_path)
    assert "design.case.table.V: becomes infinite or undefined with z = 0" in line, line
