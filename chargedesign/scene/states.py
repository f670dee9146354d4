"""Sets of initial states read from a scene (``initial.states``) or a file (``initial.file``).

Light on purpose (no integrator): :mod:`chargedesign.scene.simulation` reads a scene's ``[initial]``
table with it and :mod:`chargedesign.simulation.ensemble` runs the states.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.validation import input_error

STATE_COLUMNS = ("p", "q", "r", "gamma1", "gamma2", "gamma3")


def parse_states(value: Any, where: str = "initial.states") -> np.ndarray:
    """A set of initial states ``(p, q, r, gamma1, gamma2, gamma3)``, ndarray shape (m, 6).

    Rejects bools, non-numbers, non-finite numbers, rows of the wrong length and zero gamma,
    naming the key and the row.
    """
    if isinstance(value, np.ndarray):
        rows: Any = value.tolist() if value.ndim == 2 else None
    else:
        rows = value
    if isinstance(rows, (str, bytes)) or not isinstance(rows, Sequence) or len(rows) == 0:
        raise input_error(
            where, "a non-empty list of [p, q, r, gamma1, gamma2, gamma3] rows", value
        )
    out = np.empty((len(rows), 6))
    for i, row in enumerate(rows):
        name = f"{where}[{i}]"
        if isinstance(row, (str, bytes)) or not isinstance(row, Sequence) or len(row) != 6:
            raise input_error(name, "6 numbers [p, q, r, gamma1, gamma2, gamma3]", row)
        for j, x in enumerate(row):
            if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.number)):
                raise input_error(f"{name}[{j}]", "a number", x)
            if not np.isfinite(float(x)):
                raise input_error(f"{name}[{j}]", "a finite number", x)
            out[i, j] = float(x)
        if float(np.linalg.norm(out[i, 3:])) < 1e-12:
            raise input_error(name, "a non-zero gamma", row)
    return out


def load_states(path: str | os.PathLike[str], where: str = "initial.file") -> np.ndarray:
    """Initial states from a ``.npy`` (m, 6) or ``.csv`` file (6 columns, optional header)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{where}: no such file {str(p)!r}")
    suffix = p.suffix.lower()
    if suffix == ".npy":
        try:
            arr = np.load(p, allow_pickle=False)
        except (ValueError, OSError) as exc:
            raise InputError(f"{where}: cannot read {str(p)!r} as .npy ({exc})") from exc
        if arr.dtype == bool or arr.ndim != 2:
            raise input_error(where, "an (m, 6) array of numbers", f"{arr.dtype} {arr.shape}")
        return parse_states(arr.astype(float) if arr.dtype.kind in "iuf" else arr, where)
    if suffix == ".csv":
        text = p.read_text(encoding="utf-8")
        rows = [r for r in csv.reader(io.StringIO(text)) if r and any(c.strip() for c in r)]
        if rows and [c.strip() for c in rows[0]] == list(STATE_COLUMNS):
            rows = rows[1:]
        values: list[list[float]] = []
        for i, row in enumerate(rows):
            parsed = []
            for j, cell in enumerate(row):
                c = cell.strip()
                try:  # float() refuses true and false too
                    parsed.append(float(c))
                except ValueError as exc:
                    raise input_error(f"{where} row {i + 1} column {j + 1}", "a number", c) from exc
            values.append(parsed)
        return parse_states(values, where)
    raise input_error(where, "a .csv or .npy file", str(p))
