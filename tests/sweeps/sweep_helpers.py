"""Sweep commands for the tests (passed as command= from Python; importable by spawned workers)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path
from typing import Any


def square(
    scene: Any, point_dir: Path, marker: str = "", kill: float = -1.0, sleep: float = 0.0
) -> dict[str, Any]:
    """Figures from the scene's parameter n; the point with n == kill kills its own worker
    the first time (a marker file records that it did)."""
    n = scene.parameters.n
    if n == kill and marker and not Path(marker).exists():
        Path(marker).write_text("killed")
        os.kill(os.getpid(), signal.SIGKILL)
    if n < 0:
        raise ValueError("n must be >= 0 here\nsecond line")
    time.sleep(sleep)
    (point_dir / "note.txt").write_text(f"{n}\n")
    return {"n2": n * n, "label": f"n={n}"}


def interrupt_at(scene: Any, point_dir: Path, at: float = -1.0, marker: str = "") -> dict[str, Any]:
    """Raise KeyboardInterrupt (as Ctrl-C would) at the point with n == at, once."""
    n = scene.parameters.n
    if n == at and marker and not Path(marker).exists():
        Path(marker).write_text("interrupted")
        raise KeyboardInterrupt
    (point_dir / "note.txt").write_text(f"{n}\n")
    return {"n2": n * n}
