"""One validation helper for every array or number a user hands in.

Every error uses the same template, ``"<name>: expected <what>, got <received>"``, raised as
:class:`~chargedesign.errors.InputError` (a ``ValueError``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from chargedesign.errors import InputError


def _describe(value: Any) -> str:
    if isinstance(value, np.ndarray):
        return f"array of shape {value.shape} and dtype {value.dtype}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def input_error(name: str, expected: str, received: Any) -> InputError:
    """Build the one error message template: names the input and what was received."""
    return InputError(f"{name}: expected {expected}, got {_describe(received)}")


def as_finite_float(value: Any, name: str, *, positive: bool = False) -> float:
    """Return ``value`` as a finite float (bools and strings are rejected)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise input_error(name, "a real number", value)
    out = float(value)
    if not math.isfinite(out):
        raise input_error(name, "a finite number", value)
    if positive and out <= 0.0:
        raise input_error(name, "a number > 0", value)
    return out


def as_array(value: Any, name: str, shape: Sequence[int | None]) -> np.ndarray:
    """Return ``value`` as a finite float64 array of the given shape (None: any length).

    Shape and finiteness are checked before any reshaping, so a wrong input is named as
    it was received.
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise input_error(name, f"numbers of shape {_shape_text(shape)}", value) from exc
    if arr.ndim != len(shape) or any(
        s is not None and a != s for a, s in zip(arr.shape, shape, strict=True)
    ):
        raise input_error(name, f"shape {_shape_text(shape)}", arr)
    if not np.all(np.isfinite(arr)):
        raise input_error(name, "finite numbers (no NaN or inf)", arr)
    return arr


def as_points(value: Any, name: str = "positions", n: int | None = None) -> np.ndarray:
    """Points as ``ndarray, shape (n, 3)``, float64, finite. An empty list gives shape (0, 3)."""
    if isinstance(value, (list, tuple)) and len(value) == 0:
        value = np.zeros((0, 3))
    return as_array(value, name, (n, 3))


def as_weights(value: Any, name: str = "values", n: int | None = None) -> np.ndarray:
    """Weights as ``ndarray, shape (n,)``, float64, finite."""
    return as_array(value, name, (n,))


def _shape_text(shape: Sequence[int | None]) -> str:
    return (
        "("
        + ", ".join("n" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )
