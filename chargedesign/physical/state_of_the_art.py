"""What a laboratory can reach today: the figures a testbed's requirements are checked against.

Each figure is a :class:`Figure` (value in SI units, the unit, and its source named precisely:
a publication or a vendor datasheet). Figures quoted from a source's text carry the source's
numbers; figures derived from them say how. A scene may always state its own equipment
instead (``[testbed]`` keys, docs/testbed.md), and the report then names the scene as the source.

Groups: :data:`BALANCE` (automatic balancing, the pendulous offset labs keep),
:data:`GYROS` (rate-gyro grades), :data:`ATTITUDE_SENSORS` (lab attitude sensors),
:data:`REACTION_WHEELS` (the largest commercial wheels), :data:`BEARINGS` (air-bearing
styles: tilt, load, pedestal), :data:`FULL_SPHERE` (a floating precision ball),
:data:`ROOM_AIR` (air currents in a lab), :data:`MOUNT_MATERIALS` (the posts that hold the
parts). Checked against the documents: the automatic-balancing figures (engrXiv
doi:10.31224/7342) and the motion-capture noise (arXiv:2502.21189). Every other vendor,
handbook and standard figure was quoted from memory of the named document and could not be
re-checked against it: it is built with :func:`_from_memory`, which sets ``verified=False``
and ends its source with :data:`UNVERIFIED`, so every report line that rests on it says so.
Give your equipment's figures in the scene instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

_DEG = math.pi / 180.0
_HOUR = 3600.0

SCHWARTZ_2003 = (
    "J. L. Schwartz, M. A. Peck, C. D. Hall, 'Historical Review of Air-Bearing Spacecraft "
    "Simulators', J. Guidance, Control, and Dynamics 26(4), 513-522, 2003"
)
RAMBO_2025 = (
    "'Two-Stage Automatic Mass Balancing and Attitude Control for 3-DoF Spacecraft Attitude "
    "Simulators' (RAMBO), engrXiv preprint doi:10.31224/7342: estimated offset after "
    "automatic balancing [0.08, 0.12, -27.62] um (the vertical one kept pendulous on purpose)"
)
KIM_AGRAWAL_2009 = (
    "J. J. Kim, B. N. Agrawal, 'Automatic Mass Balancing of Air-Bearing-Based Three-Axis "
    "Rotational Spacecraft Simulator', J. Guidance, Control, and Dynamics 32(3), 2009"
)
GROVES_2013 = (
    "P. D. Groves, Principles of GNSS, Inertial, and Multisensor Integrated Navigation "
    "Systems, 2nd ed., Artech House 2013, ch. 4 (inertial sensor grades)"
)


#: the mark every figure quoted from memory carries at the end of its source
UNVERIFIED = " [unverified (from memory)]"


@dataclass(frozen=True)
class Figure:
    """One state-of-the-art figure: ``value`` in ``unit`` (SI), where it comes from, and
    whether the figure was checked against that document."""

    value: float
    unit: str
    source: str
    verified: bool = True


def _from_memory(value: float, unit: str, source: str) -> Figure:
    """A figure quoted from memory of ``source``, not re-checked against it."""
    return Figure(value, unit, source + UNVERIFIED, verified=False)


#: balancing the centre of mass onto the bearing's centre
BALANCE = {
    # the best published automatic balancing: |(0.08, 0.12)| um horizontally
    "automatic_horizontal_m": Figure(math.hypot(0.08e-6, 0.12e-6), "m", RAMBO_2025),
    # labs keep a pendulous vertical offset of tens of um for stability (Kim & Agrawal
    # describe manual balancing as limited by the travel limit and the pendulum's period;
    # no figure of its floor is quoted here)
    "pendulous_vertical_m": Figure(27.62e-6, "m", RAMBO_2025),
}


def _arw(deg_per_sqrt_hour: float) -> float:
    return deg_per_sqrt_hour * _DEG / math.sqrt(_HOUR)


def _bias(deg_per_hour: float) -> float:
    return deg_per_hour * _DEG / _HOUR


#: gyro grades: (angle random walk rad/sqrt(s), bias instability rad/s)
GYROS = {
    "navigation": (
        _from_memory(_arw(0.002), "rad/sqrt(s)", GROVES_2013),
        _from_memory(_bias(0.01), "rad/s", GROVES_2013),
    ),
    "tactical": (
        _from_memory(_arw(0.1), "rad/sqrt(s)", GROVES_2013),
        _from_memory(_bias(1.0), "rad/s", GROVES_2013),
    ),
    "industrial": (
        _from_memory(_arw(0.5), "rad/sqrt(s)", GROVES_2013),
        _from_memory(_bias(10.0), "rad/s", GROVES_2013),
    ),
}

#: lab attitude sensors: (noise per sample rad, update rate Hz)
ATTITUDE_SENSORS = {
    # markers 0.1 mm accurate over a 1 m marker baseline: 1e-4 rad
    "motion_capture": (
        Figure(
            1.0e-4,
            "rad",
            "O. Krumpek, O. Kroeger, S. Mohr, 'Reproducible Optical Tracking Precision', "
            "arXiv:2502.21189 (2025), OptiTrack PrimeX 22 cameras measured: +-0.12 mm "
            "across the line of sight, 0.02-0.07 mm noise; over a 1 m marker baseline about "
            "1e-4 rad (derived)",
        ),
        _from_memory(
            180.0, "Hz", "NaturalPoint OptiTrack PrimeX 41 camera datasheet: 180 frames/s"
        ),
    ),
    # the vertical from a two-axis inclinometer, yaw from a camera on fiducials: the
    # inclinometer's 0.01 deg resolution is the floor of the tilt read
    "camera_inclinometer": (
        _from_memory(
            0.01 * _DEG,
            "rad",
            "Murata SCL3300 inclinometer datasheet: 0.01 deg "
            "resolution (mode 1); a camera on fiducials for yaw",
        ),
        _from_memory(
            100.0,
            "Hz",
            "Murata SCL3300 datasheet: output data rate up to 2000 Hz; a "
            "100 Hz camera for yaw (derived: the slower of the two)",
        ),
    ),
}

#: the largest commercial reaction wheels (each wheel): the class's range, and the figures
#: the tool takes (its top end); a torque below ``torque_low_N_m`` is outside the class, and
#: no smaller class is sourced here
_HR16 = "Honeywell HR16 reaction wheel datasheet (Honeywell Aerospace)"
REACTION_WHEELS = {
    "torque_N_m": _from_memory(0.2, "N m", _HR16 + ": 0.1-0.2 N m reaction torque"),
    "torque_low_N_m": _from_memory(0.1, "N m", _HR16 + ": 0.1-0.2 N m reaction torque"),
    "momentum_N_m_s": _from_memory(100.0, "N m s", _HR16 + ": 25-100 N m s momentum"),
    "mass_kg": _from_memory(12.0, "kg", _HR16 + ": 7-12 kg"),
    "mass_low_kg": _from_memory(7.0, "kg", _HR16 + ": 7-12 kg"),
    # the speed labs spin wheels to (the wheel's inertia follows from its momentum need)
    "speed_rad_per_s": _from_memory(6000.0 * 2.0 * math.pi / 60.0, "rad/s", _HR16 + ": 6000 rpm"),
    "encoder_counts_per_turn": _from_memory(
        4096.0,
        "1",
        "a 12-bit absolute encoder (Renishaw RM44 encoder datasheet: 4096 positions/rev)",
    ),
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
    verified: bool = False  # the tilt and load figures below are quoted from memory


#: spherical air-bearing styles (yaw is free in every style)
BEARINGS = {
    "tabletop": BearingStyle(
        30.0,
        100.0,
        0.3,
        SCHWARTZ_2003 + " (tabletop style: the platform sits on the hemisphere's flat face; "
        "roll and pitch limited by the pedestal to some tens of degrees, 30 deg typical); "
        "load: Space Electronics spherical air bearing catalogue, 45-450 kg class (100 kg "
        "taken)" + UNVERIFIED,
    ),
    "umbrella": BearingStyle(
        45.0,
        150.0,
        0.3,
        SCHWARTZ_2003 + " (umbrella style: the platform hangs around a pedestal from the "
        "ball's top; roll and pitch to about +-45 deg); load: the same catalogue class "
        "(150 kg taken)" + UNVERIFIED,
    ),
    "full_sphere": BearingStyle(
        180.0,
        30.0,
        0.0,
        SCHWARTZ_2003 + " (fully spherical: the platform is a ball floating in a cup, every "
        "attitude allowed; payload inside the ball, no outside reach); load: the cup's "
        "film carries a ball of tens of kg" + UNVERIFIED,
    ),
}

#: the floating precision ball of a full-sphere bearing
FULL_SPHERE = {
    # Grade 10 balls (ISO 3290-1): sphericity 0.25 um; large hollow balls are lapped to ~1 um
    "sphericity_m": _from_memory(
        1.0e-6,
        "m",
        "ISO 3290-1:2014 grade tolerances (grade 10: "
        "0.25 um deviation from spherical form for solid balls); 1 um "
        "taken for a lapped hollow ball",
    ),
    "cup_coverage_sr": _from_memory(
        2.0 * math.pi * (1.0 - math.cos(60.0 * _DEG)),
        "sr",
        SCHWARTZ_2003 + " (the cup wraps the lower part of the ball; "
        "a 60 deg half-angle cup taken)",
    ),
    "largest_diameter_m": _from_memory(
        1.0, "m", SCHWARTZ_2003 + " (full-sphere simulators of up to about a metre)"
    ),
}

#: air currents in a lab: the torque on a platform of cross-section S at lever arm l is
#: 0.5 rho v^2 C_d S l; 0.05 m/s still air and C_d = 1
ROOM_AIR = {
    "air_speed_m_per_s": _from_memory(
        0.05,
        "m/s",
        "ASHRAE Standard 55-2020, still air (< 0.2 m/s); 0.05 m/s taken for a draught-shielded lab",
    ),
    "air_density_kg_per_m3": _from_memory(
        1.204,
        "kg/m^3",
        "CRC Handbook of Chemistry and Physics, 97th ed., CRC Press 2016: dry air at 20 C, 1 atm",
    ),
    # the unbalanced fraction of the drag's lever arm: a symmetric platform cancels most of it
    "asymmetry": Figure(
        0.1, "1", "assumed: a platform symmetric about O to 10 % of its frontal area"
    ),
}

_ASM1 = (
    "ASM Handbook vol. 1, Properties and Selection: Irons, Steels, and High-Performance "
    "Alloys, ASM International, 1990"
)
_ASM2 = (
    "ASM Handbook vol. 2, Properties and Selection: Nonferrous Alloys and Special-Purpose "
    "Materials, ASM International, 1990"
)

#: posts that hold the parts: Young's modulus Pa, density kg/m^3
MOUNT_MATERIALS = {
    "steel": (
        _from_memory(200e9, "Pa", _ASM1 + ": carbon steel, E = 200 GPa"),
        _from_memory(7850.0, "kg/m^3", _ASM1),
    ),
    "aluminium": (
        _from_memory(69e9, "Pa", _ASM2 + ": 6061-T6, E = 69 GPa"),
        _from_memory(2700.0, "kg/m^3", _ASM2),
    ),
    "invar": (
        _from_memory(141e9, "Pa", _ASM2 + ": Invar 36, E = 141 GPa"),
        _from_memory(8050.0, "kg/m^3", _ASM2),
    ),
}

#: the fastest attitude loop a lab platform's computer runs
LOOP_RATE = _from_memory(
    1000.0,
    "Hz",
    KIM_AGRAWAL_2009 + " and the NPS simulators: 1 kHz real-time loops (dSPACE/xPC targets)",
)


def room_air_torque(radius_m: float) -> float:
    """The room air's torque on a platform of envelope radius R, N m:
    ``asymmetry x 0.5 rho v^2 (pi R^2) R`` (drag coefficient 1)."""
    v = ROOM_AIR["air_speed_m_per_s"].value
    rho = ROOM_AIR["air_density_kg_per_m3"].value
    return ROOM_AIR["asymmetry"].value * 0.5 * rho * v * v * math.pi * radius_m**3


__all__ = [
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
    "room_air_torque",
]
