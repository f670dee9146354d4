"""The ``[testbed]`` scene table: one parser (:meth:`TestbedOptions.from_table`), its defaults
with their sources, and the table's JSON-schema fragment (:func:`table_schema`).

Every default is either taken from a cited figure or derived (the bearing's drag from the
Couette flow in its gap); :data:`SOURCES` says which. All values are SI.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.physical.materials import BALLAST_DENSITY
from chargedesign.physical.state_of_the_art import (
    ATTITUDE_SENSORS,
    BALANCE,
    BEARINGS,
    FULL_SPHERE,
    GYROS,
    MOUNT_MATERIALS,
    UNVERIFIED,
)
from chargedesign.validation import (
    as_array,
    as_count,
    as_finite_float,
    check_keys,
    input_error,
)

#: gyro grades: (angle random walk rad/sqrt(s), bias rad/s), order-of-magnitude figures of each
#: class (chargedesign.physical.state_of_the_art.GYROS); ``ideal`` is a perfect gyro (the
#: loop's own limit)
GYRO_GRADES: dict[str, tuple[float, float]] = {
    "ideal": (0.0, 0.0),
    **{name: (arw.value, bias.value) for name, (arw, bias) in GYROS.items()},
}

#: bearing styles (chargedesign.physical.state_of_the_art.BEARINGS)
BEARING_STYLES = tuple(BEARINGS)
#: lab attitude sensors (chargedesign.physical.state_of_the_art.ATTITUDE_SENSORS)
ATTITUDE_SENSOR_NAMES = tuple(ATTITUDE_SENSORS)
#: the centre-of-mass estimator: recursive least squares with gravity feed-forward, or none
ESTIMATORS = ("rls", "none")

#: the wheel arrays: three orthogonal wheels, or four on a pyramid about body z
WHEEL_ARRAYS = ("orthogonal", "pyramid")
#: the command laws: zero-order hold of the law sampled at t_k, or the model's average over
#: the coming interval (predictive)
COMMANDS = ("predictive", "zoh")

#: dynamic viscosity of air at 20 C, Pa s (CRC Handbook of Chemistry and Physics, 97th ed.,
#: "Viscosity of gases": 18.2 uPa s at 20 C, 1 atm; quoted from memory, not re-checked)
AIR_VISCOSITY = 1.82e-5
#: where each default comes from
SOURCES = {
    "platform": "a thin spherical shell (a cage) about O with an opening for the pedestal "
    "(the keep-out cap; closed for a full sphere): centre of mass R (1 - cos alpha) / 2 along "
    "the pedestal axis, inertia in closed form; 10 kg and 0.25 m radius: the tabletop class "
    "of the survey Schwartz, Peck & Hall, J. Guid. Control Dyn. 26(4) 2003 (e.g. NPS CubeTAS)",
    "bearing_capacity_kg": "the style's rated load (state_of_the_art.BEARINGS: a vendor "
    "catalogue class); give your bearing's",
    "drag_N_m_s": "derived: viscous Couette drag of the air film, b = (4 pi / 3) eta R^4 / h "
    "for a hemispherical cup of radius R and gap h (eta of air at 20 C from the CRC Handbook, "
    "97th ed., CRC Press 2016)" + UNVERIFIED,
    "bearing_gap_m": "10 um: the film thickness of spherical air bearings is of order 5-25 um "
    "(Schwartz, Peck & Hall 2003 describe micrometre films)" + UNVERIFIED,
    "imbalance_m": "0.14 um: the best published automatic balancing, horizontally "
    "(chargedesign.physical.state_of_the_art.BALANCE: engrXiv doi:10.31224/7342)",
    "bearing": "tabletop: tilt limit 30 deg, umbrella 45 deg, full_sphere every attitude "
    "(Schwartz, Peck & Hall 2003; chargedesign.physical.state_of_the_art.BEARINGS)" + UNVERIFIED,
    "pedestal_radius_m": "the style's pedestal radius over the ball's radius (0.3) times "
    "bearing_radius_m",
    "mount_material": "steel posts (E = 200 GPa, ASM Handbook vol. 1, ASM International 1990)"
    + UNVERIFIED,
    "attitude_sensor": "motion capture: 1e-4 rad at 180 Hz (OptiTrack cameras measured by "
    "Krumpek et al., arXiv:2502.21189, checked; the 180 Hz rate from the PrimeX 41 datasheet "
    "unverified (from memory); state_of_the_art.ATTITUDE_SENSORS)",
    "estimator": "rls: recursive least squares of the centre-of-mass offset and the drag on "
    "the integrated torque balance, with gravity feed-forward (Kim & Agrawal 2009 estimate "
    "the offset online the same way)",
    "encoder_counts": "4096 counts per turn (a 12-bit encoder; state_of_the_art)" + UNVERIFIED,
    "max_loop_steps": "200000 fixed integration steps per loop run: a run's work is bounded "
    "before it starts",
    "motors": "ideal torque sources unless the scene gives its wheels' motor_bandwidth_Hz "
    "(a first-order lag) and wheel_friction_N_m (Coulomb, against the wheel's momentum): "
    "no default is sourced here (B. Bialke, 'High fidelity mathematical modeling of reaction "
    "wheel performance', AAS 98-063, 1998 gives the model's form; the figures are the "
    "wheel's datasheet's)" + UNVERIFIED,
    "gyro_grades": "order-of-magnitude class figures (bias; angle random walk): navigation "
    "0.01 deg/h, 0.002 deg/sqrt(h); tactical 1 deg/h, 0.1 deg/sqrt(h); industrial 10 deg/h, "
    "0.5 deg/sqrt(h): P. D. Groves, Principles of GNSS, Inertial, and Multisensor Integrated "
    "Navigation Systems, 2nd ed., Artech House 2013, ch. 4 (inertial sensor grades)" + UNVERIFIED,
    "attitude_noise_rad": "the attitude sensor's (attitude_sensor)",
    "rate_Hz": "200 Hz and 1 ms of delay: the contract's example loop",
    "wheels": "limits sized from the planned motion times wheel_margin (1.5: headroom for "
    "noise and disturbances); flight-like wheels give 0.01-0.1 N m (Schwartz, Peck & Hall "
    "2003); give max_torque_N_m and max_momentum_N_m_s to check a real wheel",
    "torque_resolution_N_m": "a 16-bit command over +-max torque: 2 max_torque / 2^16",
    "pyramid_angle_deg": "arccos(1/sqrt(3)) = 54.74 deg: the four-wheel pyramid whose wheels "
    "share the three body axes equally",
    "ballast_material": "brass (8500 kg/m^3, chargedesign.physical.materials): machinable, "
    "non-magnetic, dense",
    "initial": "none: the tool plans motions that fit the bearing (near the stable relative "
    "equilibrium on I3 = 0); a scene's start (initial_gamma, initial_p, initial_q; r from "
    "I3 = 0) is used when it fits",
    "planned_motions": "3: starts at 0.9, 0.6 and 0.3 of the tilt limit from the stable "
    "relative equilibrium (the first is the loop's); the wheels are sized for the largest "
    "need among them",
    "t_end_s": "20 s: the horizon of the issue's outside measurement",
    "target_I4_drift": "1e-3: I4 kept to 0.1 % over the run",
    "drag_feedforward": "0: no drag fed forward (the baseline); a measured drag (spin-down "
    "test) fed forward as a fraction of the bearing's drag cancels that much of it",
    "seeds": "16 noise seeds (and 2 per requirement setting): a spread in seconds of run time; "
    "raise them for tighter percentiles",
}

_TABLE_KEYS = (
    "platform_mass_kg",
    "platform_radius_m",
    "platform_inertia_kg_m2",
    "platform_com_m",
    "bearing",
    "tilt_limit_deg",
    "pedestal_radius_m",
    "bearing_capacity_kg",
    "bearing_radius_m",
    "bearing_gap_m",
    "ballast_material",
    "ballast_spacing_m",
    "mount_material",
    "wheels",
    "pyramid_angle_deg",
    "max_torque_N_m",
    "max_momentum_N_m_s",
    "wheel_margin",
    "torque_resolution_N_m",
    "motor_bandwidth_Hz",
    "wheel_friction_N_m",
    "rate_Hz",
    "delay_s",
    "command",
    "gyro_grade",
    "gyro_arw_rad_per_sqrt_s",
    "gyro_bias_rad_per_s",
    "attitude_sensor",
    "attitude_noise_rad",
    "attitude_rate_Hz",
    "encoder_counts",
    "estimator",
    "imbalance_m",
    "drag_N_m_s",
    "drag_feedforward",
    "initial_gamma",
    "initial_p",
    "initial_q",
    "planned_motions",
    "t_end_s",
    "seeds",
    "target_I4_drift",
    "requirement_rates_Hz",
    "requirement_seeds",
    "max_loop_steps",
)

#: caps on work (a scene asks for no more)
MAX_SEEDS = 10_000
#: the most planned motions the wheels are sized over (one ideal-loop integration each)
MAX_PLANNED_MOTIONS = 64
MAX_SAMPLES = 20_000_000
#: runs x samples an ensemble keeps (states of 6 floats each: 480 MB)
MAX_STORED_SAMPLES = 10_000_000
#: candidate ballast sites a grid may hold (the program's memory grows with them)
MAX_BALLAST_SITES = 100_000
#: rates (Hz) a loop or a requirement setting may take
RATE_RANGE_HZ = (0.1, 100_000.0)
#: the default cap on fixed integration steps per loop run
MAX_LOOP_STEPS = 200_000


@dataclass(frozen=True)
class TestbedOptions:
    """The ``[testbed]`` table, validated (SI units; see docs/testbed.md).

    ``platform_inertia_kg_m2`` and ``platform_com_m`` None mean the hemispherical shell of
    ``platform_mass_kg`` and ``platform_radius_m``; ``max_torque_N_m``,
    ``max_momentum_N_m_s`` None mean sized from the motion; ``drag_N_m_s`` None means
    derived from the bearing; ``torque_resolution_N_m`` None means 16 bits.
    """

    platform_mass_kg: float = 10.0
    platform_radius_m: float = 0.25
    platform_inertia_kg_m2: tuple[tuple[float, ...], ...] | None = None
    platform_com_m: tuple[float, float, float] | None = None
    bearing: str = "tabletop"
    tilt_limit_deg: float | None = None
    pedestal_radius_m: float | None = None
    bearing_capacity_kg: float | None = None
    bearing_radius_m: float = 0.05
    bearing_gap_m: float = 1.0e-5
    ballast_material: str = "brass"
    ballast_spacing_m: float | None = None
    mount_material: str = "steel"
    wheels: str = "orthogonal"
    pyramid_angle_deg: float = math.degrees(math.acos(1.0 / math.sqrt(3.0)))
    max_torque_N_m: float | None = None
    max_momentum_N_m_s: float | None = None
    wheel_margin: float = 1.5
    torque_resolution_N_m: float | None = None
    motor_bandwidth_Hz: float | None = None
    wheel_friction_N_m: float | None = None
    rate_Hz: float = 200.0
    delay_s: float = 1.0e-3
    command: str = "predictive"
    gyro_grade: str = "tactical"
    gyro_arw_rad_per_sqrt_s: float | None = None
    gyro_bias_rad_per_s: float | None = None
    attitude_sensor: str = "motion_capture"
    attitude_noise_rad: float | None = None
    attitude_rate_Hz: float | None = None
    encoder_counts: int | None = None
    estimator: str = "rls"
    imbalance_m: float = BALANCE["automatic_horizontal_m"].value
    drag_N_m_s: float | None = None
    drag_feedforward: float = 0.0
    initial_gamma: tuple[float, float, float] | None = None
    initial_p: float | None = None
    initial_q: float | None = None
    planned_motions: int = 3
    t_end_s: float = 20.0
    seeds: int = 16
    target_I4_drift: float = 1.0e-3
    requirement_rates_Hz: tuple[float, ...] = (25.0, 50.0, 100.0, 200.0)
    requirement_seeds: int = 2
    max_loop_steps: int = MAX_LOOP_STEPS

    __test__ = False  # not a pytest class (its name starts with Test)

    @classmethod
    def from_table(cls, table: Mapping[str, Any] | None, where: str = "testbed") -> TestbedOptions:
        """Validate a ``[testbed]`` table (one-line errors naming ``testbed.<key>``)."""
        if table is None:
            table = {}
        if not isinstance(table, Mapping):
            raise input_error(where, "a table", table)
        check_keys(table, _TABLE_KEYS, where)
        defaults = cls()
        values: dict[str, Any] = {}
        for f in fields(cls):
            if f.name not in table:
                continue
            values[f.name] = _parse(f.name, table[f.name], f"{where}.{f.name}")
        out = cls(**{**{f.name: getattr(defaults, f.name) for f in fields(cls)}, **values})
        out._check_together(where)
        return out

    def _check_together(self, where: str) -> None:
        if self.delay_s >= 1.0 / self.rate_Hz:
            raise InputError(
                f"{where}.delay_s: expected a delay shorter than one control period "
                f"(1/rate_Hz = {fmt(1.0 / self.rate_Hz, CELL)} s), got {self.delay_s!r}"
            )
        if self.platform_mass_kg > self.capacity_kg:
            raise InputError(
                f"{where}.platform_mass_kg: the platform ({fmt(self.platform_mass_kg, PLAIN)} kg)"
                f" is heavier than the {self.bearing} bearing's rating ("
                f"{fmt(self.capacity_kg, PLAIN)} kg; bearing_capacity_kg gives yours)"
            )
        if self.pedestal_radius_m is not None and self.pedestal_radius_m >= self.bearing_radius_m:
            raise InputError(
                f"{where}.pedestal_radius_m: expected less than bearing_radius_m "
                f"({fmt(self.bearing_radius_m, PLAIN)} m), got {self.pedestal_radius_m!r}"
            )
        if self.bearing != "full_sphere" and self.keep_out_half_angle_deg >= 90.0:
            raise InputError(
                f"{where}.tilt_limit_deg: a {self.bearing} bearing's pedestal must stay below the "
                f"platform: the tilt limit plus the pedestal's width "
                f"({fmt(self.keep_out_half_angle_deg, PLAIN)} deg) must be under 90 deg; give a "
                'smaller tilt_limit_deg or bearing = "full_sphere"'
            )
        start = (self.initial_gamma, self.initial_p, self.initial_q)
        if any(v is not None for v in start) and any(v is None for v in start):
            raise InputError(
                f"{where}.initial_gamma: a start needs all of initial_gamma, initial_p and "
                "initial_q (or none of them: the tool plans motions that fit the bearing)"
            )
        rates = [("rate_Hz", self.rate_Hz)]
        rates += [("requirement_rates_Hz", r) for r in self.requirement_rates_Hz]
        for rate_name, rate in rates:
            if self.t_end_s * rate < 1.0:
                raise InputError(
                    f"{where}.t_end_s: {fmt(self.t_end_s, PLAIN)} s is shorter than one control "
                    f"period at {rate_name} = {fmt(rate, PLAIN)} Hz; give at least "
                    f"{fmt(1.0 / rate, CELL)} s"
                )
        if self.ballast_spacing_m is not None:
            k = 2 * math.floor(self.platform_radius_m / self.ballast_spacing_m) + 1
            if k**3 > MAX_BALLAST_SITES:
                raise InputError(
                    f"{where}.ballast_spacing_m: {fmt(self.ballast_spacing_m, PLAIN)} m over a "
                    f"{fmt(self.platform_radius_m, PLAIN)} m platform is a grid of "
                    f"{float(k) ** 3:.3g} "
                    f"candidate sites (about {float(k) ** 3 * 96 / 1e6:.3g} MB for the ballast "
                    f"program), more than the cap of {MAX_BALLAST_SITES}; give a larger "
                    "ballast_spacing_m"
                )
        if self.bearing_radius_m >= self.platform_radius_m:
            raise InputError(
                f"{where}.bearing_radius_m: expected less than platform_radius_m "
                f"({fmt(self.platform_radius_m, PLAIN)} m), got {self.bearing_radius_m!r}"
            )
        self._check_work(where)

    def _check_work(self, where: str) -> None:
        """The start and the amount of work (samples integrated and kept)."""
        if self.initial_gamma is not None:
            gamma = np.array(self.initial_gamma)
            if np.linalg.norm(gamma) == 0.0 or abs(gamma[2]) < 1e-8 * np.linalg.norm(gamma):
                raise InputError(
                    f"{where}.initial_gamma: expected a vector with gamma3 != 0 (r is solved "
                    f"from I3 = 0), got {list(self.initial_gamma)!r}"
                )
        fastest = max(self.rate_Hz, *self.requirement_rates_Hz)
        if self.t_end_s * fastest > MAX_SAMPLES:
            raise InputError(
                f"{where}.t_end_s: {fmt(self.t_end_s, PLAIN)} s at {fmt(fastest, PLAIN)} Hz is more"
                " than "
                f"{MAX_SAMPLES} control samples; shorten it or lower the rates"
            )
        stored = max(self.seeds, len(GYRO_GRADES) * self.requirement_seeds) * self.t_end_s
        if stored * max(self.rate_Hz, *self.requirement_rates_Hz) > MAX_STORED_SAMPLES:
            raise InputError(
                f"{where}.seeds: {self.seeds} seeds ({self.requirement_seeds} per requirement "
                f"setting) over {fmt(self.t_end_s, PLAIN)} s keep more than {MAX_STORED_SAMPLES}"
                " samples; "
                "ask for fewer seeds, a shorter t_end_s or lower rates"
            )

    @property
    def gyro(self) -> tuple[float, float]:
        """(angle random walk rad/sqrt(s), bias rad/s): the grade's, or the scene's values."""
        arw, bias = GYRO_GRADES[self.gyro_grade]
        if self.gyro_arw_rad_per_sqrt_s is not None:
            arw = self.gyro_arw_rad_per_sqrt_s
        if self.gyro_bias_rad_per_s is not None:
            bias = self.gyro_bias_rad_per_s
        return arw, bias

    @property
    def style(self) -> Any:
        return BEARINGS[self.bearing]

    @property
    def tilt_limit(self) -> float:
        """The bearing's tilt limit, deg: the scene's, or the style's."""
        return self.tilt_limit_deg if self.tilt_limit_deg is not None else self.style.tilt_limit_deg

    @property
    def capacity_kg(self) -> float:
        """The bearing's rated load, kg: the scene's, or the style's."""
        if self.bearing_capacity_kg is not None:
            return self.bearing_capacity_kg
        return float(self.style.load_kg)

    @property
    def pedestal_radius(self) -> float:
        """The pedestal's radius, m (0 for a full sphere)."""
        if self.pedestal_radius_m is not None:
            return self.pedestal_radius_m
        return self.style.pedestal_ratio * self.bearing_radius_m

    @property
    def keep_out_half_angle_deg(self) -> float:
        """The tilt limit plus the pedestal's angular half-width at the ball."""
        width = math.degrees(math.asin(min(1.0, self.pedestal_radius / self.bearing_radius_m)))
        return self.tilt_limit + width

    @property
    def attitude(self) -> tuple[float, float]:
        """(noise per sample rad, update rate Hz): the sensor's, or the scene's values."""
        noise, rate = ATTITUDE_SENSORS[self.attitude_sensor]
        return (
            noise.value if self.attitude_noise_rad is None else self.attitude_noise_rad,
            rate.value if self.attitude_rate_Hz is None else self.attitude_rate_Hz,
        )

    @property
    def has_start(self) -> bool:
        return self.initial_gamma is not None

    @property
    def drag(self) -> float:
        """Bearing drag coefficient, N m s: the scene's, or the air film's Couette drag (for a
        full sphere, the film between the whole ball and its cup)."""
        if self.drag_N_m_s is not None:
            return self.drag_N_m_s
        if self.bearing == "full_sphere":
            return cup_drag(self.platform_radius_m, self.bearing_gap_m)
        return bearing_drag(self.bearing_radius_m, self.bearing_gap_m)

    @property
    def ballast_density(self) -> float:
        return BALLAST_DENSITY[self.ballast_material]

    def to_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def bearing_drag(radius: float, gap: float, viscosity: float = AIR_VISCOSITY) -> float:
    """Viscous drag coefficient (N m s) of a hemispherical air film: ``(4 pi/3) eta R^4 / h``.

    The film's shear stress is ``eta v / h`` with ``v = omega R sin(theta)`` at polar angle
    theta from the spin axis; its torque ``int (eta omega R sin / h) R sin R^2 sin dtheta
    dphi`` over the hemisphere is ``(4 pi / 3) eta R^4 omega / h``.
    """
    return 4.0 * math.pi / 3.0 * viscosity * radius**4 / gap


def cup_half_angle() -> float:
    """The full sphere's cup half-angle, rad (from its coverage, state_of_the_art)."""
    coverage = FULL_SPHERE["cup_coverage_sr"].value
    return math.acos(1.0 - coverage / (2.0 * math.pi))


def cup_drag(radius: float, gap: float) -> float:
    """Couette drag (N m s) of a cup of half-angle a under a ball of radius R, about the
    cup's axis: the hemisphere's ``(4 pi/3) eta R^4 / h`` times the cap's share of
    ``int sin^3``, ``(2/3 - cos a + cos^3 a / 3) / (2/3)`` (a spin about the axis; other axes
    shear the film no more than this order)."""
    c = math.cos(cup_half_angle())
    return (2.0 / 3.0 - c + c**3 / 3.0) / (2.0 / 3.0) * bearing_drag(radius, gap)


_POSITIVE = (
    "pedestal_radius_m",
    "attitude_rate_Hz",
    "motor_bandwidth_Hz",
    "platform_mass_kg",
    "platform_radius_m",
    "bearing_capacity_kg",
    "bearing_radius_m",
    "bearing_gap_m",
    "ballast_spacing_m",
    "max_torque_N_m",
    "max_momentum_N_m_s",
    "torque_resolution_N_m",
    "rate_Hz",
    "t_end_s",
    "target_I4_drift",
)
_NONNEGATIVE = (
    "delay_s",
    "gyro_arw_rad_per_sqrt_s",
    "gyro_bias_rad_per_s",
    "attitude_noise_rad",
    "imbalance_m",
    "drag_N_m_s",
    "wheel_friction_N_m",
)
_CHOICES = {
    "ballast_material": tuple(BALLAST_DENSITY),
    "wheels": WHEEL_ARRAYS,
    "command": COMMANDS,
    "gyro_grade": tuple(GYRO_GRADES),
    "bearing": BEARING_STYLES,
    "mount_material": tuple(MOUNT_MATERIALS),
    "attitude_sensor": ATTITUDE_SENSOR_NAMES,
    "estimator": ESTIMATORS,
}


def _parse(name: str, value: Any, where: str) -> Any:
    if name in _CHOICES:
        if value not in _CHOICES[name]:
            raise input_error(where, "one of " + ", ".join(_CHOICES[name]), value)
        return value
    if name in ("seeds", "requirement_seeds"):
        return as_count(value, where, minimum=1, cap=MAX_SEEDS)
    if name == "planned_motions":
        return as_count(value, where, minimum=1, cap=MAX_PLANNED_MOTIONS)
    if name == "encoder_counts":
        return as_count(value, where, minimum=16, cap=2**32)
    if name == "max_loop_steps":
        return as_count(value, where, minimum=1000, cap=10**9)
    if name == "platform_inertia_kg_m2":
        return _inertia(value, where)
    if name in ("platform_com_m", "initial_gamma"):
        return tuple(float(x) for x in as_array(value, where, (3,)))
    if name == "requirement_rates_Hz":
        rates = as_array(value, where, (None,))
        low, high = RATE_RANGE_HZ
        if rates.size == 0 or rates.size > 12 or (rates < low).any() or (rates > high).any():
            raise input_error(
                where, f"1 to 12 rates in {fmt(low, PLAIN)}..{fmt(high, PLAIN)} Hz", value
            )
        return tuple(sorted(float(x) for x in rates))
    number = as_finite_float(value, where, positive=name in _POSITIVE)
    if name in _NONNEGATIVE and number < 0.0:
        raise input_error(where, "a number >= 0", value)
    if name == "wheel_margin" and number < 1.0:
        raise input_error(where, "a margin >= 1", value)
    if name == "drag_feedforward" and not 0.0 <= number <= 1.0:
        raise input_error(where, "the fraction of the drag fed forward, in 0..1", value)
    if name == "rate_Hz" and not RATE_RANGE_HZ[0] <= number <= RATE_RANGE_HZ[1]:
        raise input_error(
            where,
            f"a control rate in {fmt(RATE_RANGE_HZ[0], PLAIN)}..{fmt(RATE_RANGE_HZ[1], PLAIN)} Hz",
            value,
        )
    if name == "tilt_limit_deg" and not 0.0 < number <= 180.0:
        raise input_error(where, "a tilt limit in (0, 180] deg", value)
    if name == "pyramid_angle_deg" and not 5.0 <= number <= 85.0:
        raise input_error(where, "an angle from the body z axis in 5..85 deg", value)
    return number


def _inertia(value: Any, where: str) -> tuple[tuple[float, ...], ...]:
    matrix = as_array(value, where, (3, 3))
    if abs(matrix - matrix.T).max() > 1e-12 * max(1.0, abs(matrix).max()):
        raise input_error(where, "a symmetric 3x3 inertia matrix (kg m^2)", value)
    eig = np.linalg.eigvalsh(matrix)
    if eig[0] <= 0.0 or eig[2] > eig[0] + eig[1] + 1e-12 * eig[2]:
        raise input_error(where, "a physical inertia (positive, triangle inequality)", value)
    return tuple(tuple(float(x) for x in row) for row in matrix)


def table_schema() -> dict[str, Any]:
    """The ``[testbed]`` table's JSON-schema fragment (closed: unknown keys are refused)."""
    number = {"type": "number"}
    positive = {"type": "number", "exclusiveMinimum": 0}
    nonneg = {"type": "number", "minimum": 0}
    vector = {"type": "array", "items": number, "minItems": 3, "maxItems": 3}
    props: dict[str, Any] = {}
    for name in _TABLE_KEYS:
        if name in _CHOICES:
            props[name] = {"enum": list(_CHOICES[name])}
        elif name in _POSITIVE:
            props[name] = positive
        elif name in _NONNEGATIVE:
            props[name] = nonneg
        elif name in ("seeds", "requirement_seeds"):
            props[name] = {"type": "integer", "minimum": 1, "maximum": MAX_SEEDS}
        elif name == "planned_motions":
            props[name] = {"type": "integer", "minimum": 1, "maximum": MAX_PLANNED_MOTIONS}
        elif name == "encoder_counts":
            props[name] = {"type": "integer", "minimum": 16}
        elif name == "max_loop_steps":
            props[name] = {"type": "integer", "minimum": 1000}
        elif name == "tilt_limit_deg":
            props[name] = {"type": "number", "exclusiveMinimum": 0, "maximum": 180}
        elif name == "platform_inertia_kg_m2":
            props[name] = {"type": "array", "items": vector, "minItems": 3, "maxItems": 3}
        elif name in ("platform_com_m", "initial_gamma"):
            props[name] = vector
        elif name == "requirement_rates_Hz":
            props[name] = {
                "type": "array",
                "items": {
                    "type": "number",
                    "minimum": RATE_RANGE_HZ[0],
                    "maximum": RATE_RANGE_HZ[1],
                },
                "minItems": 1,
                "maxItems": 12,
            }
        elif name == "drag_feedforward":
            props[name] = {"type": "number", "minimum": 0, "maximum": 1}
        else:
            props[name] = number
    return {
        "type": "object",
        "description": "the air-bearing testbed (docs/testbed.md): platform, ballast, wheels, "
        "sampled loop, sensors, disturbances, requirements",
        "properties": props,
        "additionalProperties": False,
    }


__all__ = [
    "AIR_VISCOSITY",
    "COMMANDS",
    "GYRO_GRADES",
    "MAX_PLANNED_MOTIONS",
    "SOURCES",
    "WHEEL_ARRAYS",
    "TestbedOptions",
    "bearing_drag",
    "table_schema",
]
