"""The tolerance analysis' defaults and the small helpers its modules share (JSON values,
quantiles).

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

import numpy as np

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
