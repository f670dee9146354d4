"""A file never makes the tool import or run code it names (issue 22, finding 1).

A sweep file's ``command`` is compared with the built-in registry's names and nothing else:
``module:function`` is refused before anything is imported, so a colleague's sweep file is
data, not a program. A function of one's own runs only when passed as an object from Python.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from reliability_support import run_cli, snapshot

from chargedesign.errors import InputError
from chargedesign.sweeps import COMMANDS, load_sweep, run_sweep, sweep_from_dict
from chargedesign.sweeps.registry import resolve

#: names a hostile or careless sweep file might give; none may be imported or called
HOSTILE = [
    "shutil:rmtree",
    "this:x",
    "os:system",
    "builtins:eval",
    "subprocess:run",
    "chargedesign.files:write_text_atomic",
    "sweep_trap:boom",
    "sweep_trap",
    "../sweep_trap:boom",
]


@pytest.fixture
def trap(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An importable module that leaves a marker file if it is ever imported."""
    marker = tmp_path / "imported"
    package = tmp_path / "trap_path"
    package.mkdir()
    (package / "sweep_trap.py").write_text(
        f"from pathlib import Path\nPath({str(marker)!r}).write_text('imported')\n"
        "def boom(*args, **kwargs):\n    return {}\n"
    )
    monkeypatch.syspath_prepend(str(package))
    sys.modules.pop("sweep_trap", None)
    return marker


@pytest.mark.parametrize("command", HOSTILE)
def test_a_sweep_file_naming_code_is_refused_before_anything_is_imported(
    command: str, tmp_path: Path, trap: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sweep = tmp_path / "hostile.toml"
    sweep.write_text(f'command = "{command}"\n[grid]\n"parameters.n" = [0.5]\n')
    before_modules = set(sys.modules)
    before_files = snapshot(tmp_path)
    code, _out, err = run_cli(["sweep", str(sweep), "--out", str(tmp_path / "out")], capsys)
    assert code == 2
    line = err.strip()
    assert "\n" not in line and "Traceback" not in line
    assert "unknown command" in line and repr(command) in line
    assert not trap.exists()  # the trap module was never imported
    assert "this" not in set(sys.modules) - before_modules
    assert "sweep_trap" not in sys.modules
    assert not (tmp_path / "out").exists()
    assert snapshot(tmp_path) == before_files


@pytest.mark.parametrize("command", HOSTILE)
def test_the_library_refuses_the_same_names(command: str, trap: Path) -> None:
    with pytest.raises(InputError, match="unknown command"):
        sweep_from_dict({"command": command, "grid": {"parameters.n": [0.5]}})
    with pytest.raises(InputError, match="not a built-in command"):
        resolve(command)
    assert not trap.exists()


def test_a_module_colon_name_gets_the_python_route_in_its_message() -> None:
    with pytest.raises(InputError, match=r"command=function"):
        sweep_from_dict({"command": "shutil:rmtree", "grid": {"parameters.n": [0.5]}})


def test_builtin_commands_still_resolve_by_name() -> None:
    for name, function in COMMANDS.items():
        assert resolve(name) is function


def _quarter(scene, point_dir: Path) -> dict[str, float]:
    return {"n_quarter": scene.parameters.n / 4.0}


def test_a_function_of_ones_own_runs_when_passed_from_python(tmp_path: Path) -> None:
    sweep = tmp_path / "own.toml"
    sweep.write_text('[grid]\n"parameters.n" = [0.5, 1.0]\n')
    result = run_sweep(load_sweep(sweep, command=_quarter), tmp_path / "out")
    assert result.failed == 0 and result.ran == 2
    figures = sorted(r["n_quarter"] for r in result.rows)
    assert figures == [0.125, 0.25]
    plan = (tmp_path / "out" / "sweep.json").read_text()
    assert "python:" in plan and "_quarter" in plan  # a label, never imported back


def test_a_file_naming_a_command_and_a_function_passed_too_is_ambiguous(tmp_path: Path) -> None:
    sweep = tmp_path / "both.toml"
    sweep.write_text('command = "design"\n[grid]\n"parameters.n" = [0.5]\n')
    with pytest.raises(InputError, match="give one of them"):
        load_sweep(sweep, command=_quarter)


def test_a_command_that_is_not_callable_is_refused() -> None:
    with pytest.raises(InputError, match="expected a function"):
        sweep_from_dict({"grid": {"parameters.n": [0.5]}}, command="design")  # type: ignore[arg-type]


def test_the_command_line_imports_only_its_listed_commands() -> None:
    """The one lazy import of the command line takes a listed command name, nothing else."""
    from chargedesign.cli import COMMANDS, command_module
    from chargedesign.errors import InputError

    assert command_module("verify").__name__ == "chargedesign.commands.verify"
    for name in ("arguments", "os", "..sweeps", "verify.sys"):
        assert name not in COMMANDS
        with pytest.raises(InputError, match="command: one of"):
            command_module(name)
