"""Requirements: the drift each sensor grade gives at each control rate, and what meets the
target.

For every control rate the runs of all gyro grades (``requirement_seeds`` noise seeds each)
go together in one batch, with the scene's command, attitude sensor and wheels and without
disturbances (the balance and the drag they allow are read from the linear response,
:mod:`.balance`: each alone may use the whole target). A setting
meets the target when the largest drift over its seeds is within ``target_I4_drift``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import LoopSettings, run_loop
from chargedesign.scene.keys import KEY


@dataclass(frozen=True)
class Requirements:
    """Drift (largest over seeds) per grade and rate, and the lowest rate meeting the target.

    Attributes
    ----------
    rates_Hz : tuple of float
    grades : tuple of str
    drift : ndarray, shape (grades, rates)
    delays_s : tuple of float
        The delay used at each rate (the scene's, at most half a period).
    lowest_rate_Hz : dict
        grade -> the lowest rate whose drift is within the target, or None.
    """

    rates_Hz: tuple[float, ...]
    grades: tuple[str, ...]
    drift: np.ndarray
    delays_s: tuple[float, ...]
    lowest_rate_Hz: dict[str, float | None]
    target: float

    def to_dict(self) -> dict:
        return {
            KEY.target_I4_drift: self.target,
            "rates_Hz": list(self.rates_Hz),
            "delays_s": list(self.delays_s),
            "I4_relative_drift": {g: self.drift[i].tolist() for i, g in enumerate(self.grades)},
            "lowest_rate_Hz": dict(self.lowest_rate_Hz),
        }


def requirements(
    plant: Plant,
    x0: np.ndarray,
    base: LoopSettings,
    grades: dict[str, tuple[float, float]],
    rates: tuple[float, ...],
    seeds: int,
    target: float,
    seed: int = 1,
    tally: Callable[[int], None] | None = None,
) -> Requirements:
    """Run every grade at every rate (see the module docstring); ``tally(k)`` is told the
    ``k`` runs each rate adds."""
    names = tuple(grades)
    arw = np.repeat([grades[g][0] for g in names], seeds)
    bias = np.repeat([grades[g][1] for g in names], seeds)
    drift = np.empty((len(names), len(rates)))
    delays = []
    for j, rate in enumerate(rates):
        delay = min(base.delay_s, 0.5 / rate)
        delays.append(delay)
        settings = replace(
            base, rate_Hz=rate, delay_s=delay, gyro_arw=arw, gyro_bias=bias, imbalance_m=0.0
        )
        run = run_loop(plant, x0, settings, runs=len(arw), seed=seed + j)
        drift[:, j] = run.I4_drift.reshape(len(names), seeds).max(axis=1)
        if tally is not None:
            tally(len(arw))
    lowest: dict[str, float | None] = {}
    for i, g in enumerate(names):
        ok = np.flatnonzero(drift[i] <= target)
        lowest[g] = float(rates[ok[0]]) if ok.size else None
    return Requirements(tuple(rates), names, drift, tuple(delays), lowest, target)


__all__ = ["Requirements", "requirements"]
