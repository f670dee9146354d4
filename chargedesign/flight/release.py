"""The release: a start on I3 = 0 in a named chamber of the diagram, and its tolerance.

The start: the diagram of the theorem's parameters in closed form
(:class:`chargedesign.topology.closed_form.ClosedForm`, branches ``k = ((h - h_j)/C)^2``)
names its cells by their walls; the start takes the thickest cell (the one whose tori lie
furthest from every critical value, relative to the energy spread) among those whose motion
makes at least :data:`~chargedesign.physical.support.MIN_TURNS` turns within the flight, at
the cell's middle ``(h, k)``: a state on ``H = h, I4 = k, I3 = 0, |gamma| = 1`` from the
level's sampled conics (:class:`chargedesign.topology.chambers.LevelSampler`). A turn is
``2 pi`` of rotation angle (``int |omega| dt``).

The tolerance: the released omega errs by ``epsilon |omega|`` in a random direction, so I3
is no longer 0 and I4 is no longer an integral; each released state is integrated over the
flight by the flow counting's route (:func:`chargedesign.topology.chambers.propagate`: heyoka's
ensemble, DOP853 without heyoka) and its I4 drift ``max |I4(t) - I4(0)| / |I4(0)|`` recorded. The
drift is linear in the error for small errors: the largest error that keeps the drift below
``target`` is ``target / slope``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.formatting import CELL, ROUGH, fmt
from chargedesign.params import Parameters
from chargedesign.physical.support import MIN_TURNS
from chargedesign.simulation.system import theorem_i4
from chargedesign.topology.chambers import LevelSampler, LevelSampling, propagate
from chargedesign.topology.closed_form import ClosedForm
from chargedesign.topology.equations import MomentumMap

#: the I4 drift a release keeps over the flight (0.1 %)
TARGET_DRIFT = 1e-3
#: relative errors of the released omega the tolerance is measured at
RELEASE_ERRORS = (1e-4, 1e-3, 1e-2)
#: random directions of the error per size (seeded)
DIRECTIONS = 6
#: output samples per second of flight
SAMPLES_PER_S = 200.0
#: how far above the top critical energy the cells are looked for, in energy spreads
ENERGY_SPAN = 3.0


@dataclass
class Start:
    """A released state on I3 = 0: ``state`` (p, q, r, gamma1..3), its ``(h, k)``, the cell
    it lies in (its walls' names, chamber index, energy range, thickness), and the turns of
    its motion within ``flight_s``."""

    state: np.ndarray
    h: float
    k: float
    walls: tuple[str, str]
    chamber: int
    energy_range: tuple[float, float]
    thickness: float
    flight_s: float
    turns: float

    @property
    def name(self) -> str:
        return f"chamber {self.chamber}: between {self.walls[0]} and {self.walls[1]}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "state": [float(v) for v in self.state],
            "h_J": self.h,
            "k_per_s4": self.k,
            "chamber": self.chamber,
            "walls": list(self.walls),
            "energy_range_J": list(self.energy_range),
            "thickness": self.thickness,
            "flight_s": self.flight_s,
            "turns": self.turns,
            "name": self.name,
        }


def turns_of(times: np.ndarray, states: np.ndarray) -> np.ndarray:
    """Rotation angle over ``2 pi`` of each trajectory (m, T, 6): ``int |omega| dt / 2 pi``."""
    speed = np.linalg.norm(states[..., :3], axis=2)
    return np.trapezoid(speed, times, axis=1) / (2.0 * math.pi)


def i4_drift(params: Parameters, states: np.ndarray) -> np.ndarray:
    """``max_t |I4(t) - I4(0)| / |I4(0)|`` of each trajectory (m, T, 6), shape (m,)."""
    i4 = theorem_i4(states.reshape(-1, 6), params).reshape(states.shape[:2])
    return np.max(np.abs(i4 - i4[:, :1]), axis=1) / np.abs(i4[:, 0])


def _state_on(F: MomentumMap, h: float, k: float) -> np.ndarray | None:
    """One state of the level ``H = h, I4 = k`` on I3 = 0 (None: the sampling found none)."""
    sampler = LevelSampler(F, h, LevelSampling(gammas=600, angles=96))
    points = sampler.points(k)
    if not len(points):
        return None
    x = points[0] * np.array([sampler.omega_scale] * 3 + [1.0] * 3)
    x[3:] /= np.linalg.norm(x[3:])
    return x


def release_start(params: Parameters, flight_s: float, min_turns: float = MIN_TURNS) -> Start:
    """The start of the flight: the thickest cell of the diagram whose motion makes at least
    ``min_turns`` turns in ``flight_s`` (s), at its middle ``(h, k)``.

    Raises
    ------
    ValueError
        No cell of the diagram (up to :data:`ENERGY_SPAN` spreads above the top critical
        energy) has a motion that turns ``min_turns`` times within the flight.
    """
    F = MomentumMap(params)
    closed = ClosedForm.of(params)
    lo = closed.h_min
    hi = max(closed.energies) + ENERGY_SPAN * closed.energy_scale
    samples = max(int(SAMPLES_PER_S * flight_s), 50)
    for cell in sorted(closed.cells(lo, hi), key=lambda c: -c.thickness):
        x = _state_on(F, cell.h, cell.k)
        if x is None:
            continue
        times, states, _ = propagate(params, x[None, :], flight_s, samples)
        turns = float(turns_of(times, states)[0])
        if turns >= min_turns:
            return Start(
                x,
                cell.h,
                cell.k,
                cell.walls,
                cell.chamber,
                (cell.a, cell.b),
                cell.thickness,
                flight_s,
                turns,
            )
    raise ValueError(
        f"no chamber of the diagram turns {fmt(min_turns)} times in {fmt(flight_s)} s: the "
        "body is too slow for the flight (a larger time rate)"
    )


def perturbed(start: np.ndarray, error: float, count: int, seed: int = 0) -> np.ndarray:
    """``count`` copies of ``start`` (6,) whose omega errs by ``error |omega|`` in random
    directions (seeded), shape (count, 6)."""
    rng = np.random.default_rng(seed)
    directions = rng.normal(size=(count, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    out = np.repeat(start[None, :], count, axis=0)
    out[:, :3] += error * np.linalg.norm(start[:3]) * directions
    return out


@dataclass
class ReleaseTolerance:
    """How an error in the released omega moves I4 over the flight: per relative error, the
    I3 it gives (over ``C |omega|``) and the largest I4 drift over its directions; the slope
    ``drift / error`` (the largest at the smallest error) and the largest error that keeps the
    drift below ``target``."""

    errors: list[float]
    i3_relative: list[float]
    drifts: list[float]
    slope: float
    target: float
    nominal_drift: float
    flight_s: float

    @property
    def largest_error(self) -> float:
        return self.target / self.slope if self.slope > 0 else math.inf

    def to_dict(self) -> dict[str, Any]:
        return {
            "errors": self.errors,
            "I3_over_C_omega": self.i3_relative,
            "I4_drifts": self.drifts,
            "slope": self.slope,
            "target_I4_drift": self.target,
            "largest_omega_error": self.largest_error,
            "nominal_I4_drift": self.nominal_drift,
            "flight_s": self.flight_s,
        }

    def __str__(self) -> str:
        rows = ", ".join(
            f"{fmt(e, CELL)}: I3 {fmt(i, ROUGH)}, I4 drift {fmt(d, ROUGH)}"
            for e, i, d in zip(self.errors, self.i3_relative, self.drifts, strict=True)
        )
        return (
            f"release tolerance over {fmt(self.flight_s)} s: an error of epsilon |omega| in the "
            f"released omega drifts I4 by about {fmt(self.slope, ROUGH)} epsilon ({rows}); "
            f"I4 kept to {fmt(self.target, CELL)} needs epsilon <= "
            f"{fmt(self.largest_error, ROUGH)} (the exact release drifts "
            f"{fmt(self.nominal_drift, ROUGH)})"
        )


def release_tolerance(
    params: Parameters,
    start: Start,
    *,
    errors: tuple[float, ...] = RELEASE_ERRORS,
    directions: int = DIRECTIONS,
    target: float = TARGET_DRIFT,
    seed: int = 0,
) -> ReleaseTolerance:
    """The I4 drift over the flight of releases whose omega errs by each of ``errors`` (relative
    to ``|omega|``) in ``directions`` random directions, from ``start``."""
    F = MomentumMap(params)
    samples = max(int(SAMPLES_PER_S * start.flight_s), 50)
    starts = np.concatenate(
        [start.state[None, :]]
        + [perturbed(start.state, e, directions, seed + i) for i, e in enumerate(errors)]
    )
    _, states, _ = propagate(params, starts, start.flight_s, samples)
    drift = i4_drift(params, states)
    scale = params.C * float(np.linalg.norm(start.state[:3]))
    i3 = np.abs(F.values(starts)[:, 3]) / scale
    out_i3, out_d = [], []
    for i in range(len(errors)):
        rows = slice(1 + i * directions, 1 + (i + 1) * directions)
        out_i3.append(float(np.max(i3[rows])))
        out_d.append(float(np.max(drift[rows])))
    slope = out_d[0] / errors[0]
    return ReleaseTolerance(
        list(errors), out_i3, out_d, slope, target, float(drift[0]), start.flight_s
    )
