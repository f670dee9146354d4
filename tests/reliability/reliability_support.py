"""Shared helpers of the reliability tests (imported by name: a module called conftest
would be ambiguous beside the other test folders' conftest files)."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest

from chargedesign.cli import main

#: a small scene that designs in a few seconds (ball of 123 lattice points)
SMALL_SCENE = """\
[parameters]
C = 1.0
c = 0.3
d = -0.4
n = 0.7
K = 0.5
kappa = 0.9

[fields.magnetic]
a1 = 1.0
a2 = 0.5

[body]
shape = "ball"
radius = 1.0
spacing = 0.34
"""

#: a theorem-only scene that simulates in about a second (no design, no JIT): the small
#: scene's parameters and field, without its body
THEOREM_SCENE = (
    SMALL_SCENE.split("[body]")[0]
    + """[simulation]
effects = ["theorem"]
t_end = 1.0
samples = 11
method = "DOP853"
"""
)

#: a valid design.json (one charge, one mass, one dipole; realises nothing, so check passes)
SMALL_DESIGN = {
    "format": "chargedesign.design/1",
    "parameters": {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9},
    "fields": {"magnetic": {"legendre": [1.0, 1.0]}, "electric": {"legendre": [0.0, 0.0, 1.0]}},
    "charges": {"positions": [[0.0, 0.0, 1.0]], "values": [-0.8]},
    "masses": {"positions": [[0.5, 0.0, 0.0]], "values": [0.1]},
    "dipoles": {"positions": [[0.0, 0.5, 0.0]], "moments": [[0.0, 0.0, 0.2]]},
    "realises": [],
}


def snapshot(folder: Path) -> dict[str, str]:
    """Every entry under ``folder`` (hidden ones too) with the hash of its content."""
    out: dict[str, str] = {}
    if not folder.exists():
        return out
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            out[os.path.relpath(os.path.join(root, name), folder) + "/"] = "dir"
        for name in files:
            path = os.path.join(root, name)
            out[os.path.relpath(path, folder)] = hashlib.sha256(Path(path).read_bytes()).hexdigest()
    return out


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """Run the CLI in-process; any exception escaping it fails the test (a traceback)."""
    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_clean_error(code: int, err: str, command: str) -> str:
    """Exit 2 with exactly one line ``chargedesign COMMAND: error: ...`` and no traceback."""
    assert code == 2, err
    lines = [line for line in err.splitlines() if line.strip()]
    errors = [line for line in lines if f"chargedesign {command}: error:" in line]
    assert len(errors) == 1, err
    assert "Traceback" not in err, err
    return errors[0]


def design_json(folder: Path, name: str = "design.json", **changes: object) -> Path:
    """Write SMALL_DESIGN with ``changes`` (a value of None removes its key) into ``folder``."""
    data = json.loads(json.dumps(SMALL_DESIGN))
    data.update(changes)
    for key in [k for k, v in changes.items() if v is None]:
        del data[key]
    path = folder / name
    path.write_text(json.dumps(data))
    return path


def refused(argv: list[str], command: str, capsys, folder: Path) -> str:
    """Run ``argv``; assert one error line and that ``folder`` is unchanged; the line."""
    before = snapshot(folder)
    code, _, err = run_cli(argv, capsys)
    line = assert_clean_error(code, err, command)
    assert snapshot(folder) == before, f"{argv}: wrote or changed files"
    return line
