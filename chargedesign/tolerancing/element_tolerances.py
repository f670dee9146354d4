"""The tolerance report: per-element placement and value tolerances for a target relative
error, from the exact first derivatives, and the relative errors of mu, V and the inertia.

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.elements import ElementSet
from chargedesign.formatting import ORDER_SCI, fmt, fmt_length
from chargedesign.results import Result, json_ready
from chargedesign.sensitivity import (
    DEFAULT_ORIENTATIONS,
    QUANTITIES,
    analysed_elements,
    design_fields,
    jacobians,
    orientations,
    quantities,
    quantity_scales,
    references,
    row_norm,
    with_arrays,
)
from chargedesign.tolerancing.common import DEFAULT_MATERIAL_SAMPLES, DEFAULT_TARGET
from chargedesign.tolerancing.material_properties import (
    MaterialErrors,
    MaterialUncertainty,
    material_uncertainty,
    recorded_material_errors,
)
from chargedesign.validation import as_finite_float


@dataclass(repr=False)
class ToleranceReport(Result):
    """Per-element tolerances for a target relative accuracy (first order, exact derivatives).

    Attributes
    ----------
    target : float
        Target relative error of each quantity.
    scales : dict[str, float]
        The relative errors' denominators (``max |x_theorem|``; ``2C`` for the inertia).
    nominal : dict[str, float]
        The relative errors of the design as it is (same orientations).
    elements : list of dict
        One per element, most influential first: ``element`` (e.g. ``"charge 3"``, the index
        into the design.json block), ``kind``, ``index``, ``position_tol_m`` (per quantity,
        m: the largest displacement in the worst direction that keeps that quantity's error
        below ``target``), ``position_tol_m_min`` and its ``binding`` quantity,
        ``value_tol_rel`` (relative change of the charge, moment or mass; per quantity) and
        ``value_tol_rel_min``.
    uniform : dict
        One tolerance for all elements at once: ``position_tol_m_worst_case`` (errors add up
        in the worst directions) and ``position_tol_m_rms`` (independent random errors,
        ``target`` at one standard deviation), per quantity and their minimum.
    claimed : list of str
        What the design claims (``realises``); tolerances are computed for every quantity the
        body contributes to.
    """

    target: float
    scales: dict[str, float]
    nominal: dict[str, float]
    elements: list[dict[str, Any]]
    uniform: dict[str, Any]
    claimed: list[str]
    n_orientations: int
    materials: MaterialUncertainty | None = None

    @property
    def dominant(self) -> dict[str, Any] | None:
        return self.elements[0] if self.elements else None

    def headline(self) -> str:
        """``charge 3 dominates: place it within +-20 um to keep the relative error of mu
        below 1e-04``."""
        d = self.dominant
        if d is None or not math.isfinite(d["position_tol_m_min"]):
            return "no element affects mu, V or the inertia"
        return (
            f"{d['element']} dominates: place it within ±{fmt_length(d['position_tol_m_min'])} "
            f"to keep the relative error of {d['binding']} below {fmt(self.target, ORDER_SCI)}"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": "chargedesign.tolerance/1",
            "target": self.target,
            "headline": self.headline(),
            "n_orientations": self.n_orientations,
            "scales": dict(self.scales),
            "nominal_rel_err": dict(self.nominal),
            "uniform": json_ready(self.uniform),
            "elements": [json_ready(e) for e in self.elements],
            "claimed": list(self.claimed),
            **({"materials": self.materials.to_dict()} if self.materials is not None else {}),
        }

    def _summary(self) -> dict[str, Any]:
        d = self.dominant
        return {
            "target": self.target,
            "elements": len(self.elements),
            "dominant": d["element"] if d else None,
            "position_tol_m": d["position_tol_m_min"] if d else None,
            "uniform_tol_m": self.uniform.get("position_tol_m_worst_case_min"),
        }

    def _text(self) -> str:
        lines = [self.headline(), ""]
        lines.append(
            f"{'element':<12} {'position tol':>13} {'binding':>8} {'value tol':>10}  "
            "(first order, worst direction; target "
            f"{fmt(self.target, ORDER_SCI)})"
        )
        for e in self.elements[:20]:
            lines.append(
                f"{e['element']:<12} {fmt_length(e['position_tol_m_min']):>13} "
                f"{e['binding'] or '-':>8} {_percent(e['value_tol_rel_min']):>10}"
            )
        if len(self.elements) > 20:
            lines.append(f"... {len(self.elements) - 20} more elements")
        u = self.uniform
        lines.append("")
        lines.append(
            "all elements at once: within "
            f"±{fmt_length(u['position_tol_m_worst_case_min'])} (worst case) or "
            f"{fmt_length(u['position_tol_m_rms_min'])} rms (independent errors)"
        )
        if self.materials is not None:
            lines += ["", str(self.materials)]
        return "\n".join(lines)


def _percent(x: float) -> str:
    return "any" if not math.isfinite(x) else f"{fmt(100 * x)} %"


def _safe_div(a: float, b: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return np.where(b > 0.0, a / np.where(b > 0.0, b, 1.0), np.inf)


def tolerance_report(
    design: Design,
    target: float = DEFAULT_TARGET,
    *,
    n_orientations: int = DEFAULT_ORIENTATIONS,
    seed: int = 0,
    material_errors: MaterialErrors | None = None,
    material_samples: int = DEFAULT_MATERIAL_SAMPLES,
) -> ToleranceReport:
    """Tolerance per element for a target relative accuracy, most influential first.

    Parameters
    ----------
    design : Design
        Point charges (C), dipoles (A m^2) and masses (kg), body axes, m.
    target : float
        Target relative error of mu, V and the inertia (> 0).
    n_orientations : int
        Orientations sampled (the check's sampling).
    seed : int
        Seed of the orientations.
    material_errors : MaterialErrors, optional
        The materials' property errors (:func:`material_uncertainty`); default: those the
        design records from its scene's ``[tolerance]`` table (``material_errors``), if any.
    material_samples : int
        Perturbed bodies of the material analysis.

    Returns
    -------
    ToleranceReport
        ``to_dict()`` is the JSON block to store in design.json (key ``tolerance``).
    """
    if not isinstance(design, Design):
        raise TypeError(f"design: expected a Design, got {type(design).__name__}")
    target = as_finite_float(target, "target", positive=True)
    gammas = orientations(n_orientations, seed)
    ref = references(design, gammas)
    el = analysed_elements(design)
    now = quantities(el, design_fields(design), gammas)
    scales = quantity_scales(design, ref)
    nominal = relative_errors({k: v[None] for k, v in now.items()}, ref, scales)
    jac = jacobians(design, gammas)
    labels = jac.labels
    mags = _magnitudes(el)
    pos_tol = {q: _safe_div(target * scales[q], row_norm(jac.position[q], q)) for q in QUANTITIES}
    val_gain = {q: row_norm(jac.value[q], q) * mags for q in QUANTITIES}
    val_tol = {q: _safe_div(target * scales[q], val_gain[q]) for q in QUANTITIES}
    elements = []
    for j, (kind, idx) in enumerate(labels):
        p = {q: float(pos_tol[q][j]) for q in QUANTITIES}
        v = {q: float(val_tol[q][j]) for q in QUANTITIES}
        binding = min(QUANTITIES, key=lambda q: p[q])
        elements.append(
            {
                "element": f"{kind} {idx}",
                "kind": kind,
                "index": idx,
                "position_tol_m": p,
                "position_tol_m_min": p[binding],
                "binding": binding if math.isfinite(p[binding]) else None,
                "value_tol_rel": v,
                "value_tol_rel_min": min(v.values()),
            }
        )
    elements.sort(key=lambda e: (e["position_tol_m_min"], e["value_tol_rel_min"]))
    uniform: dict[str, Any] = {"position_tol_m_worst_case": {}, "position_tol_m_rms": {}}
    for q in QUANTITIES:
        J = jac.position[q]
        gains = row_norm(J, q)
        worst = float(_safe_div(target * scales[q], np.array([gains.sum()]))[0])
        # independent isotropic errors of rms s per coordinate: E|dQ|^2 = s^2 sum ||J||_F^2
        fro = np.sqrt(np.einsum("nmdc,nmdc->m", J, J).max(initial=0.0))
        rms = float(_safe_div(target * scales[q], np.array([fro]))[0])
        uniform["position_tol_m_worst_case"][q] = worst
        uniform["position_tol_m_rms"][q] = rms
    uniform["position_tol_m_worst_case_min"] = min(uniform["position_tol_m_worst_case"].values())
    uniform["position_tol_m_rms_min"] = min(uniform["position_tol_m_rms"].values())
    if material_errors is None:
        material_errors = recorded_material_errors(design)
    materials = None
    if material_errors is not None and not material_errors.is_zero:
        materials = material_uncertainty(
            design, material_errors, samples=material_samples, seed=seed
        )
    return ToleranceReport(
        target=target,
        scales=scales,
        nominal={q: float(nominal[q][0]) for q in QUANTITIES},
        elements=elements,
        uniform=uniform,
        claimed=list(design.realises),
        n_orientations=len(gammas),
        materials=materials,
    )


def with_tolerance(design: Design, report: ToleranceReport) -> Design:
    """A copy of ``design`` whose design.json carries the report under the key ``tolerance``."""
    out = with_arrays(design)
    for key, value in {**design.record(), "tolerance": report.to_dict()}.items():
        setattr(out, key, value)
    out.further_keys = dict(design.further_keys)
    out.continuous = list(design.continuous)
    return out


def _magnitudes(el: ElementSet) -> np.ndarray:
    return np.concatenate(
        [
            np.abs(el.charge_values),
            np.linalg.norm(el.dipole_moments, axis=1),
            np.abs(el.mass_values),
        ]
    )


def relative_errors(
    q: Mapping[str, np.ndarray], ref: Mapping[str, Any], scales: Mapping[str, float]
) -> dict[str, np.ndarray]:
    """Relative errors of B bodies' quantities (leading axis B): dict of (B,) arrays."""
    return {
        "mu": np.linalg.norm(q["mu"] - ref["mu"], axis=-1).max(axis=-1) / scales["mu"],
        "V": np.abs(q["V"] - ref["V"]).max(axis=-1) / scales["V"],
        "inertia": np.abs(q["inertia"] - ref["inertia"]).reshape(len(q["inertia"]), -1).max(axis=-1)
        / scales["inertia"],
    }
