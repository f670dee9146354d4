"""How the body is held, and what that costs: the support's sourced figures and its items.

The theorem's motion turns the body every way about a fixed point O. Four supports are known
(``[support] style``, :mod:`chargedesign.scene.support`):

- ``free_fall`` in ZARM's Bremen Drop Tower (a drop: 4.74 s; the catapult: 9.3 s). O is the
  centre of mass and every attitude is free. With zero net dipole, a pure quadrupole field (B
  linear in position) exerts no net force and V does not change when the centre of mass sits
  off the field's centre, so the balance in 1 g is no longer a requirement: the realised
  window's gravity law then uses the facility's residual acceleration
  (:func:`window_gravity`). What remains is counted as items: the microgravity time and the
  turns of the motion in it, the residual acceleration, the body's drift relative to the
  coils over the flight (residual acceleration, a release velocity error, the net force),
  the coils' higher harmonics at that offset (Biot-Savart, :mod:`chargedesign.physical.coils`),
  the net force of the actual coil field on the parts (dipoles and induced magnetisation,
  their dipole sum and the gradient of the gradient), the gravity gradient, the capsule's
  room and the body's own vacuum chamber (the capsule is at normal pressure).
- ``orbit``: residual acceleration, the gravity-gradient torque at the orbit's rate, the net
  force (figures marked unsourced).
- ``electrostatic``: a suspension like Gravity Probe B's (its rotors' spin-down times), and
  what 1 g would need (the field that lifts the body, the torque of an aspherical rotor).
- ``air_bearing``: today's full-sphere air bearing (:func:`chargedesign.physical.window.
  support_of`), as items.

:func:`support_record` returns the contract's ``support`` record (design.json):
``{"style", "facility", "microgravity_s", "residual_g", "turns", "net_force_N", "items"}``,
each item ``{"name", "value", "limit", "unit", "met", "source", "checked"}``. Every figure
is in :data:`FIGURES` with its source; ``checked`` is True only for what was read there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.constants import EPSILON_0, MU_0, STANDARD_GRAVITY
from chargedesign.fields import AxisymmetricField
from chargedesign.formatting import PLAIN, ROUGH, fmt
from chargedesign.physical import sources
from chargedesign.physical.coils import WIRE_SECTION, CoilPair
from chargedesign.physical.realism import material_parts, model_scales, region_radius
from chargedesign.physical.window import REALISED_FRACTION, WindowModel, window_model
from chargedesign.scene.keys import KEY
from chargedesign.scene.support import SupportOptions

#: the Boltzmann constant, J/K (exact, SI 2019)
BOLTZMANN = 1.380649e-23


#: the keys of every figure the supports use; their values and sources are the project's
#: sources table's (chargedesign/data/sources.toml, :mod:`chargedesign.physical.sources`)
SUPPORT_KEYS = (
    "drop_tower.drop_time_s",
    "drop_tower.catapult_time_s",
    "drop_tower.residual_g",
    "drop_tower.capsule_diameter_m",
    "drop_tower.capsule_length_m",
    "drop_tower.capsule_pressure_Pa",
    "drop_tower.tube_pressure_fraction",
    "drop_tower.capsule_total_mass_kg",
    "drop_tower.catapult_launch_s",
    "drop_tower.catapult_launch_g",
    "drop_tower.landing_g",
    "drop_tower.release_velocity_error_m_per_s",
    "drop_tower.release_and_cage_s",
    "chamber.pressure_Pa",
    "chamber.bore_share",
    "copper.density_kg_per_m3",
    "gas.air_molecular_mass_kg",
    "gas.temperature_K",
    "earth.radius_m",
    "orbit.residual_g",
    "orbit.altitude_m",
    "orbit.run_s",
    "gpb.rotor_diameter_m",
    "gpb.spin_down_years_min",
    "gpb.spin_down_years_max",
    "rotor.coating_conductivity_S_per_m",
    "rotor.coating_thickness_m",
    "gpb.sphericity_m",
    "camera.frame_rate_Hz",
    "camera.marker_noise_across_m",
    "camera.marker_noise_along_m",
    "camera.static_marker_precision_m",
)
FIGURES: dict[str, sources.SourceRow] = {key: sources.source(key) for key in SUPPORT_KEYS}

#: the turns the motion must make within the flight (issue 40)
MIN_TURNS = 5.0
#: orientations sampled for the net force and the coils' harmonics at the offset
ORIENTATIONS = 200
#: step of the central differences of the coils' field, in coil radii
FIELD_STEP = 1e-4
_FACILITY_TIME = {
    "drop_tower_drop": "drop_tower.drop_time_s",
    "drop_tower_catapult": "drop_tower.catapult_time_s",
}


def figure(key: str) -> float:
    """The value of one of :data:`FIGURES`."""
    return FIGURES[key].value


def residual_g(support: SupportOptions) -> float | None:
    """The support's residual acceleration in g (None: a lab in 1 g)."""
    if support.style == "free_fall":
        return figure("drop_tower.residual_g")
    if support.style == "orbit":
        return figure("orbit.residual_g")
    return None


def window_gravity(support: SupportOptions, given: float) -> float:
    """The gravity (m/s^2) the realised window's balance law uses: the residual acceleration in
    free fall and in orbit (the balance is no longer a requirement there), ``given`` (the
    scene's ``[design] realised_gravity``) otherwise."""
    g = residual_g(support)
    return given if g is None else g * STANDARD_GRAVITY


def scene_window_gravity(scene: Any) -> float:
    """:func:`window_gravity` of a scene: ``[design] realised_gravity`` when the scene gives
    it, else its support's."""
    if KEY.realised_gravity in scene.table("design"):
        return float(scene.design.realised_gravity)
    return window_gravity(scene.support, scene.design.realised_gravity)


def item(
    name: str, value: float, limit: float, unit: str, met: bool, key: str | None = None
) -> dict[str, Any]:
    """One support item; ``key`` names its figure in :data:`FIGURES` (its source)."""
    out: dict[str, Any] = {
        "name": name,
        "value": float(value),
        "limit": float(limit),
        "unit": unit,
        "met": bool(met),
    }
    if key is not None:
        row = FIGURES[key]
        out["source"] = f"{key}: {row.source}, {row.locator}" + (
            "" if row.checked else " [unchecked]"
        )
        out["checked"] = FIGURES[key].checked
    else:
        out["source"] = "computed from the design"
        out["checked"] = True
    return out


def at_most(
    name: str, value: float, limit: float, unit: str, key: str | None = None
) -> dict[str, Any]:
    """The :func:`item` of a figure that must stay at or below its ``limit``."""
    return item(name, value, limit, unit, value <= limit, key)


# ----------------------------------------------------------------------------- the field


def coil_pairs(model: WindowModel) -> list[CoilPair]:
    """The window's coil pairs (the body's own apparatus, Biot-Savart)."""
    return list(model.apparatus.pairs) if model.apparatus is not None else []


def _coil_field(pairs: list[CoilPair], points: np.ndarray) -> np.ndarray:
    out = np.zeros((len(points), 3))
    for pair in pairs:
        out += pair.field(points)
    return out


def _rotations(count: int, seed: int = 0) -> np.ndarray:
    """``count`` body-to-space rotations, the identity first, then uniform (seeded)."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(count, 4))
    q[0] = (1.0, 0.0, 0.0, 0.0)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


@dataclass
class FieldOnParts:
    """The coils' field on the parts at one offset of the centre of mass from the field's
    centre: the largest net force over orientations (N), the range over orientations of the
    magnets' energy in the coils less the designed field's (J), and the dipole sum (A m^2)."""

    offset_m: float
    net_force_N: float
    net_force_dipoles_N: float
    net_force_induced_N: float
    energy_error_J: float
    dipole_sum: float
    dipole_magnitudes: float


def field_on_parts(
    design: Any, pairs: list[CoilPair], offset: np.ndarray, count: int = ORIENTATIONS
) -> FieldOnParts:
    """Net force and energy error of the parts in the coils' Biot-Savart field, with the body's
    centre of mass (O) at ``offset`` (m, space axes) from the field's centre.

    Force on a dipole: ``grad (m . B)``; on a part of susceptibility chi and volume v:
    ``grad (chi v |B|^2 / (2 mu0))`` (chi << 1); both by central differences of the
    Biot-Savart field. In a pure quadrupole the dipoles' sum is ``G sum m`` (zero for zero net
    dipole) and the induced sum ``chi v G^2 X / mu0`` summed over the parts; the coils'
    higher harmonics (the gradient of the gradient) add the rest.
    """
    offset = np.asarray(offset, dtype=float)
    positions = np.asarray(design.dipole_positions, dtype=float).reshape(-1, 3)
    moments = np.asarray(design.dipole_moments, dtype=float).reshape(-1, 3)
    parts = [p for p in material_parts(design) if p.get("chi")]
    legendre = tuple(design.field("magnetic"))
    designed = AxisymmetricField(legendre[:2]) if legendre else None
    h = FIELD_STEP * max((p.radius for p in pairs), default=1.0)
    steps = h * np.eye(3)
    rotations = _rotations(count)  # (r, 3, 3)

    def placed(points: np.ndarray) -> np.ndarray:
        """``points`` (k, 3) turned by every rotation and offset: (r, k, 3)."""
        return np.einsum("rij,kj->rki", rotations, points) + offset

    def field(X: np.ndarray) -> np.ndarray:
        return _coil_field(pairs, X.reshape(-1, 3)).reshape(X.shape)

    force_dip = np.zeros((count, 3))
    errors = np.zeros(count)
    if len(moments) and pairs:
        X = placed(positions)
        m = np.einsum("rij,kj->rki", rotations, moments)
        for k, s in enumerate(steps):
            force_dip[:, k] = np.sum(m * (field(X + s) - field(X - s)), axis=(1, 2)) / (2 * h)
        errors = -np.sum(m * field(X), axis=(1, 2))
        if designed is not None:
            centred = np.einsum("rij,kj->rki", rotations, positions)
            ideal = designed.gradient(centred.reshape(-1, 3)).reshape(centred.shape)
            errors = errors - np.sum(m * ideal, axis=(1, 2))
    force_ind = np.zeros((count, 3))
    for part in parts if pairs else []:
        X = placed(np.asarray(part["centres"], dtype=float).reshape(-1, 3))
        weight = float(part["chi"]) * np.asarray(part["volumes"], dtype=float) / (2 * MU_0)
        for k, s in enumerate(steps):
            up = np.sum(field(X + s) ** 2, axis=2)
            down = np.sum(field(X - s) ** 2, axis=2)
            force_ind[:, k] += np.sum(weight * (up - down), axis=1) / (2 * h)
    worst = float(np.max(np.linalg.norm(force_dip + force_ind, axis=1)))
    worst_dip = float(np.max(np.linalg.norm(force_dip, axis=1)))
    worst_ind = float(np.max(np.linalg.norm(force_ind, axis=1)))
    energy_error = float(np.ptp(errors)) if len(moments) else 0.0
    return FieldOnParts(
        float(np.linalg.norm(offset)),
        worst,
        worst_dip,
        worst_ind,
        energy_error,
        float(np.linalg.norm(moments.sum(axis=0))) if len(moments) else 0.0,
        float(np.sum(np.linalg.norm(moments, axis=1))) if len(moments) else 0.0,
    )


def free_molecular_torque(pressure: float, radius: float, rate: float) -> float:
    """Drag torque (N m) on a sphere of ``radius`` turning at ``rate`` in a rarefied gas at
    ``pressure`` (free molecular flow, diffuse reflection): each molecule leaving the surface
    carries its tangential velocity, ``tau = (2 pi / 3) p sqrt(8 m / (pi k T)) omega R^4``."""
    m, temperature = figure("gas.air_molecular_mass_kg"), figure("gas.temperature_K")
    return (
        2.0
        * math.pi
        / 3.0
        * pressure
        * math.sqrt(8.0 * m / (math.pi * BOLTZMANN * temperature))
        * rate
        * radius**4
    )


def tidal_torque(rate_squared: float, C: float) -> float:
    """Largest gravity-gradient torque (N m) on the theorem's inertia diag(2C, 2C, C) where
    the gradient's rate is ``GM / r^3 = rate_squared``: ``(3/2) (GM / r^3) (A - C)``."""
    return 1.5 * rate_squared * (2.0 * C - C)


def coil_room(pairs: list[CoilPair]) -> tuple[float, float, float]:
    """The coils' outer diameter, axial length (m) and copper mass (kg): a square winding of
    ``turns`` wires of :data:`~chargedesign.physical.coils.WIRE_SECTION` on each loop."""
    diameter = length = mass = 0.0
    for pair in pairs:
        side = math.sqrt(pair.turns * WIRE_SECTION)
        diameter = max(diameter, 2.0 * (pair.radius + side))
        length = max(length, pair.separation + side)
        mass += (
            2.0
            * 2.0
            * math.pi
            * pair.radius
            * pair.turns
            * WIRE_SECTION
            * figure("copper.density_kg_per_m3")
        )
    return diameter, length, mass


# ---------------------------------------------------------------------------- the record


@dataclass
class _Body:
    """What every support reads from the design."""

    model: WindowModel
    pairs: list[CoilPair]
    region: float
    mass: float
    rate: float
    C: float
    fraction: float

    @property
    def term(self) -> float:
        return self.model.term_size


def _body(design: Any, gravity: float, fraction: float) -> _Body:
    model = window_model(design, 1.0, fraction=fraction, gravity=gravity)
    scales = model_scales(design, design.body_parameters)
    return _Body(
        model,
        coil_pairs(model),
        region_radius(design),
        float(np.sum(design.all_masses()[1])),
        scales.rate,
        scales.C,
        fraction,
    )


@dataclass
class _Drop:
    """The figures of one drop: times, drift, forces and the field on the parts."""

    facility: str
    time_key: str
    micro: float
    flight: float
    needed: float
    g_res: float
    turns: float
    chamber: float
    clearance: float
    v_err: float
    drift: float
    force: float
    force_limit: float
    residual_limit: float
    harmonic: float
    tidal: float
    room: tuple[float, float, float]
    p_chamber: float
    p_max: float
    p_tube: float
    on: list[Any]
    centred: Any


def _free_fall(design: Any, spec: SupportOptions, body: _Body) -> dict[str, Any]:
    drop = _drop(design, spec, body)
    notes = _drop_notes(drop, body)
    if len(design.charge_values):
        notes.append("the charges' Lorentz forces are not in the net force (not estimated)")
    return {
        "facility": drop.facility,
        "microgravity_s": drop.micro,
        "flight_s": drop.flight,
        "residual_g": drop.g_res,
        "turns": drop.turns,
        "net_force_N": drop.force,
        "drift_m": drop.drift,
        "items": _drop_items(drop, body),
        "notes": notes,
    }


def _drop(design: Any, spec: SupportOptions, body: _Body) -> _Drop:
    facility = spec.facility or "drop_tower_catapult"
    time_key = _FACILITY_TIME[facility]
    micro = figure(time_key)
    flight = micro - figure("drop_tower.release_and_cage_s")
    g_res = figure("drop_tower.residual_g")
    turns = body.rate * flight / (2.0 * math.pi)
    needed = 2.0 * math.pi * MIN_TURNS / body.rate + figure("drop_tower.release_and_cage_s")
    coil_radius = max((p.radius for p in body.pairs), default=4.0 * body.region)
    chamber = figure("chamber.bore_share") * coil_radius
    clearance = chamber - body.region
    v_err = figure("drop_tower.release_velocity_error_m_per_s")
    drift0 = 0.5 * g_res * STANDARD_GRAVITY * flight**2 + v_err * flight
    # the net force at that offset adds its own drift (evaluated once more at the sum)
    directions = (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    on = [field_on_parts(design, body.pairs, drift0 * u) for u in directions]
    force = max(f.net_force_N for f in on)
    drift = drift0 + 0.5 * force / body.mass * flight**2
    on = [field_on_parts(design, body.pairs, drift * u) for u in directions]
    at_offset = max(on, key=lambda f: f.energy_error_J)
    force = max(f.net_force_N for f in on)
    force_limit = body.mass * 2.0 * max(clearance - drift0, 0.0) / flight**2
    centred = field_on_parts(design, body.pairs, np.zeros(3))
    harmonic = at_offset.energy_error_J / body.term
    tidal = tidal_torque(STANDARD_GRAVITY / figure("earth.radius_m"), body.C) / body.term
    room_d, room_l, copper = coil_room(body.pairs)
    room_d = max(room_d, 2.0 * chamber)
    p_chamber = figure("chamber.pressure_Pa")
    p_max = body.fraction * body.term / free_molecular_torque(1.0, body.region, body.rate)
    p_tube = figure("drop_tower.tube_pressure_fraction") * figure("drop_tower.capsule_pressure_Pa")
    residual_limit = 2.0 * max(clearance - v_err * flight, 0.0) / flight**2 / STANDARD_GRAVITY
    return _Drop(
        facility,
        time_key,
        micro,
        flight,
        needed,
        g_res,
        turns,
        chamber,
        clearance,
        v_err,
        drift,
        force,
        force_limit,
        residual_limit,
        harmonic,
        tidal,
        (room_d, room_l, copper),
        p_chamber,
        p_max,
        p_tube,
        on,
        centred,
    )


def _drop_items(drop: _Drop, body: _Body) -> list[dict[str, Any]]:
    """The drop's requirements, each with its limit and source."""
    d, centred, (room_d, room_l, copper) = drop, drop.centred, drop.room
    return [
        item("microgravity_time_s", d.micro, d.needed, "s", d.micro >= d.needed, d.time_key),
        item("turns_in_flight", d.turns, MIN_TURNS, "", d.turns >= MIN_TURNS),
        at_most("residual_acceleration_g", d.g_res, d.residual_limit, "g", "drop_tower.residual_g"),
        at_most(
            "drift_relative_to_coils_m",
            d.drift,
            d.clearance,
            "m",
            "drop_tower.release_velocity_error_m_per_s",
        ),
        at_most("coil_harmonics_at_offset_over_term", d.harmonic, body.fraction, ""),
        at_most("net_force_N", d.force, d.force_limit, "N"),
        item(
            "net_dipole_over_dipoles",
            centred.dipole_sum / centred.dipole_magnitudes if centred.dipole_magnitudes else 0.0,
            1e-6,
            "",
            (centred.dipole_sum <= 1e-6 * centred.dipole_magnitudes),
        ),
        at_most("gravity_gradient_torque_over_term", d.tidal, body.fraction, "", "earth.radius_m"),
        *(
            at_most(name, value, figure(key), unit, key)
            for name, value, unit, key in (
                ("capsule_diameter_m", room_d, "m", "drop_tower.capsule_diameter_m"),
                ("capsule_length_m", room_l, "m", "drop_tower.capsule_length_m"),
                ("coil_copper_mass_kg", copper, "kg", "drop_tower.capsule_total_mass_kg"),
            )
        ),
        at_most("chamber_pressure_Pa", d.p_chamber, d.p_max, "Pa", "chamber.pressure_Pa"),
    ]


def _drop_notes(drop: _Drop, body: _Body) -> list[str]:
    """What the drop's items do not say: the pressures, the launch and landing, the forces."""
    p_tube, p_max, centred, force, on = drop.p_tube, drop.p_max, drop.centred, drop.force, drop.on
    harmonic, chamber, clearance = drop.harmonic, drop.chamber, drop.clearance
    return [
        f"the capsule is at normal pressure and the tube at {fmt(p_tube, ROUGH)} Pa "
        f"(1e-4 of it): at the tube's pressure the gas's drag would be "
        f"{fmt(free_molecular_torque(p_tube, body.region, body.rate) / body.term, ROUGH)} of "
        "the smallest term (free molecular estimate), so the body needs its own vacuum "
        f"chamber, at most {fmt(p_max, ROUGH)} Pa",
        f"the release comes after the catapult's {fmt(figure('drop_tower.catapult_launch_s'))} "
        f"s launch at up to {fmt(figure('drop_tower.catapult_launch_g'))} g, and the body is "
        f"caged before the landing at up to {fmt(figure('drop_tower.landing_g'))} g "
        f"({fmt(figure('drop_tower.release_and_cage_s'))} s of the microgravity time, not "
        "sourced)",
        f"net force at the centre {fmt(centred.net_force_N, ROUGH)} N, at the drift "
        f"{fmt(force, ROUGH)} N (dipoles {fmt(max(f.net_force_dipoles_N for f in on), ROUGH)} "
        f"N, induced magnetisation {fmt(max(f.net_force_induced_N for f in on), ROUGH)} N); "
        f"limit: the force whose drift fills the clearance left by the residual acceleration "
        f"and the release velocity",
        f"coils' harmonics at the centre {fmt(centred.energy_error_J / body.term, ROUGH)} of "
        f"the smallest term, at the drift {fmt(harmonic, ROUGH)}",
        f"vacuum chamber: inner radius {fmt(chamber, ROUGH)} m (half the coils' radius), "
        f"clearance {fmt(clearance, ROUGH)} m around the body region",
    ]


def _orbit(design: Any, body: _Body) -> dict[str, Any]:
    g_res = figure("orbit.residual_g")
    run = figure("orbit.run_s")
    radius = figure("earth.radius_m") + figure("orbit.altitude_m")
    rate_squared = STANDARD_GRAVITY * figure("earth.radius_m") ** 2 / radius**3
    tidal = tidal_torque(rate_squared, body.C) / body.term
    coil_radius = max((p.radius for p in body.pairs), default=4.0 * body.region)
    clearance = figure("chamber.bore_share") * coil_radius - body.region
    drift = 0.5 * g_res * STANDARD_GRAVITY * run**2
    on = field_on_parts(design, body.pairs, np.array([0.0, 0.0, min(drift, clearance)]))
    force_limit = body.mass * 2.0 * max(clearance - drift, 0.0) / run**2
    residual_limit = 2.0 * clearance / run**2 / STANDARD_GRAVITY
    items = [
        at_most("residual_acceleration_g", g_res, residual_limit, "g", "orbit.residual_g"),
        at_most("gravity_gradient_torque_over_term", tidal, body.fraction, "", "orbit.altitude_m"),
        at_most("net_force_N", on.net_force_N, force_limit, "N"),
    ]
    notes = [
        f"the orbit's rate {fmt(math.sqrt(rate_squared), ROUGH)} 1/s at "
        f"{fmt(figure('orbit.altitude_m'), ROUGH)} m; a run of {fmt(run)} s (not sourced)"
    ]
    return {
        "facility": None,
        "microgravity_s": None,
        "residual_g": g_res,
        "turns": None,
        "net_force_N": on.net_force_N,
        "items": items,
        "notes": notes,
    }


def _electrostatic(design: Any, body: _Body) -> dict[str, Any]:
    year = 365.25 * 86400.0
    tau = figure("gpb.spin_down_years_min") * year
    drag = 2.0 * body.C * body.rate / tau / body.term
    area = math.pi * body.region**2
    lift = math.sqrt(2.0 * body.mass * STANDARD_GRAVITY / (EPSILON_0 * area))
    medium = design.medium
    safe = medium.breakdown * medium.safety if medium is not None else math.inf
    aspherical = body.mass * STANDARD_GRAVITY * figure("gpb.sphericity_m") / body.term
    # the coat turning in the gradient: E ~ omega G a^2, dissipation sigma E^2 over the coat
    # (4 pi a^2 t), torque = power / omega: an order of magnitude (coefficient not derived)
    legendre = tuple(design.field("magnetic"))
    gradient = 2.0 * abs(legendre[1]) if len(legendre) > 1 else 0.0
    coat = (
        4.0
        * math.pi
        * figure("rotor.coating_conductivity_S_per_m")
        * body.rate
        * gradient**2
        * body.region**6
        * figure("rotor.coating_thickness_m")
        / body.term
    )
    items = [
        at_most("spin_down_drag_over_term", drag, body.fraction, "", "gpb.spin_down_years_min"),
        at_most("lifting_field_1g_V_per_m", lift, safe, "V/m"),
        at_most(
            "asphericity_torque_1g_over_term", aspherical, body.fraction, "", "gpb.sphericity_m"
        ),
        at_most("rotor_coat_eddy_over_term", coat, body.fraction, "", "rotor.coating_thickness_m"),
    ]
    notes = [
        "a suspension like Gravity Probe B's: the body inside a conducting spherical rotor "
        f"(GP-B's: {fmt(figure('gpb.rotor_diameter_m') * 1e3)} mm fused quartz, niobium "
        "coated), electrodes over its cross-section (not sourced); in orbit GP-B's rotors "
        f"spun down in {fmt(figure('gpb.spin_down_years_min'))}-"
        f"{fmt(figure('gpb.spin_down_years_max'))} years",
        "in 1 g the field must lift the body (the electrodes' area is the body region's "
        "cross-section: not sourced) and an aspherical rotor's lift makes a torque M g delta",
    ]
    return _held_in_one_g(items, notes)


def _held_in_one_g(items: list[dict[str, Any]], notes: list[str]) -> dict[str, Any]:
    """The record of a support that holds the body in the lab's 1 g (no flight, no turns)."""
    return {
        "facility": None,
        "microgravity_s": None,
        "residual_g": 1.0,
        "turns": None,
        "net_force_N": None,
        "items": items,
        "notes": notes,
    }


def _air_bearing(design: Any, body: _Body) -> dict[str, Any]:
    found = body.model.support or {}
    gas = design.medium.gas_properties if design.medium is not None else None
    has_gas = gas is not None and gas[0] > 0
    drag = float(found.get("drag_over_term", math.inf))
    tilt = float(found.get(KEY.tilt_limit_deg, 0.0))
    items = [
        at_most("film_drag_over_term", drag, body.fraction, ""),
        item("tilt_limit_deg", tilt, 180.0, "deg", tilt >= 180.0),
        item("gas_at_the_film", 1.0 if has_gas else 0.0, 1.0, "", has_gas),
        at_most("load_kg", body.mass, float(found.get("load_kg", 0.0)), "kg"),
    ]
    source = str(found.get("source", ""))
    for entry in items:
        entry["source"] = source or entry["source"]
        entry["checked"] = "unverified" not in source
    notes = [str(found.get("needs", ""))] if found.get("needs") else []
    return _held_in_one_g(items, notes)


def support_record(
    design: Any, spec: SupportOptions, *, fraction: float = REALISED_FRACTION
) -> dict[str, Any]:
    """The contract's ``support`` record of ``design`` held as ``spec`` says.

    Parameters
    ----------
    design : Design
        A physical body (``medium``, ``materials``; its ``buildability`` region).
    spec : SupportOptions
        The scene's ``[support]``.
    fraction : float
        Each parasitic must stay below this fraction of the smallest realised term.

    Returns
    -------
    dict
        ``style``, ``facility``, ``microgravity_s``, ``residual_g``, ``turns``,
        ``net_force_N``, ``items`` (each ``name, value, limit, unit, met, source, checked``),
        ``notes``, ``state`` ("included" when every item is met, else "open") and
        ``window_gravity_m_per_s2``.
    """
    gravity = window_gravity(spec, STANDARD_GRAVITY)
    body = _body(design, gravity, fraction)
    if spec.style == "free_fall":
        out = _free_fall(design, spec, body)
    elif spec.style == "orbit":
        out = _orbit(design, body)
    elif spec.style == "electrostatic":
        out = _electrostatic(design, body)
    else:
        out = _air_bearing(design, body)
    items = out.pop("items")
    return {
        "style": spec.style,
        **out,
        "items": items,
        "state": "included" if all(i["met"] for i in items) else "open",
        "window_gravity_m_per_s2": gravity,
        "typical_rate_per_s": body.rate,
        "smallest_term_N_m": body.term,
    }


def support_lines(record: dict[str, Any]) -> list[str]:
    """The record in words (the report's "Flight" section renders these)."""
    head = f"support: {record['style']}"
    if record.get("facility"):
        head += f" ({record['facility']}, {fmt(record['microgravity_s'])} s of microgravity)"
    lines = [head + f": {record.get('state', 'open')}"]
    for entry in record["items"]:
        mark = "met" if entry["met"] else "NOT met"
        unit = f" {entry['unit']}" if entry["unit"] else ""
        lines.append(
            f"- {entry['name']}: {fmt(entry['value'], ROUGH)}{unit} (limit "
            f"{fmt(entry['limit'], PLAIN)}{unit}): {mark}"
        )
    lines += [f"- {note}" for note in record.get("notes", [])]
    return lines
