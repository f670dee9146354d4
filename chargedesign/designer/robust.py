"""The robust objective's costs: each candidate priced by its first-order placement sensitivity.

``objective = "robust"`` minimises ``sum_j cost_j |w_j|`` (``||sigma_j||`` for dipoles) with
``cost_j = (1 - beta) + beta c_j / mean(c)``: ``c_j`` is the worst-case relative error of mu,
V or the inertia that a unit element at candidate j adds per metre of placement error
(:func:`chargedesign.sensitivity.sensitivity_weights`), ``beta`` is ``[design] robust_weight``.
With ``beta = 1`` the optimum is the body whose first-order error bound
``sum_j c_j |w_j| |delta|`` is least among those that meet the conditions: the one that
tolerates the largest placement errors. ``beta = 0`` is the plain (sparse) l1 design.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from chargedesign.sensitivity import sensitivity_weights

#: smallest relative cost: a candidate whose placement no condition sees (c_j = 0) stays priced
COST_FLOOR = 1e-3


def robust_costs(
    points: np.ndarray,
    source: str,
    fields: Mapping[str, Sequence[float]],
    parameters: Any,
    beta: float,
) -> np.ndarray:
    """Per-candidate costs of the robust objective (mean 1 when ``beta = 1``), shape (n,)."""
    c = sensitivity_weights(points, source, fields, parameters)
    mean = float(np.mean(c)) if len(c) else 0.0
    if not np.all(np.isfinite(c)) or mean <= 0.0:
        return np.ones(len(points))  # no placement sensitivity: every place costs the same
    return (1.0 - beta) + beta * np.maximum(c / mean, COST_FLOOR)


def weighted_norm(weights: np.ndarray, costs: np.ndarray) -> float:
    """``sum_j cost_j |w_j|`` (rows' Euclidean norms for dipoles)."""
    mags = np.linalg.norm(weights, axis=1) if weights.ndim == 2 else np.abs(weights)
    return float(np.sum(costs * mags))
