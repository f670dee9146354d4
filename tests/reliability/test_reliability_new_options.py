"""Issue 22's rules on the options and tables added after it (an outside review): design.json's
``larmor`` key, ``tolerance --chi-relative/--density-relative/--magnetisation-relative``.

Each refusal is one error line, no traceback, nothing written and the inputs unchanged.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import SMALL_DESIGN, assert_clean_error, run_cli, snapshot

#: every command that reads a design.json (the error comes from the one reader, before the work)
READERS = [
    ["check", "j.json"],
    ["export", "j.json", "--format", "csv", "--out", "o.csv"],
    ["simulate", "j.json", "--t-end", "1", "--no-progress"],
    ["tolerance", "j.json"],
]


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _with_larmor(folder: Path, larmor: object) -> Path:
    data = json.loads(json.dumps(SMALL_DESIGN))
    data["larmor"] = larmor
    path = folder / "j.json"
    path.write_text(json.dumps(data))
    return path


def _refused(argv: list[str], command: str, capsys, folder: Path) -> str:
    before = snapshot(folder)
    code, _, err = run_cli(argv, capsys)
    line = assert_clean_error(code, err, command)
    assert snapshot(folder) == before, f"{argv}: wrote or changed files"
    return line


@pytest.mark.parametrize("argv", READERS, ids=lambda a: a[0])
@pytest.mark.parametrize(
    ("larmor", "named"),
    [
        # a rate other than parameters.n (0.7): silently ignored by a charges body (check,
        # export, simulate, tolerance exited 0), and a frame body's axes turned at it
        ({"reading": "charges", "rate": 5.0}, "differs from parameters.n = 0.7"),
        ({"reading": "frame", "rate": 123.0}, "differs from parameters.n = 0.7"),
        # outside n's own range: check exited 1, export and tolerance 0, simulate failed in
        # the integrator ("stopped near t = nan")
        ({"reading": "frame", "rate": 1e200}, "1e-08 <= |x| <= 1e+08"),
    ],
)
def test_larmor_rate_is_the_theorems_n(
    argv: list[str], larmor: dict[str, object], named: str, work: Path, capsys
) -> None:
    _with_larmor(work, larmor)
    line = _refused(argv, argv[0], capsys, work)
    assert "larmor.rate" in line and named in line, line


def test_a_larmor_rate_equal_to_n_is_read(work: Path, capsys) -> None:
    """The refusal is of the mismatch only: the same file with rate = n passes check."""
    _with_larmor(work, {"reading": "charges", "rate": 0.7})
    code, out, err = run_cli(["check", "j.json"], capsys)
    assert code == 0 and not err, err
    assert "larmor reading: charges (rate 0.7 1/s)" in out


@pytest.mark.parametrize(
    "option", ["--chi-relative", "--density-relative", "--magnetisation-relative"]
)
@pytest.mark.parametrize("value", ["1", "-0.5", "nan", "1e400"])
def test_material_error_options_have_their_range(
    option: str, value: str, work: Path, capsys
) -> None:
    design = work / "design.json"
    design.write_text(json.dumps(SMALL_DESIGN))
    line = _refused(
        ["tolerance", "design.json", option, value, "--out", "o"], "tolerance", capsys, work
    )
    assert option in line, line
    assert "[0, 1)" in line or "finite" in line, line
