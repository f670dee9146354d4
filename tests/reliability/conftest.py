"""Fixtures of the reliability tests; their helpers live in reliability_support.py."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from reliability_support import SMALL_DESIGN


@pytest.fixture
def design_file(tmp_path: Path):
    """Write a design.json built from SMALL_DESIGN with changes; returns its path."""

    def make(name: str = "design.json", text: str | None = None, **changes: object) -> Path:
        data = json.loads(json.dumps(SMALL_DESIGN))
        data.update(changes)
        path = tmp_path / name
        path.write_text(text if text is not None else json.dumps(data))
        return path

    return make


@pytest.fixture(scope="session")
def case_design(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """design.json of the Kowalevski example scene (designed once per session), as a dict."""
    from case_scene import EXAMPLE

    from chargedesign.cli import main

    out = tmp_path_factory.mktemp("case_design") / "out"
    assert main(["design", str(EXAMPLE), "--out", str(out), "--no-picture"]) == 0
    return json.loads((out / "design.json").read_text())
