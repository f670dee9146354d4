"""Material-property errors (susceptibility, density, magnetisation): the induced-magnetisation
parasitic they leave, by a Monte Carlo of perturbed materials and to first order.

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.errors import InputError
from chargedesign.formatting import FLOOR, ORDER_SCI, PLAIN, ROUGH, fmt
from chargedesign.physical.budget import induced_reference
from chargedesign.physical.induced import induced_energy
from chargedesign.physical.materials import SUSCEPTIBILITY, SUSCEPTIBILITY_METROLOGY
from chargedesign.physical.realism import (
    RESPONSE_ORIENTATIONS,
    field_response,
    material_parts,
    typical_rate,
)
from chargedesign.results import Result, json_ready
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene.design_realism import INDUCED_NAME, INDUCED_REFERENCE
from chargedesign.scene.keys import KEY
from chargedesign.tolerancing.common import (
    DEFAULT_MATERIAL_SAMPLES,
    quantile_summary,
    sample_count,
)
from chargedesign.validation import (
    check_material_analysis,
    check_material_error,
    check_material_errors,
    input_error,
)
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS


@dataclass(frozen=True)
class MaterialErrors:
    """Relative errors of the parts' material properties (one standard deviation each).

    Each error is one draw per material (a batch's value, shared by all its parts). Parts are
    made to their designed mass (carriers, ballast) and moment (magnets): a density or
    magnetisation error then changes a part's volume, so its induced energy ``-chi v |B|^2 /
    (2 mu0)``, as ``(1 + e_chi) / (1 + e_rho)`` (or ``/ (1 + e_M)`` for magnets).
    """

    chi_relative: float = 0.0
    density_relative: float = 0.0
    magnetisation_relative: float = 0.0

    @classmethod
    def parse(cls, where: str = "tolerance", **values: Any) -> MaterialErrors:
        """From keyword values (None: 0); a bad value names ``where.key`` (``--key`` on the
        command line, ``where = "--"``); each is checked by :func:`check_material_error`."""
        checked = {}
        for key, value in values.items():
            if key not in MATERIAL_ERROR_KEYS:
                raise input_error(where, "keys among " + ", ".join(MATERIAL_ERROR_KEYS), key)
            if value is not None:
                name = "--" + key.replace("_", "-") if where == "--" else f"{where}.{key}"
                checked[key] = check_material_error(value, name)
        return cls(**checked)

    @classmethod
    def from_table(cls, table: Any, where: str = "tolerance") -> MaterialErrors:
        """A scene's ``[tolerance]`` table."""
        return cls(**check_material_errors(table, where))

    @property
    def is_zero(self) -> bool:
        return not (self.chi_relative or self.density_relative or self.magnetisation_relative)

    def to_dict(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in MATERIAL_ERROR_KEYS}


def _material_groups(design: Design) -> tuple[list[dict[str, Any]], list[tuple[str, str]]]:
    """The parts with a known susceptibility, and the (role, name) of each material."""

    check_material_analysis(
        "tolerance",
        design.medium is not None and bool(design.materials),
        tuple(design.field("magnetic")),
    )
    parts = [part for part in material_parts(design) if part["chi"] is not None]
    groups: list[tuple[str, str]] = []
    for part in parts:
        if (part["role"], part["name"]) not in groups:
            groups.append((part["role"], part["name"]))
    return parts, groups


def _perturbed_materials(
    design: Design, groups: Sequence[tuple[str, str]], e: Mapping[str, np.ndarray]
) -> Design:
    """``design`` with every material's susceptibility, density and magnetisation perturbed
    by the relative errors ``e[key][j]`` of material ``groups[j]``; parts keep their mass
    (ballast, carriers) and moment (magnets), so their volumes change."""
    from dataclasses import replace

    def changed(spec: dict[str, Any], role: str) -> dict[str, Any]:
        key = (role, spec.get("name", role))
        if key not in groups:
            return dict(spec)
        j = groups.index(key)
        out = dict(spec)
        chi = spec.get("volume_susceptibility", SUSCEPTIBILITY.get(out.get("name", "")))
        if chi is not None:
            out["volume_susceptibility"] = chi * (1.0 + e[KEY.chi_relative][j])
        out["density_kg_per_m3"] = spec["density_kg_per_m3"] * (1.0 + e[KEY.density_relative][j])
        if role == "magnet":
            out["remanent_magnetisation_A_per_m"] = spec["remanent_magnetisation_A_per_m"] * (
                1.0 + e[KEY.magnetisation_relative][j]
            )
        return out

    materials: dict[str, Any] = {}
    for role, spec in design.materials.items():
        if isinstance(spec, list):
            materials[role] = [changed(x, role) for x in spec]
        else:
            materials[role] = changed(spec, role)
    arrays: dict[str, Any] = {}
    magnet = design.materials.get("magnet")
    if magnet is not None and len(design.dipole_moments):
        j = groups.index(("magnet", magnet["name"])) if ("magnet", magnet["name"]) in groups else -1
        if j >= 0:
            vol = design.magnet_volumes()
            new_vol = vol / (1.0 + e[KEY.magnetisation_relative][j])
            rho, new_rho = magnet["density_kg_per_m3"], materials["magnet"]["density_kg_per_m3"]
            # the attached ballast (mass beyond the magnet's own) keeps its mass
            arrays["dipole_volumes"] = new_vol
            arrays["dipole_masses"] = design.magnet_masses() - rho * vol + new_rho * new_vol
    return replace(design, materials=materials, **arrays)


@dataclass(repr=False)
class MaterialUncertainty(Result):
    """The induced-magnetisation parasitic that the materials' property errors leave.

    Attributes
    ----------
    errors : MaterialErrors
    materials : list of str
        ``role name`` of each material with a known susceptibility.
    sensitivity : ndarray, shape (materials,)
        Range over orientations of each material's induced energy over the smallest realised
        term at the design's rate (the reference of the induced magnetisation's one figure,
        :func:`~chargedesign.physical.budget.induced_magnetisation`): the parasitic a relative
        error of 1 in its chi v leaves (exact: the energy is linear in chi v).
    nominal : float
        The design's own induced magnetisation over that term (the one figure's value, by the
        field route; its round-off floor).
    monte_carlo, linear : ndarray, shape (samples,)
        The induced magnetisation of each perturbed body over that term: recomputed from its
        parts by the field (:func:`~chargedesign.physical.realism.field_response`), and to
        first order from the sensitivity (moment formula).
    chi_needed, chi_negligible : float
        The relative accuracy of every material's chi (one standard deviation) at which the
        parasitic stays below the smallest realised term, and below the realised fraction of
        it (the one figure's limit), for 90 % of the batches (first order).
    reference : dict
        The reference (:func:`~chargedesign.physical.budget.induced_reference`): ``term``,
        ``term_N_m``, ``s``, ``unit``, ``limit``.
    """

    errors: MaterialErrors
    materials: list[str]
    sensitivity: np.ndarray
    nominal: float
    monte_carlo: np.ndarray
    linear: np.ndarray
    chi_needed: float
    chi_negligible: float
    reference: dict[str, Any]

    @property
    def agreement(self) -> float:
        """Largest |Monte Carlo - linear| over the largest linear fraction."""
        top = float(np.max(np.abs(self.linear), initial=0.0))
        if top == 0.0:
            return 0.0
        return float(np.max(np.abs(self.monte_carlo - self.linear))) / top

    def verdict(self) -> str:
        metrology = SUSCEPTIBILITY_METROLOGY
        reach = "within" if self.chi_needed >= metrology else "beyond"
        return (
            f"the susceptibilities must be known to {fmt(self.chi_needed, ROUGH)} (relative, one "
            f"standard deviation) for the induced magnetisation to stay below the smallest "
            f"realised term ({self._term()}) in 90 % of the batches "
            f"({fmt(self.chi_negligible, ROUGH)} for it to be below the limit "
            f"{fmt(self.reference['limit'], PLAIN)} of it, negligible); "
            f"susceptibility metrology reaches about {fmt(metrology, ORDER_SCI)} (calibrated ac "
            f"susceptometers, Chen & Skumryev 2010; SQUID magnetometers at percent level): "
            f"{reach} reach"
        )

    def _term(self) -> str:
        return f"{self.reference['term']} at s = {fmt(self.reference['s'], ROUGH)}"

    def to_dict(self) -> dict[str, Any]:
        sensitivity = dict(zip(self.materials, self.sensitivity.tolist(), strict=True))
        induced = {
            "monte_carlo": quantile_summary(self.monte_carlo),
            "linear": quantile_summary(self.linear),
        }
        return json_ready(
            {
                "errors": self.errors.to_dict(),
                "samples": len(self.monte_carlo),
                "materials": list(self.materials),
                "reference": dict(self.reference),
                "sensitivity_over_term_per_unit_error": sensitivity,
                "nominal_induced_over_term": self.nominal,
                "induced_over_term": induced,
                # deprecated aliases (same values, same reference as the keys above)
                "sensitivity_fraction_per_unit_error": sensitivity,
                "nominal_induced_fraction": self.nominal,
                "induced_fraction": induced,
                "agreement": self.agreement,
                "chi_relative_needed": self.chi_needed,
                "chi_relative_negligible": self.chi_negligible,
                "metrology_chi_relative": SUSCEPTIBILITY_METROLOGY,
                "verdict": self.verdict(),
            }
        )

    def _summary(self) -> dict[str, Any]:
        return {
            "samples": len(self.monte_carlo),
            "induced_over_term_p90": float(np.quantile(self.monte_carlo, 0.9)),
            "chi_relative_needed": self.chi_needed,
        }

    def _text(self) -> str:
        mc, lin = quantile_summary(self.monte_carlo), quantile_summary(self.linear)
        lines = [
            "Material properties (errors at one standard deviation, one draw per material: "
            + ", ".join(f"{k} {fmt(v, PLAIN)}" for k, v in self.errors.to_dict().items())
            + f"; {len(self.monte_carlo)} bodies):",
            f"{INDUCED_NAME} {INDUCED_REFERENCE} ({self._term()}): median "
            f"{fmt(mc['median'])}, p90 {fmt(mc['p90'])} (Monte Carlo, field at each part); "
            f"median {fmt(lin['median'])}, p90 {fmt(lin['p90'])} (first order); the two agree "
            f"to {fmt(self.agreement, FLOOR)}; the design as it is: {fmt(self.nominal)}",
            "per material, for a relative error of 1 in chi v: "
            + ", ".join(
                f"{m} {fmt(s)}" for m, s in zip(self.materials, self.sensitivity, strict=True)
            ),
            "verdict: " + self.verdict(),
        ]
        return "\n".join(lines)


def material_uncertainty(
    design: Design,
    errors: MaterialErrors,
    *,
    samples: int = DEFAULT_MATERIAL_SAMPLES,
    seed: int = 0,
) -> MaterialUncertainty:
    """The induced-magnetisation parasitic left by the materials' property errors.

    Each material's susceptibility, density and (magnets) magnetisation is drawn once per
    body (Gaussian, one standard deviation = the relative error). The figure reported is the
    induced magnetisation's one figure
    (:func:`~chargedesign.physical.budget.induced_magnetisation`): the range over
    orientations of the parts' induced energy over the smallest realised term at the
    design's rate. Two routes: each perturbed body recomputed from its parts
    by the field (:func:`~chargedesign.physical.realism.field_response`, the Monte Carlo), and
    the exact sensitivity (the energy is linear in each part's chi v; its orientation part by
    the moment formula, :func:`~chargedesign.physical.induced.induced_energy`), to first order
    in the errors.

    Parameters
    ----------
    design : Design
        A physical design (medium, materials) in a magnetic field of degree <= 2.
    errors : MaterialErrors
    samples : int
        Perturbed bodies (1 .. MAX_SAMPLES).
    seed : int
        Seed of the draws.
    """

    if not isinstance(design, Design):
        raise TypeError(f"design: expected a Design, got {type(design).__name__}")
    if not isinstance(errors, MaterialErrors):
        raise TypeError(f"errors: expected MaterialErrors, got {type(errors).__name__}")
    samples = sample_count(samples, "samples", 1)
    parts, groups = _material_groups(design)
    rate = typical_rate(design.parameters)
    legendre = tuple(design.field("magnetic"))
    # the induced torques are weighed against a typical motion
    if rate == 0 or not legendre:
        raise InputError("tolerance: material errors need a magnetic field and a typical motion")
    # the reference is stated for any body, also one whose parts are outside their limits
    reference = induced_reference(design, parts_ok=True)
    if reference is None:
        raise InputError(
            "material errors: this body's realised window has no induced-magnetisation item "
            "(no magnetic field acts on its parts)"
        )
    # field_response states the energy over C omega^2 / 4; the one figure's reference is the
    # smallest realised term at s = 1, so every ratio below is over that term
    term = reference["term_N_m"]
    per_term = design.parameters.C * rate**2 / 4.0 / term
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    per = np.zeros((len(groups), len(gammas)))
    for part in parts:
        j = groups.index((part["role"], part["name"]))
        per[j] += induced_energy(legendre, part["centres"], part["chi"] * part["volumes"], gammas)
    sensitivity = np.ptp(per, axis=1) / term
    base = field_response(design)["induced_magnetisation_fraction"]["value"]
    nominal = float(base) * per_term if base is not None else math.inf
    nominal_energy = per.sum(axis=0)
    rng = np.random.default_rng(seed)
    draws = {
        key: getattr(errors, key) * rng.standard_normal((samples, len(groups)))
        for key in MATERIAL_ERROR_KEYS
    }
    # first order: chi v of each material changes by e_chi - e_rho (e_chi - e_M for magnets)
    volume_error = np.array(
        [
            KEY.magnetisation_relative if role == "magnet" else KEY.density_relative
            for role, _ in groups
        ]
    )
    delta = draws[KEY.chi_relative].copy()
    for j, key in enumerate(volume_error):
        delta[:, j] -= draws[key][:, j]
    linear = np.ptp(nominal_energy[None] + delta @ per, axis=1) / term
    monte_carlo = np.empty(samples)
    for b in range(samples):
        body = _perturbed_materials(design, groups, {k: v[b] for k, v in draws.items()})
        value = field_response(body)["induced_magnetisation_fraction"]["value"]
        monte_carlo[b] = math.inf if value is None else value * per_term
    # the chi accuracy needed: the first-order parasitic is homogeneous of degree 1 in the
    # errors, so unit chi errors give it per unit accuracy (90 % of the batches)
    unit = np.random.default_rng([seed, 2]).standard_normal((max(samples, 1000), len(groups)))
    p90 = float(np.quantile(np.ptp(unit @ per, axis=1), 0.9)) / term
    needed = 1.0 / p90 if p90 > 0 else math.inf
    return MaterialUncertainty(
        errors=errors,
        materials=[f"{role} {name}" for role, name in groups],
        sensitivity=sensitivity,
        nominal=nominal,
        monte_carlo=monte_carlo,
        linear=linear,
        chi_needed=needed,
        chi_negligible=reference["limit"] * needed,
        reference=reference,
    )


def recorded_material_errors(design: Design) -> MaterialErrors | None:
    """The material errors a design records from its scene (design.json
    ``material_errors``, from ``[tolerance]``), or None."""
    recorded = design.material_errors
    if recorded is None:
        return None
    return MaterialErrors.from_table(recorded, "material_errors")


def material_errors_with(design: Design, where: str = "--", **given: Any) -> MaterialErrors | None:
    """The material errors ``design`` records from its scene (``[tolerance]``) with the
    ``given`` ones (not None) in their place; a bad value names ``where`` as
    :meth:`MaterialErrors.parse` does (None: none recorded and none given)."""
    materials = recorded_material_errors(design)
    if any(value is not None for value in given.values()):
        base = materials.to_dict() if materials is not None else {}
        base.update({key: value for key, value in given.items() if value is not None})
        materials = MaterialErrors.parse(where, **base)
    return materials
