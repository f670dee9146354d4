"""The actuator catalogue the testbed's window searches: reaction wheels of several classes
and control moment gyros, each with its torque, momentum, mass and power from the sources
table (``actuators.<id>.torque``, ``.momentum``, ``.mass``; ``chargedesign sources``).

A testbed needs on each wheel axis an actuator whose torque and momentum cover the planned
motions' needs; the lightest such actuator is chosen (:func:`choose`), and its mass, one per
axis, is counted against the platform's mass (the wheels are part of it). Where no actuator
covers the need, the nearest one (the smallest worst ratio of need over capacity) is named,
and the requirement it misses says by how much.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from chargedesign.physical.sources import rows_under, source

#: the catalogue's rows in the sources table: actuators.<id>.<field>
PREFIX = "actuators."
#: the fields every actuator carries
FIELDS = ("torque", "momentum", "mass")


@dataclass(frozen=True)
class Actuator:
    """One actuator of the catalogue (per wheel axis).

    Attributes
    ----------
    id : str
        Its id in the sources table (``actuators.<id>.torque`` ...).
    name : str
    kind : str
        ``reaction_wheel`` or ``cmg``.
    torque, momentum, mass : float
        N m, N m s, kg.
    power : float or None
        W (None: not given by the sources read).
    source : str
    checked : bool
        Every one of its figures read in its source.
    in_development : bool
        Not a flight product yet (the source says so).
    """

    id: str
    name: str
    kind: str
    torque: float
    momentum: float
    mass: float
    power: float | None
    source: str
    checked: bool
    in_development: bool

    def key(self, field: str) -> str:
        """The sources-table key of one of its figures (torque, momentum or mass)."""
        return f"{PREFIX}{self.id}.{field}"

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(self.key(f) for f in FIELDS)

    def to_dict(self) -> dict[str, Any]:
        """The contract's entry of testbed.json ``actuators``."""
        return {
            "name": self.name,
            "kind": self.kind,
            "torque_N_m": self.torque,
            "momentum_N_m_s": self.momentum,
            "mass_kg": self.mass,
            "power_W": self.power,
            "source": self.source,
            "checked": self.checked,
            "in_development": self.in_development,
            "keys": {f: self.key(f) for f in FIELDS},
            "unchecked": [self.key(f) for f in FIELDS if not source(self.key(f)).checked],
        }


def _actuator(ident: str) -> Actuator:
    rows = {f: source(f"{PREFIX}{ident}.{f}") for f in FIELDS}
    what = rows["torque"].what
    name = what.split(":")[0]
    power_key = f"{PREFIX}{ident}.power"
    power = source(power_key).value if power_key in {r.key for r in rows_under(PREFIX)} else None
    return Actuator(
        id=ident,
        name=name,
        kind="cmg" if "control moment gyro" in name.lower() else "reaction_wheel",
        torque=rows["torque"].value,
        momentum=rows["momentum"].value,
        mass=rows["mass"].value,
        power=power,
        source=rows["torque"].source,
        checked=all(r.checked for r in rows.values()),
        in_development="in development" in what.lower(),
    )


@lru_cache(maxsize=1)
def catalogue() -> tuple[Actuator, ...]:
    """Every actuator of the sources table, in its order."""
    ids: list[str] = []
    for row in rows_under(PREFIX):
        parts = row.key[len(PREFIX) :].split(".")
        if len(parts) == 2 and parts[1] == "torque" and parts[0] not in ids:
            ids.append(parts[0])
    return tuple(_actuator(i) for i in ids)


def choose(torque: Any, momentum: Any) -> np.ndarray:
    """The index in :func:`catalogue` of the actuator for each need (arrays broadcast):
    the lightest whose torque and momentum cover ``torque`` (N m) and ``momentum`` (N m s),
    or, where none does, the one whose worst ratio of need over capacity is smallest."""
    caps = capacities()
    t = np.asarray(torque, float)[..., None]
    h = np.asarray(momentum, float)[..., None]
    worst = np.maximum(t / caps["torque"], h / caps["momentum"])
    fits = worst <= 1.0
    lightest = np.argmin(np.where(fits, caps["mass"], np.inf), axis=-1)
    nearest = np.argmin(worst, axis=-1)
    return np.where(fits.any(axis=-1), lightest, nearest)


def chosen(torque: float, momentum: float) -> Actuator:
    """The actuator :func:`choose` picks for one need."""
    return catalogue()[int(choose(torque, momentum))]


def capacities() -> dict[str, np.ndarray]:
    """The catalogue's torque (N m), momentum (N m s) and mass (kg), shape (actuators,)."""
    cat = catalogue()
    return {
        "torque": np.array([a.torque for a in cat]),
        "momentum": np.array([a.momentum for a in cat]),
        "mass": np.array([a.mass for a in cat]),
    }


__all__ = ["FIELDS", "PREFIX", "Actuator", "capacities", "catalogue", "choose", "chosen"]
