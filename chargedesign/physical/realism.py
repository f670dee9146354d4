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

import functools
import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.constants import (
    BOHR_RADIUS,
    ELEMENTARY_CHARGE,
    EPSILON_0,
    MU_0,
    STANDARD_GRAVITY,
)
from chargedesign.formatting import ORDER_SCI, PLAIN, ROUGH, fmt
from chargedesign.physical.field_bounds import field_magnitude_max
from chargedesign.physical.map_data import component_values, shipped_map
from chargedesign.physical.materials import (
    BUILDER_BALANCE_M,
    CONDUCTIVITY,
    GAS_PROPERTIES,
    INSULATOR_CONDUCTIVITY,
    MAGNET_CONTINUUM_SIZE,
    SUSCEPTIBILITY,
    SUSCEPTIBILITY_METROLOGY,
    ballast_groups,
    ballast_materials,
    mass_densities,
    sphere_radius,
)
from chargedesign.physical.parasitics import (
    RESPONSE_ORIENTATIONS,
    balance_offset,
    balance_torque,
    eddy_torques_by_set,
    holder_eddy_torque,
    induced_energies_by_set,
    laminar_drag,
    larmor_power,
    reynolds,
    self_field,
    speed_over_c,
)
from chargedesign.physical.sources import value
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene.design_realism import FIELD_RESPONSE_KEYS, K_LAW_KEY, RESPONSE_FRACTION
from chargedesign.validation import as_finite_float

G_EARTH = STANDARD_GRAVITY
MICROGRAVITY = 1e-6 * G_EARTH
#: a torque this fraction of the designed torques is what "balanced" tolerates
BALANCE_FRACTION = 1e-3
#: a body whose element-level induced range is below this fraction of the same matter's
#: uncancelled law has its chi-weighted moments cancelled by design
CANCELLED = 1e-2
#: field at which metal surfaces evaporate as ions, V/m: about 6e10 V/m for tungsten (57 V/nm
#: in Tsong's table; sources table: limits.field_evaporation.tungsten, checked)
FIELD_EVAPORATION_KEY = "limits.field_evaporation.tungsten"
FIELD_EVAPORATION = value(FIELD_EVAPORATION_KEY)
#: the atomic unit of field, e / (4 pi eps0 a0^2), V/m (CODATA: 5.14e11): the field that
#: binds a hydrogen electron
ATOMIC_FIELD = ELEMENTARY_CHARGE / (4.0 * math.pi * EPSILON_0 * BOHR_RADIUS**2)


def typical_rate(params: Any) -> float:
    """``|omega| = 2 max(|n|, |K|, sqrt|kappa|, sqrt|lambda|, sqrt|rho|)`` (1/s)."""
    p = params
    return 2.0 * max(
        abs(p.n), abs(p.K), math.sqrt(abs(p.kappa)), math.sqrt(abs(p.lam)), math.sqrt(abs(p.rho))
    )


@dataclass(frozen=True)
class ModelScales:
    """The typical motion of the model a body realises: its rate (1/s), the inertia of its
    kinetic scale (kg m^2) and the typical torque ``C rate^2 / 4`` (N m); ``terms`` are a
    general case's realised terms (N m, :func:`case_terms`), None for the theorem's (its
    terms are the realisability map's rows)."""

    rate: float
    C: float
    terms: dict[str, float] | None = None

    @property
    def torque(self) -> float:
        return self.C * self.rate**2 / 4.0


#: a general case's numeric functions by its record (they cost sympy): a design is read
#: many times by its budgets, window and support
_CASE_FUNCTIONS: dict[tuple[Any, ...], Any] = {}
#: most kept
MAX_CASE_FUNCTIONS = 16


def general_case_functions(design: Any) -> Any:
    """The numeric functions (:class:`chargedesign.model.case_numeric.CaseFunctions`) of the
    case a general case's body realises, rebuilt from its design.json record at the body's
    time rate (None: the theorem's body)."""
    record = design.general_case
    if record is None:
        return None
    larmor, time_rate = design.larmor, design.time_rate
    key = (
        json.dumps(record.get("table"), sort_keys=True, default=str),
        None if larmor is None else (larmor.reading, larmor.rate),
        time_rate,
    )
    functions = _CASE_FUNCTIONS.get(key)
    if functions is None:
        # sympy: a general case's body only
        from chargedesign.model.case_numeric import design_case_functions

        functions = design_case_functions(record, larmor, time_rate)
        if len(_CASE_FUNCTIONS) >= MAX_CASE_FUNCTIONS:
            _CASE_FUNCTIONS.pop(next(iter(_CASE_FUNCTIONS)))
        _CASE_FUNCTIONS[key] = functions
    return functions


def model_scales(design: Any, parameters: Any = None) -> ModelScales:
    """The typical rate and torque of the model ``design`` realises, the one source every
    budget, window and support reads.

    The theorem's body: :func:`typical_rate` of ``parameters`` (default
    ``design.parameters``; the support reads the parameters its elements realise) and their C.
    A general case's body (``design.general_case``): the case's own rate and terms, from
    its V and mu as the record rebuilds them (:func:`case_terms`), with the smallest diagonal
    inertia as C.
    """
    functions = general_case_functions(design)
    if functions is None:
        p = design.parameters if parameters is None else parameters
        return ModelScales(typical_rate(p), float(p.C))
    sized = case_terms(design, functions)
    inertia = np.diag(functions.inertia)
    c_min = float(np.min(inertia[inertia > 0]))
    return ModelScales(sized["rate_rad_s"], c_min, dict(sized["terms"]))


def region_radius(design: Any) -> float:
    """The radius of the body's region, m: ``buildability.region_radius_m`` as written (a
    one-line error names it when it is not a number), else the farthest part's distance
    from O."""
    written = (design.buildability or {}).get("region_radius_m")
    if written is not None:
        return as_finite_float(written, "buildability.region_radius_m")
    return float(np.max(np.linalg.norm(design.all_masses()[0], axis=1), initial=0.0))


def magnet_continuum(design: Any) -> dict[str, Any]:
    """The designed magnets against the continuum size their material data hold for.

    A magnet's size is the edge of the cube of its material's volume (m, as the report's
    "Part sizes" line gives it). Below :data:`MAGNET_CONTINUUM_SIZE` it is a single-domain
    nanoparticle whose moment is not ``M v`` with the data-sheet ``M``: flagged, not accepted.

    Parameters
    ----------
    design : Design
        Any design; one without magnets gives ``{}``.

    Returns
    -------
    dict
        ``count``, ``smallest_m``, ``largest_m``, ``continuum_size_m``, ``below`` (how many
        magnets are smaller), ``material`` (its name, or None).
    """
    volumes = np.asarray(design.magnet_volumes(), dtype=float)
    if volumes.size == 0:
        return {}
    edges = np.cbrt(volumes)
    material = (design.materials or {}).get("magnet") or {}
    return {
        **_span(edges),
        "continuum_size_m": MAGNET_CONTINUUM_SIZE,
        "below": int(np.count_nonzero(edges < MAGNET_CONTINUUM_SIZE)),
        "material": material.get("name"),
    }


def _span(sizes: np.ndarray) -> dict[str, Any]:
    return {
        "count": len(sizes),
        "smallest_m": float(np.min(sizes)),
        "largest_m": float(np.max(sizes)),
    }


def part_sizes(design: Any) -> dict[str, Any]:
    """How large each kind of part is, from the written elements: what a builder must make.

    Returns
    -------
    dict
        ``carriers`` (the carriers' sphere radii) and ``ballast`` (the radius of each ballast
        part's sphere of its material; absent when a part's material is unknown): ``count``,
        ``smallest_m``, ``largest_m``; ``magnets``: :func:`magnet_continuum` (the edge of each
        magnet's cube of material). A kind of part the body has not is absent.
    """
    out: dict[str, Any] = {}
    radii = design.carrier_radii()
    if len(radii):
        out["carriers"] = _span(radii)
    magnets = magnet_continuum(design)
    if magnets:
        out["magnets"] = magnets
    density = mass_densities(design)
    if len(design.mass_values) and np.all(np.isfinite(density)):
        out["ballast"] = _span(sphere_radius(design.mass_values / density))
    return out


def _part_set(
    role: str,
    spec: dict[str, Any],
    centres: np.ndarray,
    volumes: np.ndarray,
    outer: np.ndarray,
    inner: Any,
) -> dict[str, Any] | None:
    """One set of parts of a material: those of non-zero volume (None: none)."""
    name = spec.get("name", role)
    keep = volumes > 0
    if not np.any(keep):
        return None
    return {
        "role": role,
        "name": name,
        "centres": centres[keep],
        "volumes": volumes[keep],
        "outer": outer[keep],
        "inner": np.broadcast_to(inner, outer.shape)[keep],
        "density": spec.get("density_kg_per_m3"),
        "chi": spec.get("volume_susceptibility", SUSCEPTIBILITY.get(name)),
        "sigma": spec.get("conductivity_S_per_m", CONDUCTIVITY.get(name)),
    }


def material_parts(design: Any) -> list[dict[str, Any]]:
    """Every part's material as spheres, from the written elements: one dict per part set.

    Keys: ``role``, ``name``, ``centres`` (k, 3), ``volumes`` (k,) of material (written mass
    over density), ``outer`` and ``inner`` radii (k,) (a hollow carrier's wall; 0 for solid
    spheres), ``density`` (kg/m^3), ``chi`` and ``sigma`` (as written, else the named
    material's; None when unknown). A magnet's attached ballast (its mass beyond the
    magnet's own) is a ballast sphere at its centre.
    """
    materials = design.materials
    sets: list[dict[str, Any]] = []

    def add(
        role: str, centres: np.ndarray, volumes: np.ndarray, outer: np.ndarray, inner, spec=None
    ) -> None:
        spec = spec if spec is not None else (materials.get(role) or {})
        part = _part_set(role, spec, centres, volumes, outer, inner)
        if part is not None:
            sets.append(part)

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
    holder = getattr(design, "holder", None)
    if holder:
        # a concentric homogeneous sphere's energy does not depend on the orientation; each
        # bore removes holder material at its part: the contrast chi_part - chi_holder
        bores = holder.get("bores") or []
        centres = np.array([b["position"] for b in bores], dtype=float).reshape(-1, 3)
        radii = np.array([b["radius_m"] for b in bores], dtype=float)
        chi = holder.get("volume_susceptibility")
        bore = {
            "name": f"{holder['material']} (its bores)",
            "density_kg_per_m3": holder["density_kg_per_m3"],
            "volume_susceptibility": None if chi is None else -chi,
            "conductivity_S_per_m": None,
        }
        add("holder", centres, 4.0 / 3.0 * np.pi * radii**3, radii, 0.0, bore)
    return sets


def _largest_part(parts: list[dict[str, Any]], values: np.ndarray, key: str) -> str:
    """The part set of the largest value, with its ``key`` (none: no positive value)."""
    if not len(values) or not np.any(values > 0):
        return "none"
    part = parts[int(np.argmax(values))]
    return f"{part['role']} {part['name']} ({key} = {fmt(part[key])})"


def _induced_note(induced: float, energy: np.ndarray, parts: list[dict[str, Any]]) -> str:
    """What the induced fraction measures, what negligible needs, the parts not counted."""
    unknown = sorted({f"{p['role']} {p['name']}" for p in parts if p["chi"] is None})
    note = (
        "range over orientations of the energy -chi v |B|^2 / (2 mu0) of the parts' materials "
        f"in the applied field, over the designed torques x 1 rad (largest: "
        f"{_largest_part(parts, energy, 'chi')})"
    )
    if induced >= RESPONSE_FRACTION:
        note += (
            f"; negligible needs the parts' chi-weighted dipole and quadrupole moments to "
            f"cancel to 1 part in {fmt(induced / RESPONSE_FRACTION, ROUGH)}"
        )
    if unknown:
        note += "; not counted (no susceptibility given): " + ", ".join(unknown)
    return note


def _eddy_note(
    damping: float, eddy: np.ndarray, parts: list[dict[str, Any]], periods: float
) -> str:
    """What the eddy fraction measures, how fast it damps, the parts not counted."""
    unknown_sigma = sorted({f"{p['role']} {p['name']}" for p in parts if p["sigma"] is None})
    note = (
        "eddy-current torque of the conducting parts turning in the field and moving through "
        "its gradient ((2 pi / 15) sigma |omega| max|L|^2 (a^5 - b^5) each, dB/dt = L omega = "
        "R^T (v . grad) B - omega x B; a conducting holder by its bound; largest: "
        f"{_largest_part(parts, eddy, 'sigma')}) over the designed torques"
    )
    if damping >= RESPONSE_FRACTION:
        note += (
            f"; it damps the motion within {fmt(periods, ROUGH)} periods; negligible needs "
            f"conductivities {fmt(damping / RESPONSE_FRACTION, ROUGH)} times lower (insulating "
            f"parts)"
        )
    if unknown_sigma:
        note += "; not counted (no conductivity given): " + ", ".join(unknown_sigma)
    return note


def field_response(design: Any) -> dict[str, Any]:
    """The applied magnetic field acting on the parts' materials, against the designed torques.

    Two items of the realism budget (``induced_magnetisation_fraction``,
    ``eddy_torque_fraction``), recomputed from the written elements and materials.
    """
    scales = model_scales(design)
    rate = scales.rate
    legendre = tuple(design.field("magnetic"))
    if rate == 0 or not legendre or design.medium is None:
        return {}
    torque = scales.torque
    parts = material_parts(design)
    energies = induced_energies_by_set(legendre, parts)
    energy = np.ptp(energies, axis=1)  # each set's own range, to name the largest
    eddy = eddy_torques_by_set(legendre, parts, rate)
    total_eddy = float(np.sum(eddy)) + holder_eddy_torque(
        legendre, getattr(design, "holder", None), rate
    )
    induced = float(np.ptp(np.sum(energies, axis=0))) / torque
    damping = total_eddy / torque
    # damping time: kinetic energy C rate^2 over the dissipated power sum(torque) rate
    periods = scales.C * rate**2 / (2 * math.pi * total_eddy) if total_eddy else math.inf
    induced_note = _induced_note(induced, energy, parts)
    eddy_note = _eddy_note(damping, eddy, parts, periods)
    induced_key, eddy_key = FIELD_RESPONSE_KEYS
    return {
        induced_key: _judged(induced, "", RESPONSE_FRACTION, induced_note),
        eddy_key: _judged(damping, "", RESPONSE_FRACTION, eddy_note),
    }


def chi_over_rho(design: Any, gross: bool = False) -> tuple[float, float, list[str]]:
    """The body's susceptibility per density: the mass-weighted mixture of its parts' materials.

    With ``gross`` every part's ``|chi|`` is counted: the figure of the same matter when
    paramagnetic and diamagnetic parts do not cancel (a body not designed for it).

    ``(chi/rho)_body = sum_p chi_p v_p / sum_p rho_p v_p`` over every part p (carriers, magnets,
    ballast; ``v_p`` the volume of its material, ``rho_p`` its density): the susceptibility
    of the body's matter per kilogram. It is the ``chi/rho`` of the K law exactly when every
    part has the same ``chi/rho``; otherwise the law's quadrupole is weighted by the parts'
    second moments, not their masses, and the element-level figure
    (:func:`field_response`) says by how much they differ.

    Returns
    -------
    chi_over_rho : float
        m^3/kg (0 when no part's susceptibility is known).
    mass : float
        kg, of the parts counted.
    unknown : list of str
        Parts whose susceptibility or density is not known (not counted).
    """
    num = mass = 0.0
    unknown: list[str] = []
    for part in material_parts(design):
        if part["role"] == "holder":  # the bores: the holder's contrast, not matter of its own
            continue
        if part["chi"] is None or part["density"] is None:
            unknown.append(f"{part['role']} {part['name']}")
            continue
        volume = float(np.sum(part["volumes"]))
        num += (abs(part["chi"]) if gross else part["chi"]) * volume
        mass += part["density"] * volume
    return (num / mass if mass > 0 else 0.0), mass, sorted(set(unknown))


def _frontier_k(design: Any) -> tuple[float, str]:
    """K at the frontier (1/s) and where it comes from, read from design.json's ``frontier``.

    ``frontier.K_max`` when written; else ``frontier.s_max`` times K (the charges reading's
    frontier scales n and K together); else the design's own K.
    """
    frontier = design.frontier
    K = abs(design.parameters.K)
    if isinstance(frontier, dict):
        # the design.json reader refused a negative or non-finite rate
        # (Design.from_dict, chargedesign.body)
        if frontier.get("K_max") is not None:
            return float(frontier["K_max"]), "frontier.K_max"
        if frontier.get("s_max") is not None:
            return float(frontier["s_max"]) * K, "frontier.s_max x K"
    return K, "the design's K (no frontier in design.json)"


def _conductivity_needed(
    design: Any, eddy_ratio: float | None
) -> tuple[float, dict[str, Any] | None, float | None]:
    """The most conducting part (its conductivity and the part) and the conductivity that
    would bring the eddy torque at the K frontier down to RESPONSE_FRACTION."""
    sigmas = [(part["sigma"], part) for part in material_parts(design) if part["sigma"]]
    sigma_top, top = max(sigmas, key=lambda x: x[0]) if sigmas else (0.0, None)
    sigma_needed = (
        sigma_top * RESPONSE_FRACTION / eddy_ratio if eddy_ratio and sigma_top > 0 else None
    )
    return sigma_top, top, sigma_needed


def _one_charge_sizes(design: Any, e_safe: float) -> tuple[float, float | None]:
    """The carrier radius at which one elementary charge reaches the safe field, and the
    radius of the smallest similar body whose carriers still hold one."""
    radii = design.carrier_radii()
    one_e = math.sqrt(ELEMENTARY_CHARGE / (4.0 * math.pi * EPSILON_0 * e_safe))
    carrier = float(np.max(radii, initial=0.0))
    region = region_radius(design)
    return one_e, (region * one_e / carrier if carrier > 0 else None)


def _k_law_note(item: dict[str, Any], unknown: list[str]) -> str:
    """The K law's one-paragraph note, from the figures of its budget item."""
    mix, mass = item["chi_over_rho_m3_per_kg"], item["parts_mass_kg"]
    k_max, a2, g = item["K_max_1_per_s"], item["a2_T_per_m"], item["G_C_m_per_kg"]
    source, ratio_elements = item["K_max_source"], item["ratio_elements"]
    cancelled, chi_needed = item["cancelled_by_design"], item["chi_relative_needed"]
    ratio_gross = item["ratio_without_cancellation"]
    reference = ratio_gross if cancelled else item["ratio"]
    parity_field = item["parity_surface_field_V_per_m"]
    parity_mix = item["parity_chi_over_rho_m3_per_kg"]
    eddy_ratio, sigma_needed = item["eddy_ratio"], item["conductivity_needed_S_per_m"]
    top, sigma_top = item["conductivity_needed_for"], item["conductivity_now_S_per_m"]
    note = (
        f"6 (chi/rho) / (mu0 G^2) with chi/rho = {fmt(mix)} m^3/kg (mass-weighted over "
        f"{fmt(mass)} kg of parts), G = K_max / a2 = {fmt(k_max)} / {fmt(a2)} = {fmt(g)} C m/kg "
        f"({source}): the parts' induced-magnetisation energy range over the designed K "
        f"torques C K_max^2, for any size and any a2"
    )
    if ratio_elements is not None:
        note += f"; element by element {fmt(ratio_elements)}"
    if cancelled and chi_needed is not None:
        note += (
            f" (cancelled by the design's chi-weighted moments; {fmt(ratio_gross)} without the "
            "cancellation, which holds only if each material's chi is known to"
            f" {fmt(chi_needed, ROUGH)} "
            "relative: susceptibility metrology reaches about"
            f" {fmt(SUSCEPTIBILITY_METROLOGY, ORDER_SCI)})"
        )
    note += (
        f". Parity needs G {fmt(math.sqrt(reference))} times larger: surface fields of "
        f"{fmt(parity_field)} V/m ({fmt(parity_field / FIELD_EVAPORATION)} x field evaporation, "
        f"{fmt(parity_field / ATOMIC_FIELD)} x the atomic field)"
        + (f", or chi/rho = {fmt(parity_mix)} m^3/kg" if parity_mix is not None else "")
    )
    if eddy_ratio is not None and sigma_needed is not None and top is not None:
        insulators = ", ".join(
            f"{k} {fmt(v, ORDER_SCI)}" for k, v in INSULATOR_CONDUCTIVITY.items()
        )
        note += (
            f". Eddy currents at the K frontier: {fmt(eddy_ratio)} x the designed K torques, a "
            f"choice of material: below {fmt(RESPONSE_FRACTION, PLAIN)} needs conductivities under "
            f"{fmt(sigma_needed)} S/m (now {top} {fmt(sigma_top)} S/m; "
            f"insulators: {insulators} S/m)"
        )
    if unknown:
        note += "; not counted (no susceptibility or density given): " + ", ".join(unknown)
    return note


def k_law(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """The induced-magnetisation parasitic at the K frontier, by the size-free law.

    With n read as a rotation of axes only K needs Lorentz charges (``6 a2 I_xxz = -C K d``,
    ``6 a2 I_xyz = c C K``). The parts' induced energy ``-chi v |B|^2 / (2 mu0)`` varies over
    orientations by ``6 a2^2 (chi/rho) C / mu0`` (all parts of one ``chi/rho``, docs/
    buildable.md), against the designed K torques ``C K^2``::

        ratio = 6 (chi/rho) / (mu0 G^2),   G = K_max / a2   (C m / kg, ~ (Q/M) L)

    Size-free for similar bodies, independent of a2, falling like ``1 / E_surface^2``.

    Parameters
    ----------
    design : Design
        With ``medium``, ``materials`` and a magnetic field with a gradient ``a2``.
    response : dict, optional
        The design's :func:`field_response` when already computed.

    Returns
    -------
    dict
        An item of the realism budget (``value`` = ``ratio_measured``, what the verdict rests
        on: the element-level ratio, else the law's; ``unit``, ``verdict``,
        ``note``) with the figures: ``chi_over_rho_m3_per_kg``, ``a2_T_per_m``,
        ``K_max_1_per_s`` and ``K_max_source``, ``G_C_m_per_kg``, ``ratio`` (the law),
        ``ratio_elements`` (the element-level induced energy range of :func:`field_response`
        over ``C K_max^2``), ``surface_field_V_per_m`` (the safe field the frontier reaches),
        ``parity_surface_field_V_per_m``, ``parity_chi_over_rho_m3_per_kg``,
        ``field_evaporation_V_per_m``, ``atomic_field_V_per_m``, ``eddy_ratio`` (the eddy
        torque at the K frontier's motion ``|omega| = 2 K_max`` over ``C K_max^2``),
        ``conductivity_needed_S_per_m``, ``insulators_S_per_m``, ``one_charge_carrier_radius_m``
        and ``smallest_similar_body_radius_m``. Empty when the law does not apply (no medium,
        no gradient, K = 0, or no part's susceptibility known). ``chi/rho`` may be negative
        (a diamagnetic body); the ratio takes its size.
    """
    legendre = tuple(design.field("magnetic"))
    a2 = legendre[1] / 2.0 if len(legendre) > 1 else 0.0
    if design.medium is None or a2 == 0.0 or design.parameters.K == 0.0:
        return {}
    p = design.parameters
    k_max, source = _frontier_k(design)
    if k_max == 0.0:
        return {}
    mix, mass, unknown = chi_over_rho(design)
    if mass == 0.0:  # no part's susceptibility is known: the law has nothing to say
        return {}
    gross_mix = chi_over_rho(design, gross=True)[0]
    g = k_max / abs(a2)
    # a diamagnetic body (chi < 0) has the same range of energy, upside down
    ratio = 6.0 * abs(mix) / (MU_0 * g**2)
    # the same matter without a designed cancellation: every part's |chi| counted
    ratio_gross = 6.0 * gross_mix / (MU_0 * g**2)
    designed = p.C * k_max**2
    response = field_response(design) if response is None else response
    rate = typical_rate(p)
    torque = p.C * rate**2 / 4.0
    induced_key, eddy_key = FIELD_RESPONSE_KEYS
    induced = (response.get(induced_key) or {}).get("value")
    eddy = (response.get(eddy_key) or {}).get("value")
    # the induced energy does not depend on the rate; the eddy torque is beta |omega|
    ratio_elements = induced * torque / designed if induced is not None else None
    eddy_ratio = eddy * torque / rate * 2.0 * k_max / designed if eddy is not None else None
    e_safe = design.medium.safe_field
    cancelled = (
        ratio_elements is not None and ratio_gross > 0 and ratio_elements < CANCELLED * ratio_gross
    )
    # parity for the matter as it would act without a designed cancellation
    reference, reference_mix = (ratio_gross, gross_mix) if cancelled else (ratio, abs(mix))
    parity_field = e_safe * math.sqrt(reference) if reference > 0 else 0.0
    parity_mix = reference_mix / reference if reference > 0 else None
    sigma_top, top, sigma_needed = _conductivity_needed(design, eddy_ratio)
    one_e, smallest = _one_charge_sizes(design, e_safe)
    # the verdict rests on what this body's written parts measure (element by element): a
    # body whose chi-weighted moments were designed to cancel is far below the law, which
    # describes matter whose susceptibility was not designed
    measured = ratio_elements if ratio_elements is not None else ratio
    chi_needed = RESPONSE_FRACTION / ratio_gross if ratio_gross > 0 else None
    verdict = _verdict(measured, RESPONSE_FRACTION)
    item = {
        # the number the verdict rests on (a budget row shows value and verdict side by side)
        "value": measured,
        "unit": "",
        "verdict": verdict,
        "note": "",
        "law": "6 (chi/rho) / (mu0 G^2), G = K_max / a2",
        "larmor_reading": design.larmor_reading,
        "chi_over_rho_m3_per_kg": mix,
        "parts_mass_kg": mass,
        "a2_T_per_m": abs(a2),
        "K_max_1_per_s": k_max,
        "K_max_source": source,
        "G_C_m_per_kg": g,
        "ratio": ratio,
        "ratio_elements": ratio_elements,
        "ratio_measured": measured,
        "ratio_without_cancellation": ratio_gross,
        "cancelled_by_design": cancelled,
        "chi_relative_needed": chi_needed,
        "metrology_chi_relative": SUSCEPTIBILITY_METROLOGY,
        "surface_field_V_per_m": e_safe,
        "parity_surface_field_V_per_m": parity_field,
        "parity_chi_over_rho_m3_per_kg": parity_mix,
        "field_evaporation_V_per_m": FIELD_EVAPORATION,
        "atomic_field_V_per_m": ATOMIC_FIELD,
        "eddy_ratio": eddy_ratio,
        "conductivity_needed_S_per_m": sigma_needed,
        "conductivity_needed_for": None if top is None else f"{top['role']} {top['name']}",
        "conductivity_now_S_per_m": sigma_top if top is not None else None,
        "insulators_S_per_m": dict(INSULATOR_CONDUCTIVITY),
        "one_charge_carrier_radius_m": one_e,
        "smallest_similar_body_radius_m": smallest,
    }
    item["note"] = _k_law_note(item, unknown)
    return item


#: the terms of V and mu the realisability map lists: (key, where, parameter monomial as
#: exponents of (kappa, n, K, lambda, rho), name, how the term can be realised)
_MAP_TERMS: tuple[tuple[str, str, tuple[int, ...], str, str], ...] = (
    (
        "kappa",
        "V",
        (1, 0, 0, 0, 0),
        "kappa's sectoral terms (degree 2)",
        "gravity on the masses' second moments (a degree-2 gravity field); an electric "
        "potential on the charges' second moments; magnets' first moments in the gradient a2; "
        "the parts' chi-weighted second moments in a2^2 (the induced energy, designed)",
    ),
    (
        "n2",
        "V",
        (0, 2, 0, 0, 0),
        "n^2 zonal term (degree 2)",
        "turning axes: the centrifugal potential (frame reading, no parts); or, like kappa's "
        "terms, gravity, electric or magnetic potentials on masses, charges or magnets",
    ),
    (
        "nK",
        "V",
        (0, 1, 1, 0, 0),
        "n K term (degree 3)",
        "turning axes: K's vector potential seen from them (frame reading, no parts); or a "
        "field of odd degree >= 3 on charges, masses or magnets",
    ),
    (
        "K2",
        "V",
        (0, 0, 2, 0, 0),
        "K^2 quartic terms (degree 4)",
        "a field of even degree >= 4: an electric potential on the charges' fourth moments, "
        "gravity on the masses', a magnetic one on the magnets' third moments",
    ),
    (
        "lambda",
        "V",
        (0, 0, 0, 1, 0),
        "lambda / gamma3^2 (singular)",
        "none: unbounded at gamma3 = 0, which no finite set of sources in a regular field makes",
    ),
    (
        "rho",
        "V",
        (0, 0, 0, 0, 1),
        "rho (1/gamma3^4 - 1/gamma3^6) (singular)",
        "none: unbounded at gamma3 = 0",
    ),
    (
        "mu_n",
        "mu",
        (0, 1, 0, 0, 0),
        "n terms of mu (degree 1)",
        "turning axes (frame reading, no parts); or Lorentz on the charges' second moments in "
        "a1 (the paper's (p6): a uniform charge-to-mass ratio)",
    ),
    (
        "mu_K",
        "mu",
        (0, 0, 1, 0, 0),
        "K terms of mu (degree 2)",
        "Lorentz on the charges' third moments in the gradient a2 (6 a2 I_xxz = -C K d, "
        "6 a2 I_xyz = c C K): the only mechanism in these fields",
    ),
)

#: the fields and the element kind each acts on, for the map's "here" column
_FIELD_SOURCES = (("electric", "charges"), ("magnetic", "magnets"), ("gravity", "masses"))


def _sources_for_degree(design: Any, degree: int) -> list[str]:
    """The element sets of this body in a field that makes terms of this degree in gamma.

    A field component of degree j, ``f_j R^j P_j(Z/R)`` with ``Z = gamma . r``, gives terms of
    degree j, j - 2, ... in gamma on charges, masses and magnets alike.
    """
    counts = {
        "charges": len(design.charge_values),
        "magnets": len(design.dipole_moments),
        "masses": len(design.all_masses()[1]),
    }
    out = []
    for kind, elements in _FIELD_SOURCES:
        coeffs = design.field(kind)
        degrees = [j + 1 for j, f in enumerate(coeffs) if f != 0.0]
        usable = [j for j in degrees if j >= degree and (j - degree) % 2 == 0]
        if usable and counts[elements]:
            out.append(f"{counts[elements]} {elements} in the {kind} field (degree {usable[0]})")
    return out


def realisability_map(design: Any, response: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    """Each term of V and mu: how it can be realised, how this body does it, and how strong
    it is against the parasitics of the parts' materials.

    The terms come from the model's V and mu (:func:`chargedesign.model.case.symbolic_case`,
    split by their parameter monomials); their sizes are computed from this design's
    parameters on 2000 orientations: for V the range of the term over the sphere (J, a torque
    times 1 rad), for mu the gyroscopic torque ``|omega| max |mu_term|`` at the budget's
    typical rate (N m). The parasitics are the body's (:func:`field_response`): the induced
    energy range (J) and the eddy torque at the typical rate (N m).

    Returns
    -------
    list of dict
        One row per term: ``key``, ``where`` (``V`` or ``mu``), ``term``, ``expression`` (in
        gamma1..3), ``mechanisms``, ``here`` (what this body uses), ``size_N_m`` (inf for a
        singular term that is present), ``frontier_size_N_m`` (the size at the K frontier:
        every term scales like the rate squared; None where it is not bound by parts),
        ``induced_over_term`` and ``eddy_over_term`` (None where no parts realise it), and
        the same two at the K frontier (``frontier_induced_over_term``,
        ``frontier_eddy_over_term``: the induced energy does not change with the rate, the
        eddy torque grows like it).
    """
    if design.general_case is not None:
        return []  # a general case: its terms are its own (case_terms), not the theorem's
    p = design.parameters
    frame = design.larmor_reading == "frame"
    # the frame reading's n is the turning axes' rate (the parts realise n = 0)
    rate_n = design.larmor.rate if frame else p.n
    values = dict(zip(_MAP_SYMBOLS, (p.kappa, rate_n, p.K, p.lam, p.rho), strict=True))
    rate = typical_rate(p)
    response = field_response(design) if response is None else response
    torque = p.C * rate**2 / 4.0
    induced_key, eddy_key = FIELD_RESPONSE_KEYS
    induced = (response.get(induced_key) or {}).get("value")
    eddy = (response.get(eddy_key) or {}).get("value")
    induced_j = induced * torque if induced is not None else None
    eddy_nm = eddy * torque if eddy is not None else None
    k_max, _ = _frontier_k(design) if p.K else (0.0, "")
    scale2 = (k_max / abs(p.K)) ** 2 if p.K else 1.0
    rows = []
    for key, where, powers, name, mechanisms in _MAP_TERMS:
        amount = math.prod(values[s] ** e for s, e in zip(_MAP_SYMBOLS, powers, strict=True))
        entry = shipped_map()[key]
        expression, degree = entry["expression"], entry["degree"]
        if where == "V":
            singular = key in ("lambda", "rho")
            if amount == 0.0:
                size = 0.0
            elif singular:
                size = math.inf
            else:
                term = amount * map_term_values(key, p.C, p.c, p.d)
                size = float(np.ptp(term))
        else:
            size = abs(amount) * rate * float(np.max(map_term_values(key, p.C, p.c, p.d)))
            singular = False
        no_parts = frame and key in ("n2", "nK", "mu_n")
        if amount == 0.0:
            here = "not in this body (its parameter is 0)"
        elif singular:
            here = "none: this body cannot realise it"
        elif no_parts:
            here = f"turning axes at n = {fmt(design.larmor.rate)} 1/s (no parts)"
        elif key == "mu_n":
            here = f"{len(design.charge_values)} charges (second moments in a1)"
        elif key == "mu_K":
            here = f"{len(design.charge_values)} charges (third moments in a2)"
        else:
            here = "; ".join(_sources_for_degree(design, degree)) or "no source of this degree"
        parts = amount != 0.0 and not singular and not no_parts
        front = size * scale2 if parts else None
        rows.append(
            {
                "key": key,
                "where": where,
                "term": name,
                "expression": expression,
                "mechanisms": mechanisms,
                "here": here,
                "size_N_m": size,
                "frontier_size_N_m": front,
                "induced_over_term": induced_j / size if parts and induced_j is not None else None,
                "eddy_over_term": eddy_nm / size if parts and eddy_nm is not None else None,
                # at the frontier the induced energy is the same, the eddy torque ~ the rate
                "frontier_induced_over_term": (
                    induced_j / front if front and induced_j is not None else None
                ),
                "frontier_eddy_over_term": (
                    eddy_nm * math.sqrt(scale2) / front if front and eddy_nm is not None else None
                ),
            }
        )
    return rows


#: the parameters of the map's monomials, in the order of :data:`_MAP_TERMS`' exponents
_MAP_SYMBOLS = ("kappa", "n", "K", "lambda", "rho")


@functools.lru_cache(maxsize=1)
def map_term_coefficients() -> dict[str, tuple[Any, ...]]:
    """Each map term's coefficients in the model (sympy, in C, c, d and gamma): one for a term
    of V, the three components for a term of mu. The derivation behind the shipped map
    (:func:`derived_map_terms`); the map itself reads :mod:`~chargedesign.physical.map_data`."""
    import sympy as sp  # sympy stays out of ``import chargedesign`` (the map reads its table)

    from chargedesign.model.case import K, kappa, lam, n, rho, symbolic_case

    case = symbolic_case()
    symbols = (kappa, n, K, lam, rho)
    v_terms = dict(sp.Poly(sp.expand(case.V), *symbols).terms())
    mu_terms = [dict(sp.Poly(sp.expand(m), n, K).terms()) for m in case.mu]
    out: dict[str, tuple[Any, ...]] = {}
    for key, where, powers, _, _ in _MAP_TERMS:
        if where == "V":
            out[key] = (v_terms[powers],)
        else:
            out[key] = tuple(m.get(powers[1:3], sp.Integer(0)) for m in mu_terms)
    return out


def derived_map_terms() -> dict[str, Any]:
    """The map's terms derived with sympy, JSON-ready (what ``make tables`` ships in
    ``chargedesign/data/realism/map_terms.json``): per key, the ``expression`` (in
    gamma1..3, with its parameter monomial), its ``degree`` in gamma, and the coefficients'
    ``components`` as :func:`chargedesign.physical.map_data.component_values` reads them
    (None for a singular term, which the map never evaluates)."""
    import sympy as sp  # sympy stays out of ``import chargedesign`` (the map reads its table)

    from chargedesign.model.case import GAMMA, C, K, c, d, kappa, lam, n, rho

    symbols = (kappa, n, K, lam, rho)
    coefficients = map_term_coefficients()
    out: dict[str, Any] = {}
    for key, where, powers, _, _ in _MAP_TERMS:
        monomial = sp.Mul(*[s**e for s, e in zip(symbols, powers, strict=True)])
        comps = coefficients[key]
        singular = where == "V" and key in ("lambda", "rho")
        if where == "V":
            expression = str(sp.factor(comps[0]) * monomial)
            degree = int(sp.Poly(comps[0], *GAMMA).total_degree()) if not singular else 0
        else:
            expression = "(" + ", ".join(str(sp.factor(c_ * monomial)) for c_ in comps) + ")"
            degree = 1 if key == "mu_n" else 2
        components = None
        if not singular:
            components = []
            for comp in comps:
                # lex in (C, gamma1..3), descending: the order sympy prints the terms in
                by_gamma = sp.Poly(comp, C, *GAMMA).terms() if comp != 0 else []
                components.append(
                    [
                        {
                            "powers": list(gamma_powers),
                            "terms": [
                                [str(sp.Rational(r)), i, j]
                                for (i, j), r in sp.Poly(inner, c, d).terms()
                            ],
                        }
                        for gamma_powers, inner in by_gamma
                    ]
                )
        out[key] = {"expression": expression, "degree": degree, "components": components}
    return out


def map_term_values(key: str, C_value: float, c_value: float, d_value: float) -> np.ndarray:
    """A map term per unit of its parameter monomial on the map's orientations: its values
    (2000,) for a term of V, ``max |mu_term|`` (a scalar array) for a term of mu. Read from
    the shipped map (no sympy), as ``lambdify`` of the derived coefficients computes it."""
    return _map_term_values(key, float(C_value), float(c_value), float(d_value))


@functools.lru_cache(maxsize=256)
def _map_term_values(key: str, C_value: float, c_value: float, d_value: float) -> np.ndarray:
    """Rate-free: the same for every body of one C, c, d (the probes of a frontier)."""
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    values = [
        np.broadcast_to(component_values(comp, C_value, c_value, d_value, gammas), len(gammas))
        for comp in shipped_map()[key]["components"]
    ]
    if len(values) == 1:
        out = np.array(values[0], dtype=float)
    else:
        out = np.array(np.max(np.linalg.norm(np.array(values), axis=0)))
    out.flags.writeable = False
    return out


def _item(value: float, unit: str, verdict: str, note: str) -> dict[str, Any]:
    return {
        "value": value if math.isfinite(value) else None,
        "unit": unit,
        "verdict": verdict,
        "note": note,
    }


def _verdict(value: float, negligible_below: float) -> str:
    return "negligible" if value < negligible_below else "NOT negligible"


def _judged(value: float, unit: str, negligible_below: float, note: str) -> dict[str, Any]:
    """A budget item whose verdict is "negligible" below ``negligible_below``."""
    return _item(value, unit, _verdict(value, negligible_below), note)


def _drag_item(medium: Any, envelope: float, rate: float, torque: float) -> dict[str, Any]:
    """The laminar drag of the medium's gas on the enveloping sphere over the designed
    torques; a medium that names no gas (a custom breakdown without ``gas``) says so."""
    name = medium.name if medium is not None else "vacuum"
    gas = medium.gas_properties if medium is not None else GAS_PROPERTIES["vacuum"]
    if gas is None:
        return _item(
            math.nan,
            "",
            "not estimated",
            f"medium {name!r} names no gas: give [medium] gas = "
            + " | ".join(GAS_PROPERTIES)
            + " for the drag estimate",
        )
    rho_gas, viscosity = gas
    if medium is not None and medium.gas not in (None, name):
        name = f"{name} ({medium.gas})"
    drag = laminar_drag(viscosity, envelope, rate)
    re = reynolds(rho_gas, viscosity, envelope, rate)
    return _judged(
        drag / torque,
        "",
        1e-3,
        f"laminar drag of {name} on the enveloping sphere (Re = {fmt(re)}) over the "
        "designed torques",
    )


def realism_budget(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """The budget of :mod:`this module <chargedesign.physical.realism>` as a JSON-ready dict.

    ``response``: the :func:`field_response` of this design when already computed (the
    limits check computes it too).
    """
    scales = model_scales(design)
    rate = scales.rate
    if rate == 0:
        return {"note": "the model's terms vanish: no typical motion to estimate"}
    positions, masses = design.all_masses()
    radii = np.linalg.norm(design.charge_positions, axis=1)
    all_r = np.linalg.norm(positions, axis=1)
    r_max = float(np.max(all_r, initial=0.0))
    q = design.charge_values
    period = 2 * math.pi / rate
    kinetic = scales.C * rate**2  # ~ (1/2) omega . I omega with I ~ 2C
    torque = scales.torque
    v_over_c = speed_over_c(rate, r_max)
    larmor = larmor_power(q, radii, rate)
    damping_time = kinetic / larmor if larmor > 0 else math.inf
    damping_periods = damping_time / period
    b_self = self_field(q, radii, rate)
    applied = abs(design.field("magnetic")[0]) if design.field("magnetic") else 0.0
    total_mass = float(np.sum(masses))
    offset_1g = balance_offset(BALANCE_FRACTION * torque, total_mass, G_EARTH)
    offset_micro = balance_offset(BALANCE_FRACTION * torque, total_mass, MICROGRAVITY)
    drag_item = _drag_item(design.medium, region_radius(design), rate, torque)

    response = field_response(design) if response is None else response
    law = k_law(design, response)
    item = _item
    return {
        "typical_rate_1_per_s": rate,
        "period_s": period,
        "designed_torque_N_m": torque,
        "v_over_c": _judged(v_over_c, "", 1e-6, "fastest element at |omega| r_max"),
        "radiation_damping_periods": item(
            damping_periods,
            "periods",
            "negligible" if damping_periods > 1e6 else "NOT negligible",
            "kinetic energy over the Larmor power of the charges (incoherent upper bound)",
        ),
        "self_field_fraction": _judged(
            # no charges, no self-field (0, not 0/0), whatever the applied a1
            b_self / applied if applied > 0 else (0.0 if b_self == 0.0 else math.inf),
            "",
            1e-6,
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
        "drag_torque_fraction": drag_item,
        **response,
        **({K_LAW_KEY: law} if law else {}),
    }


# --- a case of (ep) (the workbench): its own terms and rate, not the theorem's ---------------

#: orientations on which a case's realised terms are sized
CASE_TERM_ORIENTATIONS = 512


def case_terms(design: Any, functions: Any) -> dict[str, Any]:
    """The realised terms of a case body and its typical rate, from the case's own V and mu.

    ``functions``: :class:`chargedesign.model.case_numeric.CaseFunctions`. The potential term is
    the largest ``|gamma x dV/dgamma|`` over the sphere (N m); the gyroscopic term
    ``omega_typ max |mu|`` (N m), with the typical rate ``omega_typ = max(sqrt(T_V / C_min),
    max |mu| / C_min)`` (rad/s): the rate at which the kinetic terms match the forces (a case
    has no time parameter of its own). Terms that are zero are left out.
    """
    gammas = fibonacci_sphere(CASE_TERM_ORIENTATIONS)
    potential = float(
        np.max(np.linalg.norm(np.cross(gammas, functions.potential_gradient(gammas)), axis=1))
    )
    gyro = float(np.max(np.linalg.norm(functions.gyroscopic(gammas), axis=1)))
    c_min = float(np.min(np.diag(functions.inertia)[np.diag(functions.inertia) > 0]))
    rate = max(math.sqrt(potential / c_min), gyro / c_min)
    terms = {"potential_torque": potential, "gyroscopic_torque": gyro * rate}
    return {"rate_rad_s": rate, "terms": {k: v for k, v in terms.items() if v > 0}}


def case_realism_budget(design: Any, functions: Any) -> dict[str, Any]:
    """The realism budget of a case body of point elements: each parasitic of the charges and
    masses over the case's smallest realised term (:func:`case_terms`), at its typical rate.

    Items: the charges' Larmor radiation over ``omega`` (``q^2 omega^3 r^2 / (6 pi eps0 c^3)``),
    their self-field ``mu0 |q| omega / (4 pi r)`` over the applied ``|B|``, ``(v / c)^2`` of
    the fastest element, and gravity on the builder's balance ``M g delta`` (``delta`` =
    BUILDER_BALANCE_M). A verdict is "negligible" below 1e-3 of the term.
    """

    sized = case_terms(design, functions)
    rate = sized["rate_rad_s"]
    if not sized["terms"]:
        return {"rate_rad_s": rate, "term_key": None, "term_N_m": 0.0, "items": {}}
    term_key = min(sized["terms"], key=sized["terms"].get)
    term = sized["terms"][term_key]
    positions, masses = design.all_masses()
    every = np.concatenate(
        [np.asarray(p, dtype=float).reshape(-1, 3) for p in (positions, design.charge_positions)]
    )
    r_max = float(np.max(np.linalg.norm(every, axis=1), initial=0.0))
    q = np.asarray(design.charge_values, dtype=float)
    radii = np.linalg.norm(np.asarray(design.charge_positions, dtype=float).reshape(-1, 3), axis=1)
    radiation = larmor_power(q, radii, rate)
    legendre = tuple(design.field("magnetic"))
    applied = float(field_magnitude_max(legendre, np.array([r_max]))[0]) if legendre else 0.0
    b_self = self_field(q, radii, rate)
    relativistic = speed_over_c(rate, r_max) ** 2
    gravity = balance_torque(float(np.sum(masses)), STANDARD_GRAVITY) / term
    items = {
        "radiation": _judged(
            radiation / rate / term,
            "of the term",
            1e-3,
            "Larmor power of the charges over omega",
        ),
        "self_field": _judged(
            b_self / applied if applied > 0 else 0.0,
            "of the applied |B|",
            1e-3,
            "the moving charges' own field mu0 |q| omega / (4 pi r)",
        ),
        "relativistic": _judged(relativistic, "(v/c)^2", 1e-3, "the fastest element's speed"),
        "gravity_balance": _judged(
            gravity,
            "of the term",
            1e-3,
            f"M g delta on the builder's balance (delta = {BUILDER_BALANCE_M} m)",
        ),
    }
    return {"rate_rad_s": rate, "term_key": term_key, "term_N_m": term, "items": items}
