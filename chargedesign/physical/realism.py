"""The realism budget: what the idealised theorem leaves out, for a designed body.

The theorem assumes rigid point charges whose only effect is the static Lorentz force in the
applied field. For a typical motion of the designed body this module estimates (numbers and
verdicts, never hidden):

- ``v/c`` of the fastest element (relativistic corrections ~ (v/c)^2);
- Larmor radiation of the charges (incoherent sum, an upper bound) against the kinetic
  energy: a damping time, in periods;
- the magnetic field the moving charges make at O against the applied field;
- the centre-of-mass offset whose gravity torque is 1e-3 of the designed torques, under 1 g
  and under 1e-6 g (how precisely the body must be balanced);
- the viscous drag torque of the medium on the body's enveloping sphere (laminar estimate,
  ``8 pi mu R^3 omega``) against the designed torques;
- the applied magnetic field acting on the parts' own materials (:func:`field_response`):
  the induced magnetisation, whose energy ``-chi v |B|^2 / (2 mu0)`` depends on the
  orientation in a field gradient (a conservative torque the design does not contain), and
  the eddy currents of the conducting parts turning in the field (a damping torque).

The typical motion: ``|omega| = 2 max(|n|, |K|, sqrt|kappa|, sqrt|lambda|, sqrt|rho|)``, the
rate the theorem's terms set; the designed torques: ``C omega^2 / 4``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from chargedesign.fields import AxisymmetricField
from chargedesign.physical.limits import fibonacci_directions, field_magnitude_max
from chargedesign.physical.materials import (
    CONDUCTIVITY,
    EPSILON_0,
    GAS_PROPERTIES,
    LIGHT_SPEED,
    MU_0,
    SUSCEPTIBILITY,
    ballast_groups,
    ballast_materials,
    sphere_radius,
)

G_EARTH = 9.80665
MICROGRAVITY = 1e-6 * G_EARTH
#: a torque this fraction of the designed torques is what "balanced" tolerates
BALANCE_FRACTION = 1e-3
#: a torque from the parts' materials below this fraction of the designed torques is negligible
RESPONSE_FRACTION = 1e-3
#: orientations (a Fibonacci sphere) at which the induced-magnetisation energy is evaluated
RESPONSE_ORIENTATIONS = 2000
#: the budget's items for the applied field acting on the parts' materials
FIELD_RESPONSE_KEYS = ("induced_magnetisation_fraction", "eddy_torque_fraction")


def typical_rate(params: Any) -> float:
    """``|omega| = 2 max(|n|, |K|, sqrt|kappa|, sqrt|lambda|, sqrt|rho|)`` (1/s)."""
    p = params
    return 2.0 * max(
        abs(p.n), abs(p.K), math.sqrt(abs(p.kappa)), math.sqrt(abs(p.lam)), math.sqrt(abs(p.rho))
    )


def material_parts(design: Any) -> list[dict[str, Any]]:
    """Every part's material as spheres, from the written elements: one dict per part set.

    Keys: ``role``, ``name``, ``centres`` (k, 3), ``volumes`` (k,) of material (written mass
    over density), ``outer`` and ``inner`` radii (k,) (a hollow carrier's wall; 0 for solid
    spheres), ``chi`` and ``sigma`` (as written, else the named material's; None when
    unknown). A magnet's attached ballast (its mass beyond the magnet's own) is a ballast
    sphere at its centre.
    """
    materials = design.materials
    sets: list[dict[str, Any]] = []

    def add(
        role: str, centres: np.ndarray, volumes: np.ndarray, outer: np.ndarray, inner, spec=None
    ) -> None:
        spec = spec if spec is not None else (materials.get(role) or {})
        name = spec.get("name", role)
        keep = volumes > 0
        if not np.any(keep):
            return
        sets.append(
            {
                "role": role,
                "name": name,
                "centres": centres[keep],
                "volumes": volumes[keep],
                "outer": outer[keep],
                "inner": np.broadcast_to(inner, outer.shape)[keep],
                "chi": spec.get("volume_susceptibility", SUSCEPTIBILITY.get(name)),
                "sigma": spec.get("conductivity_S_per_m", CONDUCTIVITY.get(name)),
            }
        )

    carrier = materials.get("carrier")
    if carrier is not None and len(design.charge_values):
        outer = design.carrier_radii()
        wall = carrier.get("shell_thickness_m")
        inner = np.maximum(outer - wall, 0.0) if wall is not None else np.zeros_like(outer)
        volumes = design.carrier_masses() / carrier["density_kg_per_m3"]
        add("carrier", design.charge_positions, volumes, outer, inner)
    magnet = materials.get("magnet")
    ballasts = ballast_materials(materials)  # a magnet's attached ballast: the first
    if magnet is not None and len(design.dipole_moments):
        volumes = design.magnet_volumes()
        add("magnet", design.dipole_positions, volumes, sphere_radius(volumes), 0.0)
        if ballasts:
            extra = np.maximum(design.magnet_masses() - magnet["density_kg_per_m3"] * volumes, 0)
            extra = extra / ballasts[0]["density_kg_per_m3"]
            add("ballast", design.dipole_positions, extra, sphere_radius(extra), 0.0, ballasts[0])
    for spec, idx in ballast_groups(design) if len(design.mass_values) else []:
        volumes = design.mass_values[idx] / spec["density_kg_per_m3"]
        add("ballast", design.mass_positions[idx], volumes, sphere_radius(volumes), 0.0, spec)
    return sets


def _induced_energies(legendre: tuple[float, ...], parts: list[dict[str, Any]]) -> np.ndarray:
    """``-sum chi v |B|^2 / (2 mu0)`` of each part set at each orientation (J), (sets, n).

    The field is axisymmetric, so a part at body position r sees the field at the point of
    polar coordinates (|r|, gamma . r): ``|B|^2`` there, for gamma on a Fibonacci sphere.
    For fields of degree <= 2 (the paper's) ``|B|^2`` is quadratic, and its mean over a
    sphere or shell of material differs from its value at the centre by an orientation-free
    constant, so the parts may be taken as points.
    """
    fld = AxisymmetricField(tuple(legendre))
    gammas = fibonacci_directions(RESPONSE_ORIENTATIONS)
    out = np.zeros((len(parts), len(gammas)))
    for k, part in enumerate(parts):
        if part["chi"] is None or fld.is_zero:
            continue
        energy = out[k]
        for start in range(0, len(part["volumes"]), 64):
            centres = part["centres"][start : start + 64]
            weights = part["chi"] * part["volumes"][start : start + 64]
            z = centres @ gammas.T  # (k, orientations)
            rho = np.sqrt(np.maximum(np.sum(centres**2, axis=1)[:, None] - z**2, 0.0))
            points = np.stack([rho, np.zeros_like(rho), z], axis=-1).reshape(-1, 3)
            b2 = np.sum(fld.gradient(points) ** 2, axis=1).reshape(z.shape)
            energy -= weights @ b2 / (2.0 * MU_0)
    return out


def _eddy_torques(legendre: tuple[float, ...], parts: list[dict[str, Any]], rate: float):
    """Eddy-current torque of each part set turning at ``rate`` in its local field (N m).

    A conducting sphere turning at omega in a uniform B (perpendicular to omega, skin depth
    much larger than the part) carries the current of ``E = (omega B / 2) y x r`` and is
    retarded by ``(2 pi / 15) sigma omega B^2 a^5`` (a shell: ``a^5 - b^5``). B is the largest
    |B| over orientations at the part's distance from O; the parts' motion through the
    gradient adds a term of the same order, so this is an order-of-magnitude estimate.
    """
    out = np.zeros(len(parts))
    if not legendre:
        return out
    for k, part in enumerate(parts):
        if part["sigma"] is None:
            continue
        b = field_magnitude_max(tuple(legendre), np.linalg.norm(part["centres"], axis=1))
        shells = part["outer"] ** 5 - part["inner"] ** 5
        out[k] = float(np.sum(2.0 * np.pi / 15.0 * part["sigma"] * rate * b**2 * shells))
    return out


def field_response(design: Any) -> dict[str, Any]:
    """The applied magnetic field acting on the parts' materials, against the designed torques.

    Two items of the realism budget (``induced_magnetisation_fraction``,
    ``eddy_torque_fraction``), recomputed from the written elements and materials.
    """
    rate = typical_rate(design.parameters)
    legendre = tuple(design.field("magnetic"))
    if rate == 0 or not legendre or design.medium is None:
        return {}
    torque = design.parameters.C * rate**2 / 4.0
    parts = material_parts(design)
    energies = _induced_energies(legendre, parts)
    energy = np.ptp(energies, axis=1)  # each set's own range, to name the largest
    eddy = _eddy_torques(legendre, parts, rate)
    unknown = sorted({f"{p['role']} {p['name']}" for p in parts if p["chi"] is None})
    unknown_sigma = sorted({f"{p['role']} {p['name']}" for p in parts if p["sigma"] is None})

    def largest(values: np.ndarray, key: str) -> str:
        if not len(values) or not np.any(values > 0):
            return "none"
        part = parts[int(np.argmax(values))]
        return f"{part['role']} {part['name']} ({key} = {part[key]:.3g})"

    induced = float(np.ptp(np.sum(energies, axis=0))) / torque
    damping = float(np.sum(eddy)) / torque
    n = abs(design.parameters.n)
    # the induced energy does not depend on the rate, the designed torques go as s^2; the
    # eddy torque as s: the rate above which each would be negligible
    n_induced = n * math.sqrt(induced / RESPONSE_FRACTION)
    n_eddy = n * damping / RESPONSE_FRACTION
    # damping time: kinetic energy C rate^2 over the dissipated power sum(torque) rate
    total_eddy = float(np.sum(eddy))
    periods = design.parameters.C * rate**2 / (2 * math.pi * total_eddy) if total_eddy else math.inf
    induced_note = (
        "range over orientations of the energy -chi v |B|^2 / (2 mu0) of the parts' materials "
        f"in the applied field, over the designed torques x 1 rad (largest: "
        f"{largest(energy, 'chi')})"
    )
    if induced >= RESPONSE_FRACTION:
        induced_note += (
            f"; negligible needs the parts' chi-weighted dipole and quadrupole moments to "
            f"cancel to 1 part in {induced / RESPONSE_FRACTION:.2g}, or n above "
            f"{n_induced:.3g} 1/s"
        )
    if unknown:
        induced_note += "; not counted (no susceptibility given): " + ", ".join(unknown)
    eddy_note = (
        "eddy-current torque of the conducting parts turning in their local |B| "
        f"((2 pi / 15) sigma |omega| B^2 (a^5 - b^5) each; largest: {largest(eddy, 'sigma')}) "
        "over the designed torques"
    )
    if damping >= RESPONSE_FRACTION:
        eddy_note += (
            f"; it damps the motion within {periods:.2g} periods; negligible needs "
            f"conductivities {damping / RESPONSE_FRACTION:.2g} times lower (insulating "
            f"parts), or n above {n_eddy:.3g} 1/s"
        )
    if unknown_sigma:
        eddy_note += "; not counted (no conductivity given): " + ", ".join(unknown_sigma)
    induced_key, eddy_key = FIELD_RESPONSE_KEYS
    return {
        induced_key: _item(induced, "", _verdict(induced, RESPONSE_FRACTION), induced_note),
        eddy_key: _item(damping, "", _verdict(damping, RESPONSE_FRACTION), eddy_note),
    }


def _item(value: float, unit: str, verdict: str, note: str) -> dict[str, Any]:
    return {
        "value": value if math.isfinite(value) else None,
        "unit": unit,
        "verdict": verdict,
        "note": note,
    }


def _verdict(value: float, negligible_below: float) -> str:
    return "negligible" if value < negligible_below else "NOT negligible"


def realism_budget(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """The budget of :mod:`this module <chargedesign.physical.realism>` as a JSON-ready dict.

    ``response``: the :func:`field_response` of this design when already computed (the
    limits check computes it too).
    """
    p = design.parameters
    rate = typical_rate(p)
    if rate == 0:
        return {"note": "the theorem's terms vanish: no typical motion to estimate"}
    positions, masses = design.all_masses()
    radii = np.linalg.norm(design.charge_positions, axis=1)
    all_r = np.linalg.norm(positions, axis=1)
    r_max = float(np.max(all_r, initial=0.0))
    q = design.charge_values
    period = 2 * math.pi / rate
    kinetic = p.C * rate**2  # ~ (1/2) omega . I omega with I ~ 2C
    torque = p.C * rate**2 / 4.0
    v_over_c = rate * r_max / LIGHT_SPEED
    larmor = float(np.sum(q**2 * (rate**2 * radii) ** 2)) / (
        6 * math.pi * EPSILON_0 * LIGHT_SPEED**3
    )
    damping_time = kinetic / larmor if larmor > 0 else math.inf
    damping_periods = damping_time / period
    with np.errstate(divide="ignore"):
        b_self = (
            MU_0
            / (4 * math.pi)
            * float(np.sum(np.abs(q) * rate / np.where(radii > 0, radii, np.inf)))
        )
    applied = abs(design.field("magnetic")[0]) if design.field("magnetic") else 0.0
    total_mass = float(np.sum(masses))
    offset_1g = BALANCE_FRACTION * torque / (total_mass * G_EARTH) if total_mass > 0 else math.inf
    offset_micro = (
        BALANCE_FRACTION * torque / (total_mass * MICROGRAVITY) if total_mass > 0 else math.inf
    )
    medium = (design.medium or {}).get("name", "vacuum")
    rho_gas, viscosity = GAS_PROPERTIES.get(medium, (0.0, 0.0))
    envelope = float(design.extra.get("buildability", {}).get("region_radius_m", r_max))
    drag = 8 * math.pi * viscosity * envelope**3 * rate
    reynolds = rho_gas * rate * envelope**2 / viscosity if viscosity > 0 else 0.0

    item = _item
    return {
        "typical_rate_1_per_s": rate,
        "period_s": period,
        "designed_torque_N_m": torque,
        "v_over_c": item(
            v_over_c, "", _verdict(v_over_c, 1e-6), "fastest element at |omega| r_max"
        ),
        "radiation_damping_periods": item(
            damping_periods,
            "periods",
            "negligible" if damping_periods > 1e6 else "NOT negligible",
            "kinetic energy over the Larmor power of the charges (incoherent upper bound)",
        ),
        "self_field_fraction": item(
            b_self / applied if applied > 0 else math.inf,
            "",
            _verdict(b_self / applied if applied > 0 else math.inf, 1e-6),
            "field of the moving charges at O over the applied a1",
        ),
        "balance_offset_1g_m": item(
            offset_1g,
            "m",
            "achievable" if offset_1g > 1e-7 else "NOT achievable on Earth (below 0.1 um)",
            "centre-of-mass offset whose gravity torque is 1e-3 of the designed torques, 1 g",
        ),
        "balance_offset_microgravity_m": item(
            offset_micro,
            "m",
            "achievable" if offset_micro > 1e-7 else "NOT achievable (below 0.1 um)",
            "the same under 1e-6 g",
        ),
        "drag_torque_fraction": item(
            drag / torque,
            "",
            _verdict(drag / torque, 1e-3),
            f"laminar drag of {medium} on the enveloping sphere (Re = {reynolds:.3g}) over the "
            "designed torques",
        ),
        **(field_response(design) if response is None else response),
    }
