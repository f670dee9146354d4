"""The raw output of one integration, shared by every back end (:mod:`.integrate` for
solve_ivp and Gauss-Legendre, :mod:`.taylor` for heyoka)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class Integration:
    """Raw output of one integration (m trajectories, T samples).

    Attributes
    ----------
    times : ndarray, shape (T,)
        Sample times, s.
    states : ndarray, shape (m, T, 7)
        ``(p, q, r, w, x, y, z)`` at each sample.
    events : list of dict
        Terminal and other events (``kind``, ``t``, ``trajectory``, ...).
    poincare : ndarray, shape (k, 7) or None
        ``(t, p, q, r, gamma1, gamma2, gamma3)`` at each section crossing (one trajectory).
    steps : int
        Accepted steps.
    rhs_evaluations : int
        Right-hand side calls (each for all m trajectories).
    seconds : float
        Wall time of the integration.
    """

    times: np.ndarray
    states: np.ndarray
    events: list[dict[str, Any]] = field(default_factory=list)
    poincare: np.ndarray | None = None
    steps: int = 0
    rhs_evaluations: int = 0
    seconds: float = 0.0
    #: back-end details (the taylor method: compile seconds, whether the compiled code was reused)
    extra: dict[str, Any] = field(default_factory=dict)


def singular_plane_event(
    t: float, trajectory: int, gamma3: float | None, threshold: float | None, **more: Any
) -> dict[str, Any]:
    """The terminal event of every back end: trajectory ``trajectory`` reached
    ``|gamma3| < threshold`` at time ``t`` (s); ``gamma3`` there (None: not recorded) and
    ``more`` (e.g. ``located``, ``stops``) as written."""
    event: dict[str, Any] = {"kind": "singular_plane", "t": t, "trajectory": trajectory}
    if gamma3 is not None:
        event["gamma3"] = gamma3
    return event | {"threshold": threshold, "terminal": True} | more
