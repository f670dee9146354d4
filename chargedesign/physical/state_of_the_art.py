"""What a laboratory can reach today: the figures a testbed's requirements are checked against.

Each figure is a :class:`Figure` read from the sources table
(:mod:`chargedesign.physical.sources`, ``chargedesign sources``) by its key: the value in SI
units, the unit, the source (ending with its citation, ``[key]`` or ``[key, unverified]``)
and whether it was checked (read in that source). A scene may always state its own
equipment instead (``[testbed]`` keys, docs/testbed.md), and the report then names the scene
as the source.

Groups: :data:`BALANCE` (automatic balancing, the pendulous offset labs keep),
:data:`GYROS` (rate-gyro grades), :data:`ATTITUDE_SENSORS` (lab attitude sensors),
:data:`REACTION_WHEELS` (the wheels' rated speed and encoders; the actuators themselves are
the catalogue of :mod:`chargedesign.airbearing.actuators`), :data:`BEARINGS` (air-bearing
styles: tilt, load, pedestal), :data:`AIR_FILM` (the film's range), :data:`FULL_SPHERE`
(a floating precision ball), :data:`ROOM_AIR` (air currents in a lab),
:data:`MOUNT_MATERIALS` (the posts that hold the parts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from chargedesign.physical.sources import UNVERIFIED_MARK, source

_DEG = math.pi / 180.0
_HOUR = 3600.0

SCHWARTZ_2003 = (
    "J. L. Schwartz, M. A. Peck, C. D. Hall, 'Historical Review of Air-Bearing Spacecraft "
    "Simulators', J. Guidance, Control, and Dynamics 26(4), 513-522, 2003"
)

#: the mark the citation of an unchecked figure carries (``[key, unverified]``)
UNVERIFIED = UNVERIFIED_MARK


@dataclass(frozen=True)
class Figure:
    """One state-of-the-art figure: ``value`` in ``unit`` (SI), where it comes from (ending
    with its citation), whether it was checked against that document, and its key in the
    sources table."""

    value: float
    unit: str
    source: str
    verified: bool = True
    key: str = ""


def figure(key: str, scale: float = 1.0, unit: str | None = None, note: str = "") -> Figure:
    """The figure of ``key`` from the sources table, times ``scale`` (a unit conversion),
    in ``unit`` (default: the table's)."""
    row = source(key)
    text = row.source + (f" ({note})" if note else "") + " " + row.cite()
    return Figure(row.value * scale, unit or row.unit, text, row.checked, key)


#: balancing the centre of mass onto the bearing's centre (the published figures are the
#: balancing's ESTIMATED offsets, not measured ones)
BALANCE = {
    "automatic_horizontal_m": figure(
        "state_of_the_art.balance.automatic_horizontal_m", note="an estimated offset"
    ),
    "pendulous_vertical_m": figure("state_of_the_art.balance.pendulous_vertical_m"),
}

_ARW = _DEG / math.sqrt(_HOUR)  # deg/sqrt(h) -> rad/sqrt(s)
_BIAS = _DEG / _HOUR  # deg/h -> rad/s

#: gyro grades: (angle random walk rad/sqrt(s), bias instability rad/s)
GYROS = {
    grade: (
        figure(f"sensors.gyro.{grade}.arw", _ARW, "rad/sqrt(s)"),
        figure(f"sensors.gyro.{grade}.bias", _BIAS, "rad/s"),
    )
    for grade in ("navigation", "tactical", "industrial")
}

_ALONG = source("sensors.motion_capture.along_m")
_BASELINE = source("sensors.motion_capture.baseline_m")
#: the motion-capture attitude noise: the marker error ALONG the cameras' line of sight (the
#: worse one, about 7 times the error across it) over the marker baseline
MOTION_CAPTURE_NOISE = Figure(
    _ALONG.value / _BASELINE.value,
    "rad",
    f"{_ALONG.source}: {_ALONG.value * 1e3:g} mm along the line of sight (across it "
    f"{source('sensors.motion_capture.across_m').value * 1e3:g} mm) over an assumed "
    f"{_BASELINE.value:g} m marker baseline (derived) {_ALONG.cite()}; {_BASELINE.cite()}",
    _ALONG.checked and _BASELINE.checked,
    _ALONG.key,
)

#: lab attitude sensors: (noise per sample rad, update rate Hz)
ATTITUDE_SENSORS = {
    "motion_capture": (MOTION_CAPTURE_NOISE, figure("sensors.motion_capture.rate")),
    # the vertical from a two-axis inclinometer, yaw from a camera on fiducials: the
    # inclinometer's resolution is the floor of the tilt read
    "camera_inclinometer": (
        figure("sensors.inclinometer.resolution", _DEG, "rad"),
        figure("sensors.inclinometer.rate"),
    ),
}

#: the wheels the tool builds: their rated speed (the wheel's inertia follows from its
#: momentum need) and encoders; the actuators' torque, momentum and mass are the catalogue's
#: (chargedesign.airbearing.actuators)
REACTION_WHEELS = {
    "speed_rad_per_s": figure("actuators.wheel_speed", 2.0 * math.pi / 60.0, "rad/s"),
    "encoder_counts_per_turn": figure("sensors.encoder.counts"),
}

#: the air film of an air bearing: its range (drag goes as 1/h, so the thin end is the
#: worst for the drag, where its verdict is taken)
AIR_FILM = {
    "thin_m": figure("bearings.air_film.thin_m"),
    "thick_m": figure("bearings.air_film.thick_m"),
}


@dataclass(frozen=True)
class BearingStyle:
    """An air-bearing style: tilt limit (deg), rated load (kg), pedestal radius over the ball
    radius (0 for a full sphere; 0.3 taken: a 15 mm post under a 50 mm ball), and the
    source of each."""

    tilt_limit_deg: float
    load_kg: float
    pedestal_ratio: float
    source: str
    verified: bool = False  # both the tilt and the load figures checked in their sources
    tilt_key: str = ""  # the sources table's keys of the tilt limit and the load
    load_key: str = ""


def _style(name: str, pedestal_ratio: float, note: str) -> BearingStyle:
    tilt = source(f"bearings.{name}.tilt_limit_deg")
    load = source(f"bearings.{name}.load_kg")
    text = f"{SCHWARTZ_2003} ({note}) {tilt.cite()}; load: {load.source} {load.cite()}"
    return BearingStyle(
        tilt.value,
        load.value,
        pedestal_ratio,
        text,
        tilt.checked and load.checked,
        tilt.key,
        load.key,
    )


#: spherical air-bearing styles (yaw is free in every style)
BEARINGS = {
    "tabletop": _style(
        "tabletop",
        0.3,
        "tabletop style: the platform sits on the hemisphere's flat face; roll and pitch "
        "limited by the pedestal to some tens of degrees, 30 deg typical",
    ),
    "umbrella": _style(
        "umbrella",
        0.3,
        "umbrella style: the platform hangs around a pedestal from the ball's top; roll and "
        "pitch to about +-45 deg",
    ),
    "full_sphere": _style(
        "full_sphere",
        0.0,
        "fully spherical: the platform is a ball floating in a cup, every attitude allowed; "
        "payload inside the ball, no outside reach",
    ),
}

_CUP = source("full_sphere.cup_half_angle_deg")
#: the floating precision ball of a full-sphere bearing
FULL_SPHERE = {
    "sphericity_m": figure("full_sphere.sphericity_m"),
    "cup_coverage_sr": Figure(
        2.0 * math.pi * (1.0 - math.cos(_CUP.value * _DEG)),
        "sr",
        f"{_CUP.source} (the cup wraps the lower part of the ball; a {_CUP.value:g} deg "
        f"half-angle cup) {_CUP.cite()}",
        _CUP.checked,
        _CUP.key,
    ),
    "largest_diameter_m": figure("full_sphere.largest_diameter_m"),
}

#: air currents in a lab: the torque on a platform of cross-section S at lever arm l is
#: 0.5 rho v^2 C_d S l; still air and C_d = 1
ROOM_AIR = {
    "air_speed_m_per_s": figure("room_air.speed_m_per_s"),
    "air_density_kg_per_m3": figure("media.density.air"),
    # the unbalanced fraction of the drag's lever arm: a symmetric platform cancels most of it
    "asymmetry": figure("room_air.asymmetry"),
}

#: posts that hold the parts: Young's modulus Pa, density kg/m^3
MOUNT_MATERIALS = {
    name: (figure(f"mounts.{name}.youngs_modulus"), figure(f"materials.density.{name}"))
    for name in ("steel", "aluminium", "invar")
}

#: the fastest attitude loop a lab platform's computer runs
LOOP_RATE = figure("state_of_the_art.loop_rate")


def room_air_torque(radius_m: float) -> float:
    """The room air's torque on a platform of envelope radius R, N m:
    ``asymmetry x 0.5 rho v^2 (pi R^2) R`` (drag coefficient 1)."""
    v = ROOM_AIR["air_speed_m_per_s"].value
    rho = ROOM_AIR["air_density_kg_per_m3"].value
    return ROOM_AIR["asymmetry"].value * 0.5 * rho * v * v * math.pi * radius_m**3


__all__ = [
    "AIR_FILM",
    "ATTITUDE_SENSORS",
    "BALANCE",
    "BEARINGS",
    "FULL_SPHERE",
    "GYROS",
    "LOOP_RATE",
    "MOUNT_MATERIALS",
    "REACTION_WHEELS",
    "ROOM_AIR",
    "UNVERIFIED",
    "BearingStyle",
    "Figure",
    "figure",
    "room_air_torque",
]
