"""The documentation's picture generators (tools/make_gallery.py, tools/bifurcation_gallery.py)
run to the end and write their pictures. They take about a minute together, so they run with
`make test-slow`; the pictures they made are checked by tests/docs (docs/images)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("tool", "pictures"),
    [("make_gallery.py", "gallery_*.png"), ("bifurcation_gallery.py", "bifurcation_*.png")],
)
def test_the_gallery_tools_write_their_pictures(tool: str, pictures: str, tmp_path: Path) -> None:
    env = {**os.environ, "MPLBACKEND": "Agg", "PYVISTA_OFF_SCREEN": "true"}
    run = subprocess.run(
        [sys.executable, str(ROOT / "tools" / tool), str(tmp_path)],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-3000:]
    assert sorted(tmp_path.glob(pictures)), f"{tool} wrote no {pictures}"
