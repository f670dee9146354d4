"""Requirements against the state of the art, the verdict, and the feasibility window.

Every requirement is a :class:`Requirement` (the contract's ``state_of_the_art[]`` entry):
``tolerance`` (a largest allowed error: met when ``best <= required``) or ``capacity`` (a
largest available figure: met when ``required <= best``). The verdict is "buildable" only when
every requirement is met and the nominal Monte Carlo's median drift (every effect on) is at
most the target; otherwise it names the requirement missed by the largest factor.

The window (:func:`window`) scales the design in time (rate s: the theorem's n, K x s,
kappa x s^2, the motion s times faster), in size (L: every length x L) and in mass (m: the
total mass x m, so every inertia x m L^2), and reads each requirement's law from its physics.
With C' = m L^2 C the designed torques are C' s^2, the gravity torque of an offset e is
m M g e:

| requirement | required | best |
| --- | --- | --- |
| centre-of-mass offset | x s^2 L^2 (C' s^2 over m M g) | mounts x m / L (W l^3 / E r^4) |
| bearing drag | x s m L^2 (C' s) | x L^4 (Couette, ball radius x L) |
| room air torque | x s^2 m L^2 (weight x offset) | x L^3 |
| wheel torque, momentum | x s^2 m L^2, x s m L^2 | the chosen actuator's (catalogue) |
| wheel mass | x m (the platform's mass holds the wheels) | one chosen actuator per axis |
| bearing load | x m | fixed |
| loop rate | x s | fixed |
| ball diameter | x L | fixed |

The same densities are m = L^3. The tilt does not change with (s, L, m). The window's last
axis is the planned motion flown: all of them (the scene's plan) or one alone, each setting
the tilt and the wheels' torque and momentum it needs (``motion_needs``); the balance
tolerances are those of the loop's start (motion 0) on every motion. The nominal drift is
measured at the scene's design only; the window says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.airbearing.actuators import capacities, catalogue, choose
from chargedesign.formatting import PLAIN, fmt
from chargedesign.physical.sources import checked as key_checked

#: how each requirement's (required, best) scale with (s, L, m): exponents of s, L and m
SCALING: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "centre_of_mass_offset_m": ((2.0, 2.0, 0.0), (0.0, 0.0, 0.0)),
    "bearing_drag_N_m_s": ((1.0, 2.0, 1.0), (0.0, 4.0, 0.0)),
    "room_air_torque_N_m": ((2.0, 2.0, 1.0), (0.0, 3.0, 0.0)),
    "wheel_torque_N_m": ((2.0, 2.0, 1.0), (0.0, 0.0, 0.0)),
    "wheel_momentum_N_m_s": ((1.0, 2.0, 1.0), (0.0, 0.0, 0.0)),
    "wheel_mass_kg": ((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),
    "bearing_load_kg": ((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),
    "loop_rate_Hz": ((1.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    "bearing_tilt_deg": ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    "ball_diameter_m": ((0.0, 1.0, 0.0), (0.0, 0.0, 0.0)),
}
#: the grid of the window: time rates, sizes and masses relative to the scene's
RATES = np.logspace(-1.0, 2.0, 61)
SIZES = np.logspace(-0.5, 0.5, 21)
MASSES = np.logspace(-0.5, 0.5, 21)


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
    keys: tuple[str, ...] = ()  # the sources-table keys its figures rest on
    origin: str = "table"  # where the best comes from: table | scene | run

    @property
    def unchecked_keys(self) -> list[str]:
        """Its keys whose figures were not read in their sources."""
        return [k for k in dict.fromkeys(self.keys) if not key_checked(k)]

    @property
    def checked(self) -> bool:
        """Every figure it rests on checked (a scene's own figure is not: the tool did not
        read it in a source)."""
        return self.origin != "scene" and not self.unchecked_keys

    def binding_source(self) -> dict[str, Any]:
        """The contract's ``verdict.binding_source``: the key of the figure that binds (its
        first unchecked one, else its first; ``scene`` for a scene's own figure, ``run``
        for a figure this run measured from checked figures alone) and whether checked."""
        unchecked = self.unchecked_keys
        if self.origin == "scene":
            key = "scene"
        elif unchecked:
            key = unchecked[0]
        elif self.keys:
            key = self.keys[0]
        else:
            key = "run"
        return {"key": key, "checked": self.checked}

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
            # a figure it rests on was not read in its source (or is the scene's own)
            "unverified": not self.checked,
            "keys": list(self.keys),
            "origin": self.origin,
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
    binding_source: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "buildable": self.buildable,
            "binding": self.binding,
            "line": self.line,
            "binding_source": self.binding_source,
        }


def _unverified_note(requirements: list[Requirement]) -> str:
    """What the verdict line says of the unverified figures the requirements rest on."""
    keys = list(dict.fromkeys(k for r in requirements for k in r.unchecked_keys))
    scene = [r.name for r in requirements if r.origin == "scene"]
    parts = []
    if keys:
        parts.append("unverified figures: " + ", ".join(keys))
    if scene:
        parts.append("the scene's own figures for " + ", ".join(scene))
    return f" (rests on {'; '.join(parts)})" if parts else ""


def verdict(requirements: list[Requirement], nominal_median: float, target: float) -> Verdict:
    """Buildable only when every requirement is met and the nominal median is within target.

    The line says when an unverified figure decides it: for "buildable", every requirement
    decides (each met one's unverified figures are named); for "NOT buildable", the binding
    requirement's."""
    unmet = [r for r in requirements if not r.met]
    if not unmet and nominal_median <= target:
        unverified = [r for r in requirements if not r.checked]
        return Verdict(
            True,
            None,
            "buildable: every requirement is met and the nominal Monte "
            f"Carlo's median I4 drift {fmt(nominal_median)} is within the target "
            f"{fmt(target, PLAIN)}" + _unverified_note(requirements),
            {
                "key": unverified[0].binding_source()["key"] if unverified else "run",
                "checked": not unverified,
            },
        )
    if not unmet:  # the drift requirement is in the list; kept for a list without it
        return Verdict(
            False,
            "nominal_I4_drift",
            f"NOT buildable: the nominal median drift "
            f"{fmt(nominal_median)} is above the target {fmt(target, PLAIN)}",
            {"key": "run", "checked": True},
        )
    worst = max(unmet, key=lambda r: r.shortfall)
    note = _unverified_note([worst])
    line = "NOT buildable: " + worst.line()
    if note:
        line += "; the binding figure is not checked" + note
    return Verdict(False, worst.name, line, worst.binding_source())


#: the window's axes, in the order of its arrays
AXES = ("rate", "size", "mass", "motion")
#: the wheel requirements the actuator catalogue decides, and the actuator's figure for each
WHEEL_FIELDS = {
    "wheel_torque_N_m": "torque",
    "wheel_momentum_N_m_s": "momentum",
    "wheel_mass_kg": "mass",
}


@dataclass(frozen=True)
class Window:
    """The (rate, size, mass, motion) designs where every scaled requirement is met.

    ``motions`` names the last axis: ``all planned`` (the scene's plan), then each planned
    motion alone. ``feasible``, ``binding`` (the most-missed or tightest requirement's index
    in ``names``) and ``margin`` (the worst shortfall, < 1 inside) have shape (rates, sizes,
    masses, motions)."""

    rates: np.ndarray
    sizes: np.ndarray
    masses: np.ndarray
    motions: tuple[str, ...]
    feasible: np.ndarray
    binding: np.ndarray
    names: tuple[str, ...]
    margin: np.ndarray
    style: str = ""  # the bearing style the requirements are read for
    actuator: np.ndarray | None = None  # index in the catalogue of each point's wheels
    keys: tuple[tuple[str, ...], ...] = ()  # each requirement's sources-table keys (names')
    origins: tuple[str, ...] = ()  # each requirement's origin (table, scene, run)

    def binding_source(self, point: tuple[int, ...]) -> dict[str, Any]:
        """The key of the figure that binds at ``point`` and whether it was checked: a wheel
        requirement's is the chosen actuator's figure, the others their requirement's."""
        n = int(self.binding[point])
        name = self.names[n]
        if self.actuator is not None and name in WHEEL_FIELDS:
            key = catalogue()[int(self.actuator[point])].key(WHEEL_FIELDS[name])
            return {"key": key, "checked": key_checked(key)}
        keys = self.keys[n] if n < len(self.keys) else ()
        origin = self.origins[n] if n < len(self.origins) else "table"
        probe = Requirement(name, "tolerance", 1.0, 1.0, "", "", keys=keys, origin=origin)
        return probe.binding_source()

    def unverified_at(self, point: tuple[int, ...]) -> list[str]:
        """The unverified keys the design at ``point`` rests on (every requirement's; the
        wheels' are the chosen actuator's)."""
        out: list[str] = []
        for n, name in enumerate(self.names):
            if self.actuator is not None and name in WHEEL_FIELDS:
                keys: tuple[str, ...] = (
                    catalogue()[int(self.actuator[point])].key(WHEEL_FIELDS[name]),
                )
            else:
                keys = self.keys[n] if n < len(self.keys) else ()
            out += [k for k in keys if not key_checked(k) and k not in out]
        return out

    @property
    def empty(self) -> bool:
        return not bool(self.feasible.any())

    def _axis_values(self) -> tuple[np.ndarray, ...]:
        return self.rates, self.sizes, self.masses, np.arange(len(self.motions))

    def best_index(self) -> tuple[int, ...]:
        """Inside, the design with the largest margin; outside, the least shortfall."""
        return tuple(
            int(i) for i in np.unravel_index(int(np.argmin(self.margin)), self.margin.shape)
        )

    def scene_index(self) -> tuple[int, int, int, int]:
        """The scene's own design: factors 1 and every planned motion."""
        return (
            int(np.argmin(np.abs(np.log(self.rates)))),
            int(np.argmin(np.abs(np.log(self.sizes)))),
            int(np.argmin(np.abs(np.log(self.masses)))),
            0,
        )

    def recommended(self) -> tuple[float, float, float, str]:
        """(rate, size, mass) factors and the motion of :meth:`best_index`."""
        i, j, k, m = self.best_index()
        return (
            float(self.rates[i]),
            float(self.sizes[j]),
            float(self.masses[k]),
            self.motions[m],
        )

    def edges(self, axis: int, point: tuple[int, ...]) -> dict[str, Any]:
        """The window along one axis through ``point``, and the limits beyond its ends."""
        line = list(point)
        line[axis] = slice(None)  # type: ignore[call-overload]
        feasible = self.feasible[tuple(line)]
        binding = self.binding[tuple(line)]
        values = self._axis_values()[axis]
        inside = np.flatnonzero(feasible)
        if inside.size == 0:
            return {"low": None, "high": None, "binding_low": None, "binding_high": None}
        lo, hi = int(inside[0]), int(inside[-1])
        label = self.motions if axis == 3 else None
        return {
            "low": label[lo] if label else float(values[lo]),
            "high": label[hi] if label else float(values[hi]),
            "binding_low": self.names[binding[lo - 1]] if lo > 0 else "the grid's end",
            "binding_high": self.names[binding[hi + 1]]
            if hi + 1 < len(values)
            else "the grid's end",
        }

    def _edges(self) -> dict[str, Any]:
        """The window along the rate at the scene's size, mass and motions."""
        e = self.edges(0, self.scene_index())
        return {
            "rate_low": e["low"],
            "rate_high": e["high"],
            "binding_low": e["binding_low"],
            "binding_high": e["binding_high"],
        }

    def to_dict(self) -> dict[str, Any]:
        rate, size, mass, motion = self.recommended()
        best = self.best_index()
        out: dict[str, Any] = {
            "bearing": self.style,
            "empty": self.empty,
            "rates": self.rates.tolist(),
            "sizes": self.sizes.tolist(),
            "masses": self.masses.tolist(),
            "motions": list(self.motions),
            "feasible_points": int(self.feasible.sum()),
            "scene_inside": bool(self.feasible[self.scene_index()]),
            "recommended": {
                "rate_factor": rate,
                "size_factor": size,
                "mass_factor": mass,
                "motion": motion,
                "worst_shortfall": float(self.margin[best]),
                "binding": self.names[self.binding[best]],
                "binding_source": self.binding_source(best),
                "actuator": self.actuator_name(best),
                "unverified": self.unverified_at(best),
            },
            "at_scene_size": self._edges(),
            "through_recommended": {a: self.edges(n, best) for n, a in enumerate(AXES)},
            "measured_only_at_the_scene": ["nominal_I4_drift"],
        }
        if self.empty:
            out["missing_factor"] = float(self.margin.min())
        return out

    def actuator_name(self, point: tuple[int, ...]) -> str | None:
        """The catalogue actuator the wheels of ``point`` are (None: no wheel figures)."""
        if self.actuator is None:
            return None
        return catalogue()[int(self.actuator[point])].name

    def line(self) -> str:
        d = self.to_dict()
        rec = d["recommended"]
        design = (
            f"rate x{fmt(rec['rate_factor'])}, size x{fmt(rec['size_factor'])}, mass "
            f"x{fmt(rec['mass_factor'])}, {rec['motion']}"
            + (f", wheels: {rec['actuator']}" if rec.get("actuator") else "")
        )
        if rec["unverified"]:
            design += f" (resting on unverified figures: {', '.join(rec['unverified'])})"
        if self.empty:
            return (
                f"no window ({self.style} bearing): over rates x{fmt(self.rates[0], PLAIN)}"
                f"..x{fmt(self.rates[-1], PLAIN)}, sizes x{fmt(self.sizes[0], PLAIN)}"
                f"..x{fmt(self.sizes[-1], PLAIN)}, masses x{fmt(self.masses[0], PLAIN)}"
                f"..x{fmt(self.masses[-1], PLAIN)} and {len(self.motions)} motion choices the "
                f"best design ({design}) still misses {rec['binding']} by a factor "
                f"{fmt(rec['worst_shortfall'])}"
            )
        edges = d["at_scene_size"]
        span = (
            f"at the scene's size, mass and motions, rates x{fmt(edges['rate_low'])}.."
            f"x{fmt(edges['rate_high'])} (bound by {edges['binding_low']} below, "
            f"{edges['binding_high']} above)"
            if edges["rate_low"] is not None
            else "none at the scene's size, mass and motions"
        )
        return (
            f"window ({self.style} bearing): {d['feasible_points']} of {self.feasible.size} "
            f"(rate, size, mass, motion) designs meet every scaled requirement; {span}; "
            f"recommended {design}"
        )


def window(
    requirements: list[Requirement],
    style: str = "",
    motion_needs: list[dict[str, float]] | None = None,
    wheels: int | None = None,
) -> Window:
    """Scale each requirement of :data:`SCALING` over the grid (see the module docstring).

    ``motion_needs``: for each planned motion alone, what it requires of what the choice of
    motion sets, ``bearing_tilt_deg``, ``wheel_torque_N_m`` and ``wheel_momentum_N_m_s`` (the
    rest is the loop start's; the requirements' own figures are the plan's, every motion).
    ``wheels`` (the number of wheel axes) chooses each point's wheels from the actuator
    catalogue: their torque, momentum and, when ``wheel_mass_kg`` is a requirement, their mass
    (:func:`_wheels`)."""
    scaled = [r for r in requirements if r.name in SCALING]
    names = tuple(r.name for r in scaled)
    alone = tuple(f"motion {k} alone" for k in range(len(motion_needs or [])))
    motions = ("all planned motions", *alone)
    req0 = np.array([[r.required for r in scaled]] * len(motions))  # (motions, names)
    for k, needs in enumerate(motion_needs or []):
        for n, name in enumerate(names):
            if name in needs:
                req0[k + 1, n] = needs[name]
    s = RATES[:, None, None, None, None]
    L = SIZES[None, :, None, None, None]
    m = MASSES[None, None, :, None, None]
    exps = np.array([SCALING[n] for n in names])  # (names, 2, 3)
    (rs, rl, rm), (bs, bl, bm) = exps[:, 0].T, exps[:, 1].T
    req = req0[None, None, None] * s**rs * L**rl * m**rm
    best = np.array([r.best for r in scaled]) * s**bs * L**bl * m**bm
    best = np.broadcast_to(best, req.shape).copy()
    for n, r in enumerate(scaled):  # the offset's best: the mounts' part bends as m / L
        if r.name == "centre_of_mass_offset_m" and "mounts_m" in r.parts:
            fixed = r.best - r.parts["mounts_m"]
            best[..., n] = fixed + r.parts["mounts_m"] * (m / L)[..., 0]
    actuator = None
    if wheels is not None and {"wheel_torque_N_m", "wheel_momentum_N_m_s"} <= set(names):
        actuator = _wheels(req, best, names, wheels)
    tolerance = np.array([r.kind == "tolerance" for r in scaled])
    with np.errstate(divide="ignore"):
        short = np.where(tolerance, best / req, req / best)
    margin = short.max(axis=-1)
    return Window(
        RATES,
        SIZES,
        MASSES,
        motions,
        margin <= 1.0,
        short.argmax(axis=-1),
        names,
        margin,
        style,
        actuator,
        tuple(r.keys for r in scaled),
        tuple(r.origin for r in scaled),
    )


def _wheels(req: np.ndarray, best: np.ndarray, names: tuple[str, ...], count: int) -> np.ndarray:
    """Each point's wheels from the catalogue (in place on ``best``): the chosen actuator's
    torque and momentum are the wheel requirements' bests, and ``count`` of its mass the
    ``wheel_mass_kg`` best (against the platform's mass, its required); returns the
    chosen actuator's index at every point."""
    t, h = names.index("wheel_torque_N_m"), names.index("wheel_momentum_N_m_s")
    index = choose(req[..., t], req[..., h])
    caps = capacities()
    best[..., t] = caps["torque"][index]
    best[..., h] = caps["momentum"][index]
    if "wheel_mass_kg" in names:
        best[..., names.index("wheel_mass_kg")] = count * caps["mass"][index]
    return index


def best_window(windows: list[Window]) -> Window:
    """The window with the most designs inside, or, when every one is empty, the one whose
    best design misses least."""
    return min(windows, key=lambda w: (-int(w.feasible.sum()), float(w.margin.min())))


__all__ = [
    "AXES",
    "SCALING",
    "Requirement",
    "Verdict",
    "Window",
    "best_window",
    "verdict",
    "window",
]
