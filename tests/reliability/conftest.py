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
