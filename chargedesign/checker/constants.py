"""Tolerances, rounding constants and the names of the compared quantities.

Part of :mod:`chargedesign.checker` (see its docstring for the method).
"""

from __future__ import annotations

import numpy as np

from chargedesign.vocabulary import (
    CHECK_DEFAULT_ORIENTATIONS,
    CHECK_DEFAULT_TOL,
)

DEFAULT_TOL = CHECK_DEFAULT_TOL
DEFAULT_ORIENTATIONS = CHECK_DEFAULT_ORIENTATIONS
#: per-effect route agreement (informational) is skipped for an effect whose rounding floor
#: (its torque against its gross contributions) exceeds this (it would only measure rounding)
NOISE_FLOOR = 1e-6
#: unit roundoff of double precision
EPS = float(np.finfo(np.float64).eps)
#: rounding floor of an evaluation = ROUNDING_FACTOR * (unit * cancellation + EPS), the
#: cancellation measured with :func:`contribution_sizes`; the largest error measured (double
#: against double-double, 154 bodies, fields of degree up to 8) is 5.3 in these units, 2.1
#: with fields of degree <= 4 (docs/check.md)
ROUNDING_FACTOR = 32.0
#: ``precision="auto"`` evaluates in double-double when a claimed quantity's double-precision
#: rounding floor exceeds this fraction of the tolerance
ACCURATE_FRACTION = 0.01
#: element-orientation pairs per vectorised block (its temporaries then stay in the L2 cache)
BLOCK_PAIRS = 1 << 13

#: quantity -> the design claim (``realises`` item) that makes it a pass/fail check
QUANTITY_CLAIMS = {
    "mu": "mu",
    "gyroscopic_torque": "mu",
    "V": "V",
    "potential_torque": "V",
    "inertia": "inertia",
}
