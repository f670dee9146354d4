"""The tolerance analysis' defaults and the small helpers its modules share (JSON values,
quantiles, the count of perturbed bodies).

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from chargedesign.limits import MAX_TOLERANCE_SAMPLES
from chargedesign.validation import input_error

#: element kinds, in report order
KINDS = ("charge", "dipole", "mass")
DEFAULT_TARGET = 1e-4
DEFAULT_LEVELS = (0.01, 0.1, 1.0)
#: integration tolerances of the ensemble (the nominal body's own drift is the floor)
DEFAULT_RTOL = 1e-10
DEFAULT_T_END = 100.0
DEFAULT_MATERIAL_SAMPLES = 200


def quantile_summary(x: np.ndarray) -> dict[str, float]:
    """Median, p90, max and mean of ``x`` (``{}`` when empty)."""
    x = np.asarray(x, float)
    if x.size == 0:
        return {}
    return {
        "median": float(np.median(x)),
        "p90": float(np.quantile(x, 0.9)),
        "max": float(x.max()),
        "mean": float(x.mean()),
    }


def sample_count(value: Any, name: str, minimum: int) -> int:
    """``value`` as an int in ``minimum .. MAX_TOLERANCE_SAMPLES`` (else an input error
    naming ``name``): the tolerance analysis' perturbed bodies."""
    expected = f"an integer in {minimum}..{MAX_TOLERANCE_SAMPLES}"
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise input_error(name, expected, value)
    if not minimum <= int(value) <= MAX_TOLERANCE_SAMPLES:
        raise input_error(name, expected, value)
    return int(value)
