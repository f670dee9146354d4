"""The ``[testbed]`` scene table read into the typed :class:`TestbedOptions`.

Every key is declared once, with its range, unit, default and the default's source, in
:data:`chargedesign.scene.keys.TESTBED`; the options' defaults, the one-line refusals, the
JSON Schema, the docs' table (docs/testbed.md) and testbed.json's ``sources`` follow from it.
Checks that join several keys (a delay shorter than a period, the work a run may do) and the
checks of a key against what the run finds it needs (:meth:`TestbedOptions.check_capacity`
and the like: the same one-line refusals, raised here, at the boundary) are this module's.
All values are SI.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from types import SimpleNamespace
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import CELL, PLAIN, PRECISE, fmt
from chargedesign.physical.drag import bearing_drag, cup_drag
from chargedesign.physical.materials import BALLAST_DENSITY
from chargedesign.physical.state_of_the_art import ATTITUDE_SENSORS, BEARINGS, GYROS
from chargedesign.scene.keys import KEY, TESTBED, Key, check_declared, check_table, declared
from chargedesign.validation import as_array, input_error

#: gyro grades: (angle random walk rad/sqrt(s), bias rad/s), order-of-magnitude figures of each
#: class (chargedesign.physical.state_of_the_art.GYROS); ``ideal`` is a perfect gyro (the
#: loop's own limit)
GYRO_GRADES: dict[str, tuple[float, float]] = {
    "ideal": (0.0, 0.0),
    **{name: (arw.value, bias.value) for name, (arw, bias) in GYROS.items()},
}
assert list(GYRO_GRADES) == declared("testbed", KEY.gyro_grade).schema["enum"]

#: testbed.json's ``sources`` (and the report's list): each default's declared source, under
#: its key's name, or the name of the group of keys that share it
_SOURCE_GROUPS = {
    KEY.platform_mass_kg: "platform",
    KEY.motor_bandwidth_Hz: "motors",
    KEY.gyro_grade: "gyro_grades",
    KEY.max_torque_N_m: "wheels",
    KEY.initial_gamma: "initial",
}
_SOURCE_ORDER = (
    KEY.platform_mass_kg,
    KEY.bearing_capacity_kg,
    KEY.drag_N_m_s,
    KEY.bearing_gap_m,
    KEY.imbalance_m,
    KEY.bearing,
    KEY.pedestal_radius_m,
    KEY.mount_material,
    KEY.attitude_sensor,
    KEY.estimator,
    KEY.encoder_counts,
    KEY.max_loop_steps,
    KEY.motor_bandwidth_Hz,
    KEY.gyro_grade,
    KEY.attitude_noise_rad,
    KEY.rate_Hz,
    KEY.max_torque_N_m,
    KEY.torque_resolution_N_m,
    KEY.pyramid_angle_deg,
    KEY.ballast_material,
    KEY.initial_gamma,
    KEY.planned_motions,
    KEY.t_end_s,
    KEY.target_I4_drift,
    KEY.drag_feedforward,
    KEY.seeds,
)
SOURCES = {_SOURCE_GROUPS.get(k, k): declared("testbed", k).source for k in _SOURCE_ORDER}

#: caps on work (a scene asks for no more)
MAX_SAMPLES = 20_000_000
#: runs x samples an ensemble keeps (states of 6 floats each: 480 MB)
MAX_STORED_SAMPLES = 10_000_000
#: bytes the testbed holds per run (seed), whatever its length, and per run and control sample
#: (states, the wheels' momentum, the invariants and their drift curves), measured here with
#: the example's testbed at 50 Hz: 100 -> 300 seeds over 5 s raised the peak memory by
#: 218 MB (1.1 MB a seed), 5 -> 10 s with 300 seeds by 13 MB (170 B a run-sample)
BYTES_PER_RUN = 1_200_000
BYTES_PER_RUN_SAMPLE = 200
#: CPU seconds per run and control sample, measured with the same runs (3e-5 s)
SECONDS_PER_RUN_SAMPLE = 3e-5
#: the memory a testbed run may take (well below the machine's: `seeds = 2000`,
#: `t_end_s = 5` needed more than 4 GB and was accepted under MAX_STORED_SAMPLES)
MAX_TESTBED_BYTES = 2 * 1024**3
#: candidate ballast sites a grid may hold (the program's memory grows with them)
MAX_BALLAST_SITES = 100_000
#: every key's declared default (None where the default is derived from other keys)
_DEFAULT = SimpleNamespace(**{k.name: k.default if k.has_default else None for k in TESTBED})
#: keys refused as "a number > 0" before their declared range (their refusals since written)
_POSITIVE_FIRST = (KEY.rate_Hz,)


@dataclass(frozen=True)
class TestbedOptions:
    """The ``[testbed]`` table, validated (SI units; see docs/testbed.md).

    ``platform_inertia_kg_m2`` and ``platform_com_m`` None mean the hemispherical shell of
    ``platform_mass_kg`` and ``platform_radius_m``; ``max_torque_N_m``,
    ``max_momentum_N_m_s`` None mean sized from the motion; ``drag_N_m_s`` None means
    derived from the bearing; ``torque_resolution_N_m`` None means 16 bits.
    """

    platform_mass_kg: float = _DEFAULT.platform_mass_kg
    platform_radius_m: float = _DEFAULT.platform_radius_m
    platform_inertia_kg_m2: tuple[tuple[float, ...], ...] | None = _DEFAULT.platform_inertia_kg_m2
    platform_com_m: tuple[float, float, float] | None = _DEFAULT.platform_com_m
    bearing: str = _DEFAULT.bearing
    tilt_limit_deg: float | None = _DEFAULT.tilt_limit_deg
    pedestal_radius_m: float | None = _DEFAULT.pedestal_radius_m
    bearing_capacity_kg: float | None = _DEFAULT.bearing_capacity_kg
    bearing_radius_m: float = _DEFAULT.bearing_radius_m
    bearing_gap_m: float = _DEFAULT.bearing_gap_m
    ballast_material: str = _DEFAULT.ballast_material
    ballast_spacing_m: float | None = _DEFAULT.ballast_spacing_m
    mount_material: str = _DEFAULT.mount_material
    wheels: str = _DEFAULT.wheels
    pyramid_angle_deg: float = _DEFAULT.pyramid_angle_deg
    max_torque_N_m: float | None = _DEFAULT.max_torque_N_m
    max_momentum_N_m_s: float | None = _DEFAULT.max_momentum_N_m_s
    wheel_margin: float = _DEFAULT.wheel_margin
    torque_resolution_N_m: float | None = _DEFAULT.torque_resolution_N_m
    motor_bandwidth_Hz: float | None = _DEFAULT.motor_bandwidth_Hz
    wheel_friction_N_m: float | None = _DEFAULT.wheel_friction_N_m
    rate_Hz: float = _DEFAULT.rate_Hz
    delay_s: float = _DEFAULT.delay_s
    command: str = _DEFAULT.command
    gyro_grade: str = _DEFAULT.gyro_grade
    gyro_arw_rad_per_sqrt_s: float | None = _DEFAULT.gyro_arw_rad_per_sqrt_s
    gyro_bias_rad_per_s: float | None = _DEFAULT.gyro_bias_rad_per_s
    attitude_sensor: str = _DEFAULT.attitude_sensor
    attitude_noise_rad: float | None = _DEFAULT.attitude_noise_rad
    attitude_rate_Hz: float | None = _DEFAULT.attitude_rate_Hz
    encoder_counts: int | None = _DEFAULT.encoder_counts
    estimator: str = _DEFAULT.estimator
    imbalance_m: float = _DEFAULT.imbalance_m
    drag_N_m_s: float | None = _DEFAULT.drag_N_m_s
    drag_feedforward: float = _DEFAULT.drag_feedforward
    initial_gamma: tuple[float, float, float] | None = _DEFAULT.initial_gamma
    initial_p: float | None = _DEFAULT.initial_p
    initial_q: float | None = _DEFAULT.initial_q
    planned_motions: int = _DEFAULT.planned_motions
    t_end_s: float = _DEFAULT.t_end_s
    seeds: int = _DEFAULT.seeds
    target_I4_drift: float = _DEFAULT.target_I4_drift
    requirement_rates_Hz: tuple[float, ...] = _DEFAULT.requirement_rates_Hz
    requirement_seeds: int = _DEFAULT.requirement_seeds
    max_loop_steps: int = _DEFAULT.max_loop_steps

    __test__ = False  # not a pytest class (its name starts with Test)

    @classmethod
    def from_table(cls, table: Mapping[str, Any] | None, where: str = "testbed") -> TestbedOptions:
        """Validate a ``[testbed]`` table (one-line errors naming ``testbed.<key>``)."""
        table = check_table({} if table is None else table, "testbed", where)
        values: dict[str, Any] = {}
        for f in fields(cls):
            if f.name not in table:
                continue
            values[f.name] = _parse(declared("testbed", f.name), table[f.name], f"{where}.{f.name}")
        out = cls(**values)
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
        if self.bearing == "full_sphere" and self.tilt_limit_deg is not None:
            # a ball floating in its cup has no pedestal: every attitude is free (180 deg).
            # A limit given with it made testbed.json say 180 while its tilt map used the limit
            raise InputError(
                f"{where}.tilt_limit_deg: a full_sphere bearing allows every attitude (no "
                "pedestal); drop tilt_limit_deg, or give a tabletop or umbrella bearing with it"
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
        rates = [(KEY.rate_Hz, self.rate_Hz)]
        rates += [(KEY.requirement_rates_Hz, r) for r in self.requirement_rates_Hz]
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
        if stored * fastest > MAX_STORED_SAMPLES:
            raise InputError(
                f"{where}.seeds: {self.seeds} seeds ({self.requirement_seeds} per requirement "
                f"setting) over {fmt(self.t_end_s, PLAIN)} s keep more than {MAX_STORED_SAMPLES}"
                " samples; "
                "ask for fewer seeds, a shorter t_end_s or lower rates"
            )

        self._check_memory(where)

    def _check_memory(self, where: str) -> None:
        """The peak memory of the runs, estimated from what one batch holds (per run, and per
        run and control sample: the nominal batch, or one rate's batch of the requirement
        sweep, whichever is larger), refused above :data:`MAX_TESTBED_BYTES` with the time."""
        batch = len(GYRO_GRADES) * self.requirement_seeds
        batches = [(self.seeds, self.rate_Hz)] + [(batch, f) for f in self.requirement_rates_Hz]
        peak = max(
            runs * (BYTES_PER_RUN + self.t_end_s * rate * BYTES_PER_RUN_SAMPLE)
            for runs, rate in batches
        )
        if peak > MAX_TESTBED_BYTES:
            seconds = sum(runs * self.t_end_s * f for runs, f in batches) * SECONDS_PER_RUN_SAMPLE
            raise InputError(
                f"{where}.seeds: {self.seeds} seeds over {fmt(self.t_end_s, PLAIN)} s at "
                f"{fmt(self.rate_Hz, PLAIN)} Hz ({self.requirement_seeds} per requirement "
                f"setting) need about {peak / 1024**3:.1f} GiB of memory and "
                f"{seconds:.0f} s (limit {MAX_TESTBED_BYTES / 1024**3:.0f} GiB); ask for fewer "
                "seeds, a shorter t_end_s or lower rates"
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

    def check_parameters(self, singular: bool) -> None:
        """The scene's parameters a testbed can run: lambda and rho 0 (``singular``: their
        torques are singular on gamma3 = 0)."""
        if singular:
            raise InputError(
                "testbed: lambda and rho must be 0 (their torques are singular on gamma3 = 0)"
            )

    def check_case(self, name: str, inertia: Sequence[Any], singular: Sequence[str]) -> None:
        """A case the testbed can fly (:func:`case_refusal`: its ``inertia`` and the
        ``singular`` factors of its V and mu)."""
        reason = case_refusal(name, inertia, singular)
        if reason is not None:
            raise InputError(reason)

    def check_case_start(self, case_name: str) -> None:
        """A case's motion starts from the scene's start: the scene must give one."""
        if not self.has_start:
            raise InputError(
                f"testbed: case {case_name}: give initial_gamma, initial_p and initial_q in "
                "[testbed] (a case's motion starts from the scene's start; r is solved from its "
                "level)"
            )

    def check_case_tilt(self, case_name: str, tilt: float, horizon: float) -> None:
        """A case's motion from the scene's start within the bearing's tilt limit: it needs
        ``tilt`` deg over ``horizon`` s."""
        if tilt > self.tilt_limit:
            raise InputError(
                f"testbed.initial_gamma: case {case_name}'s motion from the scene's start needs "
                f"{fmt(tilt, PRECISE)} deg of tilt (best pedestal axis, over "
                f"{fmt(horizon, PLAIN)} s), the {self.bearing} bearing allows "
                f"{fmt(self.tilt_limit, PLAIN)} deg; give a start nearer a stable equilibrium of "
                'the case, or bearing = "full_sphere"'
            )

    def check_loop_steps(self, rate: float, cause: str, step_fraction: float) -> None:
        """Refuse, before any work, a loop run whose fixed integration steps (no longer than
        ``step_fraction`` over the motion's fastest ``rate``, 1/s, whose source is ``cause``)
        pass ``max_loop_steps``, naming the cause and the option."""
        max_step = step_fraction / rate
        for loop_rate in (self.rate_Hz, *self.requirement_rates_Hz):
            T = 1.0 / loop_rate
            periods = max(1, round(self.t_end_s * loop_rate))
            delay = min(self.delay_s, 0.5 * T)
            per = math.ceil(delay / max_step) + math.ceil((T - delay) / max_step)
            per += math.ceil(delay / max_step) + math.ceil(T / max_step)  # the predictive command
            steps = periods * per
            if steps > self.max_loop_steps or not math.isfinite(rate):
                raise InputError(
                    f"testbed: {cause} makes the motion's fastest rate {fmt(rate, PRECISE)} 1/s, "
                    f"so {fmt(self.t_end_s, PLAIN)} s at {fmt(loop_rate, PLAIN)} Hz needs "
                    f"{float(steps):.3g} integration steps, more than testbed.max_loop_steps = "
                    f"{self.max_loop_steps}; give a slower start or smaller parameters, a shorter "
                    "t_end_s, or raise testbed.max_loop_steps"
                )

    def check_start_tilt(
        self, tilt: float, limit: float, horizon: float, alternatives: str
    ) -> None:
        """The scene's start within the bearing's tilt ``limit`` (deg): it needs ``tilt`` deg
        over ``horizon`` s; ``alternatives`` says what would fit."""
        if tilt > limit:
            raise InputError(
                f"testbed.initial_gamma: the scene's start needs {fmt(tilt, PRECISE)} deg of "
                f"tilt (best pedestal axis, over {fmt(horizon, PLAIN)} s), the "
                f"{self.bearing} bearing allows {fmt(limit, PLAIN)} deg; "
                f"{alternatives}"
            )

    def check_torque_step(self, resolution: float, need: float) -> None:
        """The wheels' torque step ``resolution`` (N m) at most a tenth of the most torque a
        planned motion ``need``s."""
        if resolution > need / 10.0:
            key = KEY.torque_resolution_N_m if self.torque_resolution_N_m else KEY.max_torque_N_m
            raise InputError(
                f"testbed.{key}: the torque step {fmt(resolution, PRECISE)} N m is more than a "
                f"tenth of the most torque a planned motion needs ({fmt(need, PRECISE)} N m): "
                "the commands would round to a few levels or to zero (an open loop); give a finer "
                "torque_resolution_N_m or a max_torque_N_m nearer the need"
            )

    def check_capacity(self, total_mass: float) -> None:
        """The platform with its ballast and posts (``total_mass``, kg) within the bearing's
        rating."""
        if total_mass > self.capacity_kg:
            raise InputError(
                "testbed.bearing_capacity_kg: the platform with its ballast and posts"
                f" ({fmt(total_mass, PRECISE)} kg) is heavier than the {self.bearing} bearing's "
                f"rating ({fmt(self.capacity_kg, PLAIN)} kg)"
            )


def case_refusal(name: str, inertia: Sequence[Any], singular: Sequence[str]) -> str | None:
    """Why the testbed cannot fly case ``name`` (one line), or None: its ``inertia`` (exact
    numbers) not diag(2C, 2C, C), or ``singular`` (the ``"<factor> = 0"`` on which its V or mu
    blows up) not empty."""
    A, B, C = inertia
    if not (A == B == 2 * C):
        return (
            f"testbed: case {name}: inertia diag({A}, {B}, {C}) is not realisable by the "
            "platform, whose ballast closes diag(2C, 2C, C) only (the layout's least-mass "
            "program); the testbed flies cases of that inertia"
        )
    if singular:
        return (
            f"testbed: case {name}: V or mu is singular on {', '.join(singular)}, so the "
            "wheels' torque would be unbounded there; the testbed flies cases whose V and mu "
            "are finite on the whole sphere"
        )
    return None


def as_count(value: Any, name: str, *, minimum: int, cap: int) -> int:
    """An integer in ``minimum..cap`` (a cap on work)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise input_error(name, "an integer", value)
    if value < minimum:
        raise input_error(name, f"an integer >= {minimum}", value)
    if value > cap:
        raise input_error(name, f"an integer <= {cap}", value)
    return int(value)


def _parse(key: Key, value: Any, where: str) -> Any:
    """One key's value checked against its declaration (one-line refusals naming ``where``)."""
    spec = key.schema
    kind = spec.get("type")
    if kind == "integer":
        return as_count(value, where, minimum=spec["minimum"], cap=spec["maximum"])
    if kind == "array":
        items = spec["items"]
        if items.get("type") == "array":
            return _inertia(value, where, key.refusal)
        if spec.get("minItems") == spec.get("maxItems") == 3:
            return tuple(float(x) for x in as_array(value, where, (3,)))
        rates = as_array(value, where, (None,))
        low, high = items["minimum"], items["maximum"]
        if not spec["minItems"] <= rates.size <= spec["maxItems"] or (
            (rates < low).any() or (rates > high).any()
        ):
            raise input_error(where, key.refusal, value)
        return tuple(sorted(float(x) for x in rates))
    return check_declared(key, value, where, positive=key.name in _POSITIVE_FIRST)


def _inertia(value: Any, where: str, refusal: str) -> tuple[tuple[float, ...], ...]:
    matrix = as_array(value, where, (3, 3))
    if abs(matrix - matrix.T).max() > 1e-12 * max(1.0, abs(matrix).max()):
        raise input_error(where, refusal, value)
    eig = np.linalg.eigvalsh(matrix)
    if eig[0] <= 0.0 or eig[2] > eig[0] + eig[1] + 1e-12 * eig[2]:
        raise input_error(where, "a physical inertia (positive, triangle inequality)", value)
    return tuple(tuple(float(x) for x in row) for row in matrix)


__all__ = [
    "GYRO_GRADES",
    "SOURCES",
    "TestbedOptions",
]
