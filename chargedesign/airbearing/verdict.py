"""Requirements against the state of the art, the verdict, and the feasibility window.

Every requirement is a :class:`Requirement` (the contract's ``state_of_the_art[]`` entry):
``tolerance`` (a largest allowed error: met when ``best <= required``) or ``capacity`` (a
largest available figure: met when ``required <= best``). The verdict is "buildable" only when
every requirement is met and the nominal Monte Carlo's median drift (every effect on) is at
most the target; otherwise it names the requirement missed by the largest factor.

The window (:func:`window`) scales the design in time (rate s: the theorem's n, K x s,
kappa x s^2, the motion s times faster) and in size (L: every length x L, masses x L^3 at the
same densities, C x L^5) and reads each requirement's scaling from its physics:

| requirement | required | best |
| --- | --- | --- |
| centre-of-mass offset | x s^2 L^2 (torque C s^2 over weight M g) | mounts x L^2, rest fixed |
| bearing drag | x s L^5 (C s) | x L^4 (Couette, ball radius x L) |
| room air torque | x s^2 L^5 (M g x offset) | x L^3 |
| wheel torque, momentum | x s^2 L^5, x s L^5 | fixed (catalogue) |
| bearing load | x L^3 | fixed |
| loop rate | x s | fixed |

The tilt does not change (the same motion, faster or larger). The nominal drift is measured at
the scene's design only; the window says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.formatting import PLAIN, fmt

#: how each requirement's (required, best) scale with (s, L): exponents of s and L
SCALING: dict[str, tuple[tuple[float, float], tuple[float, float]]] = {
    "centre_of_mass_offset_m": ((2.0, 2.0), (0.0, 0.0)),
    "bearing_drag_N_m_s": ((1.0, 5.0), (0.0, 4.0)),
    "room_air_torque_N_m": ((2.0, 5.0), (0.0, 3.0)),
    "wheel_torque_N_m": ((2.0, 5.0), (0.0, 0.0)),
    "wheel_momentum_N_m_s": ((1.0, 5.0), (0.0, 0.0)),
    "bearing_load_kg": ((0.0, 3.0), (0.0, 0.0)),
    "loop_rate_Hz": ((1.0, 0.0), (0.0, 0.0)),
    "bearing_tilt_deg": ((0.0, 0.0), (0.0, 0.0)),
    "ball_diameter_m": ((0.0, 1.0), (0.0, 0.0)),
}
#: the grid of the window: time rates and sizes relative to the scene's
RATES = np.logspace(-1.0, 1.0, 41)
SIZES = np.logspace(-0.5, 0.5, 21)


@dataclass(frozen=True)
class Requirement:
    """One requirement: what the design needs, the best reached, and whether it is met."""

    name: str
    kind: str  # tolerance | capacity
    required: float
    best: float
    unit: str
    source: str
    unmet_reason: str = ""  # missed whatever the numbers say (e.g. no rate tried meets it)
    parts: dict[str, float] = field(default_factory=dict)

    @property
    def met(self) -> bool:
        if self.unmet_reason:
            return False
        if self.kind == "tolerance":
            return self.best <= self.required
        return self.required <= self.best

    @property
    def shortfall(self) -> float:
        """How many times the best misses (>= 1 when unmet, < 1 when met)."""
        if self.unmet_reason:
            return np.inf
        if self.kind == "tolerance":
            return self.best / self.required if self.required > 0 else np.inf
        return self.required / self.best if self.best > 0 else np.inf

    def line(self) -> str:
        if self.unmet_reason:
            return f"{self.name}: {self.unmet_reason} [{self.source}]"
        need = "<=" if self.kind == "tolerance" else ">="
        return (
            f"{self.name} needs {need} {fmt(self.required)} {self.unit}, the best reached is "
            f"{fmt(self.best)} {self.unit} [{self.source}]"
        )

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "name": self.name,
            "kind": self.kind,
            "required": self.required,
            "best": self.best,
            "unit": self.unit,
            "source": self.source,
            "met": self.met,
        }
        if self.unmet_reason:
            out["note"] = self.unmet_reason
        if self.parts:
            out["parts"] = self.parts
        return out


@dataclass(frozen=True)
class Verdict:
    buildable: bool
    binding: str | None
    line: str

    def to_dict(self) -> dict[str, Any]:
        return {"buildable": self.buildable, "binding": self.binding, "line": self.line}


def verdict(requirements: list[Requirement], nominal_median: float, target: float) -> Verdict:
    """Buildable only when every requirement is met and the nominal median is within target."""
    unmet = [r for r in requirements if not r.met]
    if not unmet and nominal_median <= target:
        return Verdict(
            True,
            None,
            "buildable: every requirement is met and the nominal Monte "
            f"Carlo's median I4 drift {fmt(nominal_median)} is within the target "
            f"{fmt(target, PLAIN)}",
        )
    if not unmet:  # the drift requirement is in the list; kept for a list without it
        return Verdict(
            False,
            "nominal_I4_drift",
            f"NOT buildable: the nominal median drift "
            f"{fmt(nominal_median)} is above the target {fmt(target, PLAIN)}",
        )
    worst = max(unmet, key=lambda r: r.shortfall)
    return Verdict(False, worst.name, "NOT buildable: " + worst.line())


@dataclass(frozen=True)
class Window:
    """The (rate, size) designs where every scaled requirement is met."""

    rates: np.ndarray
    sizes: np.ndarray
    feasible: np.ndarray  # (rates, sizes) bool
    binding: np.ndarray  # (rates, sizes) the most-missed (or tightest) requirement's index
    names: tuple[str, ...]
    margin: np.ndarray  # (rates, sizes): the worst shortfall (< 1 inside)
    style: str = ""  # the bearing style the requirements are read for

    @property
    def empty(self) -> bool:
        return not bool(self.feasible.any())

    def recommended(self) -> tuple[float, float]:
        """(rate, size) factors: inside, the largest margin; outside, the least shortfall."""
        i, j = np.unravel_index(int(np.argmin(self.margin)), self.margin.shape)
        return float(self.rates[i]), float(self.sizes[j])

    def _edges(self) -> dict[str, Any]:
        """The window along the rate at the scene's size, and the limits at its ends."""
        j = int(np.argmin(np.abs(np.log(self.sizes))))
        inside = np.flatnonzero(self.feasible[:, j])
        if inside.size == 0:
            return {"rate_low": None, "rate_high": None, "binding_low": None, "binding_high": None}
        lo, hi = int(inside[0]), int(inside[-1])
        below = self.names[self.binding[lo - 1, j]] if lo > 0 else "the grid's end"
        above = (
            self.names[self.binding[hi + 1, j]] if hi + 1 < len(self.rates) else "the grid's end"
        )
        return {
            "rate_low": float(self.rates[lo]),
            "rate_high": float(self.rates[hi]),
            "binding_low": below,
            "binding_high": above,
        }

    def to_dict(self) -> dict[str, Any]:
        rate, size = self.recommended()
        i, j = np.unravel_index(int(np.argmin(self.margin)), self.margin.shape)
        out: dict[str, Any] = {
            "bearing": self.style,
            "empty": self.empty,
            "rates": self.rates.tolist(),
            "sizes": self.sizes.tolist(),
            "feasible_points": int(self.feasible.sum()),
            "scene_inside": bool(self._scene_feasible()),
            "recommended": {
                "rate_factor": rate,
                "size_factor": size,
                "worst_shortfall": float(self.margin[i, j]),
                "binding": self.names[self.binding[i, j]],
            },
            "at_scene_size": self._edges(),
            "measured_only_at_the_scene": ["nominal_I4_drift"],
        }
        if self.empty:
            out["missing_factor"] = float(self.margin.min())
        return out

    def _scene_feasible(self) -> bool:
        i = int(np.argmin(np.abs(np.log(self.rates))))
        j = int(np.argmin(np.abs(np.log(self.sizes))))
        return bool(self.feasible[i, j])

    def line(self) -> str:
        d = self.to_dict()
        rec = d["recommended"]
        if self.empty:
            return (
                f"no window ({self.style} bearing): over rates x{fmt(self.rates[0], PLAIN)}"
                f"..x{fmt(self.rates[-1], PLAIN)}"
                f" and sizes x{fmt(self.sizes[0], PLAIN)}..x{fmt(self.sizes[-1], PLAIN)} the best "
                f"design (rate x{fmt(rec['rate_factor'])}, size x{fmt(rec['size_factor'])}) "
                f"still misses {rec['binding']} by a factor {fmt(rec['worst_shortfall'])}"
            )
        edges = d["at_scene_size"]
        span = (
            f"at the scene's size, rates x{fmt(edges['rate_low'])}..x{fmt(edges['rate_high'])} "
            f"(bound by {edges['binding_low']} below, {edges['binding_high']} above)"
            if edges["rate_low"] is not None
            else "none at the scene's size"
        )
        return (
            f"window ({self.style} bearing): {d['feasible_points']} of {self.feasible.size} "
            "(rate, size) designs meet "
            f"every scaled requirement; {span}; recommended rate x{fmt(rec['rate_factor'])}, size "
            f"x{fmt(rec['size_factor'])}"
        )


def window(requirements: list[Requirement], style: str = "") -> Window:
    """Scale each requirement of :data:`SCALING` over the grid (see the module docstring)."""
    scaled = [r for r in requirements if r.name in SCALING]
    names = tuple(r.name for r in scaled)
    s = RATES[:, None, None]
    L = SIZES[None, :, None]
    req = np.array([r.required for r in scaled])[None, None, :]
    best = np.array([r.best for r in scaled])[None, None, :]
    (rs, rl), (bs, bl) = (
        np.array([SCALING[n][0] for n in names]).T,
        np.array([SCALING[n][1] for n in names]).T,
    )
    req = req * s**rs * L**rl
    best = best * s**bs * L**bl
    for k, r in enumerate(scaled):  # the offset's best: the mounts' part grows as L^2
        if r.name == "centre_of_mass_offset_m" and "mounts_m" in r.parts:
            fixed = r.best - r.parts["mounts_m"]
            best[:, :, k] = fixed + r.parts["mounts_m"] * L[:, :, 0] ** 2
    tolerance = np.array([r.kind == "tolerance" for r in scaled])
    with np.errstate(divide="ignore"):
        short = np.where(tolerance, best / req, req / best)
    margin = short.max(axis=2)
    return Window(RATES, SIZES, margin <= 1.0, short.argmax(axis=2), names, margin, style)


def best_window(windows: list[Window]) -> Window:
    """The window with the most designs inside, or, when every one is empty, the one whose
    best design misses least."""
    return min(windows, key=lambda w: (-int(w.feasible.sum()), float(w.margin.min())))


__all__ = ["SCALING", "Requirement", "Verdict", "Window", "best_window", "verdict", "window"]
