"""Manufacturing tolerances: exact first-order sensitivity and a Monte Carlo of perturbed bodies.

The errors the forward check measures (:mod:`chargedesign.checker`) are, per orientation gamma,

- ``e_mu(g) = mu_body(g) - mu_theorem(g)`` with ``mu_body = sum q (r . G_m) r``
  (``G_m = R^T grad Phi_m(R r)``, so ``-q (r . B) r`` with ``B_body = -G_m``),
- ``e_V(g)``: ``V_body - V_theorem``, each minus its mean over the orientations, with
  ``V_body = sum q Phi_e + sum m Phi_g + sum sigma . G_m``,
- ``e_I = sum m (|r|^2 1 - r r^T) - diag(2C, 2C, C)`` (no orientation),

and their relative errors are ``max_g |e(g)| / scale`` (scale ``max_g |x_theorem(g)|``; the
inertia's ``2C``; the largest absolute entry for the inertia, as in the check). Every ``e`` is
linear in the charges, dipole moments and masses and polynomial in the positions, so its
derivatives are exact and closed-form (:func:`jacobians`):

- ``d mu / d q = s r`` and ``d mu / d r = q (r (G_m + H_m r)^T + s 1)``, ``s = r . G_m``
  (``H_m = R^T Hess Phi_m R``),
- ``d V / d q = Phi_e``, ``d V / d r = q G_e``; ``d V / d m = Phi_g``, ``d V / d r = m G_g``;
  ``d V / d sigma = G_m``, ``d V / d r = H_m sigma`` (all centred over the orientations),
- ``d I / d m = |r|^2 1 - r r^T``, ``d I / d r_a = m (2 r_a 1 - e_a r^T - r e_a^T)``.

The tolerance of one element for a target relative error ``eps`` of quantity Q is the largest
displacement (or relative change of its value) whose first-order effect keeps Q's error below
``eps`` in the worst direction: ``eps * scale_Q / max_g ||dQ/dr||_2``.

The Monte Carlo (:func:`monte_carlo`) draws perturbed bodies (Gaussian errors, one standard
deviation = the given tolerance), measures their errors exactly and to first order, and
integrates them all at once (:func:`simulate_ensemble`) to measure the drift of I4; the
linear-response prediction of that drift integrates ``dI4/domega . I^-1 (N_b - N_0)`` along
the nominal trajectory. See docs/tolerance.md.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.errors import InputError
from chargedesign.formatting import AGREEMENT, ERROR, FLOOR, ORDER_SCI, PLAIN, ROUGH, fmt
from chargedesign.limits import MAX_TOLERANCE_LEVELS as MAX_LEVELS
from chargedesign.limits import MAX_TOLERANCE_SAMPLES as MAX_SAMPLES
from chargedesign.physical.induced import induced_energy
from chargedesign.physical.limits import fibonacci_directions
from chargedesign.physical.materials import SUSCEPTIBILITY, SUSCEPTIBILITY_METROLOGY
from chargedesign.physical.realism import (
    RESPONSE_FRACTION,
    RESPONSE_ORIENTATIONS,
    field_response,
    material_parts,
    typical_rate,
)
from chargedesign.results import Result, format_length
from chargedesign.sensitivity import (
    DEFAULT_ORIENTATIONS,
    QUANTITIES,
    Elements,
    Jacobians,
    batched_quantities,
    design_fields,
    jacobians,
    orientations,
    quantities,
    quantity_scales,
    references,
    row_norm,
    with_arrays,
    with_masses,
)
from chargedesign.simulation import api
from chargedesign.simulation.integrate import integrate
from chargedesign.simulation.polynomials import PolynomialBank
from chargedesign.simulation.system import (
    Body,
    RigidBodySystem,
    quaternion_gamma,
    reduced_polynomials,
    select_effects,
    theorem_i4,
)
from chargedesign.validation import (
    as_finite_float,
    check_material_error,
    check_material_errors,
    input_error,
)
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS

#: element kinds, in report order
KINDS = ("charge", "dipole", "mass")
#: the design.json blocks of the element kinds
KIND_BLOCKS = {"charge": "charges", "dipole": "dipoles", "mass": "masses"}
DEFAULT_TARGET = 1e-4
DEFAULT_LEVELS = (0.01, 0.1, 1.0)
#: integration tolerances of the ensemble (the nominal body's own drift is the floor)
DEFAULT_RTOL = 1e-10
DEFAULT_T_END = 100.0
DEFAULT_MATERIAL_SAMPLES = 200
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9}


# ------------------------------------------------------------------------ the report
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
            f"{d['element']} dominates: place it within ±{format_length(d['position_tol_m_min'])} "
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
            "uniform": _jsonable(self.uniform),
            "elements": [_jsonable(e) for e in self.elements],
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
                f"{e['element']:<12} {format_length(e['position_tol_m_min']):>13} "
                f"{e['binding'] or '-':>8} {_percent(e['value_tol_rel_min']):>10}"
            )
        if len(self.elements) > 20:
            lines.append(f"... {len(self.elements) - 20} more elements")
        u = self.uniform
        lines.append("")
        lines.append(
            "all elements at once: within "
            f"±{format_length(u['position_tol_m_worst_case_min'])} (worst case) or "
            f"{format_length(u['position_tol_m_rms_min'])} rms (independent errors)"
        )
        if self.materials is not None:
            lines += ["", str(self.materials)]
        return "\n".join(lines)


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


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
        raise input_error("design", "a Design", design)
    target = as_finite_float(target, "target", positive=True)
    gammas = orientations(n_orientations, seed)
    ref = references(design, gammas)
    el = Elements.of(design)
    now = quantities(el, design_fields(design), gammas)
    scales = quantity_scales(design, ref)
    nominal = _rel_errors({k: v[None] for k, v in now.items()}, ref, scales)
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


def _magnitudes(el: Elements) -> np.ndarray:
    return np.concatenate([np.abs(el.cv), np.linalg.norm(el.dm, axis=1), np.abs(el.mv)])


def _rel_errors(
    q: Mapping[str, np.ndarray], ref: Mapping[str, Any], scales: Mapping[str, float]
) -> dict[str, np.ndarray]:
    """Relative errors of B bodies' quantities (leading axis B): dict of (B,) arrays."""
    return {
        "mu": np.linalg.norm(q["mu"] - ref["mu"], axis=-1).max(axis=-1) / scales["mu"],
        "V": np.abs(q["V"] - ref["V"]).max(axis=-1) / scales["V"],
        "inertia": np.abs(q["inertia"] - ref["inertia"]).reshape(len(q["inertia"]), -1).max(axis=-1)
        / scales["inertia"],
    }


# ------------------------------------------------------------------------ error model
@dataclass(frozen=True)
class Spread:
    """One error size: ``value`` absolute (SI: m, C, A m^2, kg) or relative (a fraction)."""

    value: float
    relative: bool

    def __str__(self) -> str:
        if self.relative:
            return f"{fmt(100 * self.value, PLAIN)}%"
        return f"{fmt(self.value, PLAIN)}"

    def scaled(self, factor: float) -> Spread:
        return Spread(self.value * factor, self.relative)


_SPREAD = re.compile(r"^\s*([0-9.eE+-]+)\s*(%|[a-zA-Zµ]*)\s*$")


def parse_spread(text: Any, name: str, length: bool = False) -> Spread:
    """Parse ``20um``, ``0.02 mm``, ``1e-5`` (SI), ``1%`` (relative).

    Parameters
    ----------
    text : str or float
        The error: a number with an optional unit, or a percentage. Lengths (``length=True``)
        accept ``m``, ``mm``, ``um`` (or ``µm``), ``nm``; values take SI numbers only. A
        relative position error is a fraction of the element's distance from O.
    name : str
        The option's name for the error message.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = as_finite_float(text, name)
        if value < 0.0:
            raise input_error(name, "a non-negative error", text)
        return Spread(value, False)
    match = _SPREAD.match(str(text)) if isinstance(text, str) else None
    units = "m, mm, um, nm or %" if length else "%"
    if match is None:
        raise input_error(name, f"a number with an optional unit ({units}), e.g. 20um or 1%", text)
    try:
        number = float(match.group(1))
    except ValueError:
        raise input_error(name, "a number with an optional unit, e.g. 20um or 1%", text) from None
    unit = match.group(2)
    if not math.isfinite(number) or number < 0:
        raise input_error(name, "a non-negative error", text)
    if unit == "%":
        return Spread(number / 100.0, True)
    if unit == "":
        return Spread(number, False)
    if length and unit in LENGTH_UNITS:
        return Spread(number * LENGTH_UNITS[unit], False)
    raise input_error(name, f"a unit among {units}", unit)


@dataclass(frozen=True)
class ErrorModel:
    """Gaussian manufacturing errors; each spread is one standard deviation.

    Attributes
    ----------
    position : Spread
        Per coordinate of every element's position (absolute m, or a fraction of |r|).
    charge, dipole, mass : Spread
        Of each charge (C or fraction), each dipole moment component (A m^2, or a fraction
        of |sigma|), each mass (kg or fraction).
    """

    position: Spread = Spread(0.0, False)
    charge: Spread = Spread(0.0, False)
    dipole: Spread = Spread(0.0, False)
    mass: Spread = Spread(0.0, False)

    @classmethod
    def parse(
        cls,
        position: Any = None,
        charge: Any = None,
        dipole: Any = None,
        mass: Any = None,
    ) -> ErrorModel:
        def one(v: Any, name: str, length: bool = False) -> Spread:
            return Spread(0.0, False) if v is None else parse_spread(v, name, length)

        return cls(
            one(position, "--position", True),
            one(charge, "--charge"),
            one(dipole, "--dipole"),
            one(mass, "--mass"),
        )

    @property
    def is_zero(self) -> bool:
        return all(s.value == 0.0 for s in (self.position, self.charge, self.dipole, self.mass))

    def scaled(self, factor: float) -> ErrorModel:
        return ErrorModel(
            self.position.scaled(factor),
            self.charge.scaled(factor),
            self.dipole.scaled(factor),
            self.mass.scaled(factor),
        )

    def to_dict(self) -> dict[str, str]:
        return {
            "position": str(self.position) + ("" if self.position.relative else " m"),
            "charge": str(self.charge) + ("" if self.charge.relative else " C"),
            "dipole": str(self.dipole) + ("" if self.dipole.relative else " A m^2"),
            "mass": str(self.mass) + ("" if self.mass.relative else " kg"),
        }


def _sigmas(el: Elements, model: ErrorModel) -> dict[str, np.ndarray]:
    """Standard deviations per element array entry (same shapes as the arrays)."""

    def pos(r: np.ndarray) -> np.ndarray:
        s = model.position
        base = np.linalg.norm(r, axis=1) if s.relative else np.ones(len(r))
        return np.repeat((s.value * base)[:, None], 3, axis=1)

    def val(w: np.ndarray, s: Spread) -> np.ndarray:
        return s.value * (np.abs(w) if s.relative else np.ones_like(w))

    dip = model.dipole
    dsig = dip.value * (np.linalg.norm(el.dm, axis=1) if dip.relative else np.ones(len(el.dm)))
    return {
        "cp": pos(el.cp),
        "cv": val(el.cv, model.charge),
        "dp": pos(el.dp),
        "dm": np.repeat(dsig[:, None], 3, axis=1),
        "mp": pos(el.mp),
        "mv": val(el.mv, model.mass),
    }


def _draw(el: Elements, model: ErrorModel, n: int, rng: np.random.Generator) -> dict:
    """Perturbed element arrays of ``n`` bodies (leading axis n) and their unit draws."""
    sig = _sigmas(el, model)
    out = {}
    for key in ("cp", "cv", "dp", "dm", "mp", "mv"):
        base = getattr(el, key)
        z = rng.standard_normal((n, *base.shape))
        out[key] = base[None] + sig[key][None] * z
    # masses stay non-negative (a relative error of several tens of percent could flip one)
    out["mv"] = np.abs(out["mv"])
    return out


def _linear_errors(jac: Jacobians, el: Elements, draws: Mapping[str, np.ndarray]) -> dict:
    """First-order change of each quantity: dict of (B, m, d) arrays."""
    nc, nd = len(el.cv), len(el.dm)
    dpos = np.concatenate(
        [draws["cp"] - el.cp, draws["dp"] - el.dp, draws["mp"] - el.mp], axis=1
    )  # (B, N, 3)
    B, N = dpos.shape[0], dpos.shape[1]
    dval = np.zeros((B, N, 3))
    dval[:, :nc, 0] = draws["cv"] - el.cv
    dval[:, nc : nc + nd, :] = draws["dm"] - el.dm
    dval[:, nc + nd :, 0] = draws["mv"] - el.mv
    return {
        q: np.einsum("nmdc,bnc->bmd", jac.position[q], dpos)
        + np.einsum("nmdc,bnc->bmd", jac.value[q], dval)
        for q in QUANTITIES
    }


# ------------------------------------------------------------------------ the ensemble
class _Ensemble:
    """Many bodies of one structure, integrated as one batch (the reduced force route).

    Duck-types the part of :class:`~chargedesign.simulation.system.RigidBodySystem` that
    :func:`chargedesign.simulation.integrate.integrate` uses (``rhs_function``): each body's
    ``dV/dgamma`` and ``mu`` are polynomials in gamma
    (:func:`~chargedesign.simulation.system.reduced_polynomials`), stacked on one basis.
    """

    def __init__(self, bodies: Sequence[Any], effects: Sequence[str]) -> None:
        banks = [PolynomialBank(reduced_polynomials(b, *effects)) for b in bodies]
        exps = sorted({tuple(int(x) for x in e) for b in banks for e in b.exponents})
        index = {e: i for i, e in enumerate(exps)}
        self.exponents = np.array(exps, dtype=np.intp).reshape(-1, 3)
        self.degree = int(self.exponents.sum(axis=1).max(initial=0))
        coef = np.zeros((len(bodies), len(exps), 6))
        for b, bank in enumerate(banks):
            rows = [index[tuple(int(x) for x in e)] for e in bank.exponents]
            coef[b, rows] = bank.coefficients[:, 1:7]
        self.coef = coef
        self.C = bodies[0].parameters.C

    def monomials(self, gamma: np.ndarray) -> np.ndarray:
        """Basis monomials at gammas (m, 3): shape (m, K)."""
        m = len(gamma)
        powers = np.empty((m, self.degree + 1, 3))
        powers[:, 0, :] = 1.0
        for d in range(1, self.degree + 1):
            np.multiply(powers[:, d - 1, :], gamma, out=powers[:, d, :])
        e = self.exponents
        return powers[:, e[:, 0], 0] * powers[:, e[:, 1], 1] * powers[:, e[:, 2], 2]

    def torque(self, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        """Torque of body b at state b: omega, gamma (B, 3) -> (B, 3)."""
        v = np.matmul(self.monomials(gamma)[:, None, :], self.coef)[:, 0]
        return _cross(gamma, v[:, 0:3]) + _cross(v[:, 3:6], omega)

    def rhs_function(self, batch: int = 1) -> Any:
        C = self.C

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            states = y.reshape(batch, 7)
            omega, quats = states[:, :3], states[:, 3:]
            N = self.torque(omega, quaternion_gamma(quats))
            p, q, r = omega[:, 0], omega[:, 1], omega[:, 2]
            w, x, yq, z = quats[:, 0], quats[:, 1], quats[:, 2], quats[:, 3]
            out = np.empty_like(states)
            out[:, 0] = 0.5 * q * r + N[:, 0] / (2.0 * C)
            out[:, 1] = -0.5 * p * r + N[:, 1] / (2.0 * C)
            out[:, 2] = N[:, 2] / C
            out[:, 3] = -0.5 * (x * p + yq * q + z * r)
            out[:, 4] = 0.5 * (w * p + yq * r - z * q)
            out[:, 5] = 0.5 * (w * q + z * p - x * r)
            out[:, 6] = 0.5 * (w * r + x * q - yq * p)
            return out.reshape(-1)

        return fun


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (m, 3) arrays."""
    out = np.empty_like(a)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _physical_effects(body: Any) -> list[str]:
    return [e for e in select_effects(body, None)[0] if e != "theorem"]


@dataclass
class EnsembleRun:
    """Times (s,), per-body I4 relative drift over time (B, s) and the seconds taken."""

    times: np.ndarray
    drift: np.ndarray
    i4_0: np.ndarray
    seconds: float
    steps: int


def simulate_ensemble(
    designs: Sequence[Design],
    *,
    t_end: float = DEFAULT_T_END,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_RTOL,
    samples: int = 201,
    initial: Any = None,
) -> EnsembleRun:
    """Integrate many bodies of one structure in one batch; I4 drift of each over time.

    This is the one place the tolerance analysis calls the simulation (the reduced route of
    :mod:`chargedesign.simulation`, DOP853 on the whole batch).

    Parameters
    ----------
    designs : sequence of Design
        Bodies with the same fields and parameters (perturbed copies of one design).
    t_end : float
        Duration, s.
    rtol, atol : float
        solve_ivp tolerances (one step size for the whole batch).
    samples : int
        Output samples (at least 2).
    initial : mapping, optional
        Initial-state spec (default: the simulation's default on I3 = 0, r solved per body).

    Returns
    -------
    EnsembleRun
        ``drift[b, i] = |I4_b(t_i) - I4_b(0)| / |I4_b(0)|``.
    """

    if not designs:
        raise input_error("designs", "at least one design", designs)
    spec = api.parse_initial(api.DEFAULT_INITIAL if initial is None else initial)
    bodies = [Body.from_design(d) for d in designs]
    effects = _physical_effects(bodies[0])
    y0 = [api.initial_state(RigidBodySystem(b, effects, "reduced"), spec)[0] for b in bodies]
    ens = _Ensemble(bodies, effects)
    run = integrate(
        ens,  # type: ignore[arg-type]
        np.array(y0),
        t_end,
        method="DOP853",
        rtol=rtol,
        atol=atol,
        samples=samples,
    )
    states = run.states  # (B, s, 7)
    B, s = states.shape[0], states.shape[1]

    flat = states.reshape(-1, 7)
    six = np.hstack([flat[:, :3], quaternion_gamma(flat[:, 3:])])
    i4 = theorem_i4(six, designs[0].body_parameters).reshape(B, s)
    i4_0 = i4[:, 0]
    denom = np.where(np.abs(i4_0) > 0.0, np.abs(i4_0), 1.0)
    drift = np.abs(i4 - i4_0[:, None]) / denom[:, None]
    return EnsembleRun(
        times=np.asarray(run.times), drift=drift, i4_0=i4_0, seconds=run.seconds, steps=run.steps
    )


def _linear_drift(
    nominal: Design, perturbed: Sequence[Design], t_end: float, samples: int = 4001
) -> np.ndarray:
    """Linear-response I4 drift of each perturbed body: (B,) max over time.

    ``I4_b(t) - I4_b(0) = int_0^t dI4/domega . I^-1 (N_b - N_0) ds`` along the nominal
    trajectory (gamma's equation does not depend on the body and the nominal flow keeps I4),
    with ``N_b - N_0`` the torque difference at the nominal states (linear in the
    polynomial coefficients, so first order in the errors); dI4/domega by a 5-point stencil,
    exact for I4's quartic dependence on omega; the time integral by the trapezoid rule on
    the nominal run's step ends.
    """

    spec = api.parse_initial(api.DEFAULT_INITIAL)
    bodies = [Body.from_design(nominal)] + [Body.from_design(d) for d in perturbed]
    effects = _physical_effects(bodies[0])
    system = RigidBodySystem(bodies[0], effects, "reduced")
    y0 = api.initial_state(system, spec)[0]
    run = integrate(
        system, y0[None], t_end, method="DOP853", rtol=1e-12, atol=1e-12, samples=samples
    )
    st = run.states[0]
    t = np.asarray(run.times)
    omega = st[:, :3]
    gamma = quaternion_gamma(st[:, 3:])
    params = nominal.body_parameters
    grad = np.zeros_like(omega)
    h = 1e-3 * max(1.0, float(np.abs(omega).max()))
    for a in range(3):
        vals = []
        for k in (-2, -1, 1, 2):
            w = omega.copy()
            w[:, a] += k * h
            vals.append(theorem_i4(np.hstack([w, gamma]), params))
        grad[:, a] = (vals[0] - 8 * vals[1] + 8 * vals[2] - vals[3]) / (12 * h)
    inv_inertia = 1.0 / np.array([2.0 * params.C, 2.0 * params.C, params.C])
    i4_0 = float(theorem_i4(np.hstack([omega[:1], gamma[:1]]), params)[0])
    denom = abs(i4_0) if i4_0 != 0.0 else 1.0
    ens = _Ensemble(bodies, effects)
    mono = ens.monomials(gamma)  # (T, K)
    dcoef = ens.coef[1:] - ens.coef[:1]  # (B, K, 6)
    out = np.empty(len(perturbed))
    dt = np.diff(t)
    chunk = max(1, 2_000_000 // max(1, len(t) * 6))
    for start in range(0, len(perturbed), chunk):
        dv = np.einsum("tk,bkc->btc", mono, dcoef[start : start + chunk])  # (b, T, 6)
        dN = np.cross(gamma[None], dv[..., 0:3]) + np.cross(dv[..., 3:6], omega[None])
        rate = np.einsum("tj,btj->bt", grad * inv_inertia, dN)
        integral = np.cumsum(0.5 * (rate[:, 1:] + rate[:, :-1]) * dt, axis=1)
        out[start : start + chunk] = np.abs(integral).max(axis=1, initial=0.0) / denom
    return out


# ------------------------------------------------------------------------ Monte Carlo
def _quantiles(x: np.ndarray) -> dict[str, float]:
    x = np.asarray(x, float)
    if x.size == 0:
        return {}
    return {
        "median": float(np.median(x)),
        "p90": float(np.quantile(x, 0.9)),
        "max": float(x.max()),
        "mean": float(x.mean()),
    }


@dataclass(repr=False)
class MonteCarloResult(Result):
    """The Monte Carlo of perturbed bodies beside the linear-response prediction.

    Attributes
    ----------
    model : ErrorModel
        The errors at level 1 (one standard deviation each).
    errors : dict
        Per quantity: ``monte_carlo`` and ``linear`` relative errors, arrays (n,) at level 1
        (exact for each perturbed body; first order from the exact derivatives), and
        ``linear_rms`` (the predicted rms, no sampling).
    levels : ndarray
        Scale factors of the error model for the drift curve.
    drift_mc, drift_linear : ndarray, shape (levels, n_drift)
        Max over time of each perturbed body's I4 relative drift, simulated and predicted.
    drift_times, drift_median_over_time : ndarray
        The level-1 bodies' median drift against time.
    nominal_drift : float
        The unperturbed body's own drift (the integration's floor).
    """

    model: ErrorModel
    n: int
    errors: dict[str, dict[str, Any]]
    levels: np.ndarray
    drift_mc: np.ndarray
    drift_linear: np.ndarray
    drift_times: np.ndarray
    drift_median_over_time: np.ndarray
    drift_p90_over_time: np.ndarray
    nominal_drift: float
    t_end: float
    seconds: dict[str, float] = field(default_factory=dict)
    report: ToleranceReport | None = None

    def to_dict(self) -> dict[str, Any]:
        errs = {
            q: {
                "monte_carlo": _quantiles(v["monte_carlo"]),
                "linear": _quantiles(v["linear"]),
                "linear_rms": v["linear_rms"],
            }
            for q, v in self.errors.items()
        }
        drift = []
        for i, level in enumerate(self.levels):
            drift.append(
                {
                    "level": float(level),
                    "position_m": self.model.position.value * float(level)
                    if not self.model.position.relative
                    else None,
                    "monte_carlo": _quantiles(self.drift_mc[i]),
                    "linear": _quantiles(self.drift_linear[i]),
                }
            )
        out: dict[str, Any] = {
            "format": "chargedesign.tolerance-mc/1",
            "errors_model": self.model.to_dict(),
            "samples": self.n,
            "t_end": self.t_end,
            "rel_errors": errs,
            "I4_drift": drift,
            "I4_drift_nominal": self.nominal_drift,
            "seconds": dict(self.seconds),
        }
        if self.report is not None:
            out["sensitivity"] = self.report.to_dict()
        return _jsonable(out)

    def _summary(self) -> dict[str, Any]:
        return {
            "samples": self.n,
            "levels": len(self.levels),
            "t_end": self.t_end,
            **{
                f"{q}_rel_err_p90": float(np.percentile(v["monte_carlo"], 90))
                for q, v in self.errors.items()
            },
            # at the error level closest to the one given (level 1); None when not simulated
            "I4_drift_median": float(
                np.median(self.drift_mc[int(np.argmin(np.abs(self.levels - 1.0)))])
            )
            if self.drift_mc.size
            else None,
        }

    def _text(self) -> str:
        lines = []
        if self.report is not None:
            lines += [str(self.report), ""]
        lines.append(
            f"Monte Carlo: {self.n} perturbed bodies (errors at one standard deviation: "
            + ", ".join(f"{k} {v}" for k, v in self.model.to_dict().items())
            + ")"
        )
        lines.append(f"{'quantity':<9} {'MC median':>10} {'MC p90':>10} {'linear p90':>10}")
        for q, v in self.errors.items():
            mc, lin = _quantiles(v["monte_carlo"]), _quantiles(v["linear"])
            lines.append(
                f"{q:<9} {fmt(mc['median'], ERROR):>10} {fmt(mc['p90'], ERROR):>10}"
                f" {fmt(lin['p90'], ERROR):>10}"
            )
        lines.append("")
        if not self.drift_mc.size:  # --no-simulate: no drift was computed, say so (no nan)
            lines.append("I4 drift: not simulated (--no-simulate)")
            return "\n".join(lines)
        lines.append(
            f"I4 relative drift to t = {fmt(self.t_end, PLAIN)} s (median over bodies; nominal body"
            " "
            f"{fmt(self.nominal_drift, AGREEMENT)}):"
        )
        lines.append(f"{'level':>8} {'Monte Carlo':>12} {'linear':>12}")
        for i, level in enumerate(self.levels):
            lines.append(
                f"{fmt(level):>8} {fmt(np.median(self.drift_mc[i]), ERROR):>12} "
                f"{fmt(np.median(self.drift_linear[i]), ERROR):>12}"
            )
        return "\n".join(lines)


def _designs_from_draws(design: Design, draws: Mapping[str, np.ndarray]) -> list[Design]:
    out = []
    for b in range(len(draws["cv"])):
        d = with_arrays(
            design,
            charge_positions=draws["cp"][b],
            charge_values=draws["cv"][b],
            dipole_positions=draws["dp"][b],
            dipole_moments=draws["dm"][b],
        )
        out.append(with_masses(d, draws["mp"][b], draws["mv"][b]))
    return out


def error_distribution(
    design: Design,
    model: ErrorModel,
    n: int,
    *,
    seed: int = 0,
    n_orientations: int = DEFAULT_ORIENTATIONS,
) -> dict[str, dict[str, Any]]:
    """Relative errors of ``n`` perturbed bodies: exact (Monte Carlo) and first order.

    Returns
    -------
    dict
        Per quantity: ``monte_carlo`` (n,), ``linear`` (n,) and ``linear_rms`` (float).
    """
    el = Elements.of(design)
    gammas = orientations(n_orientations, 0)
    ref = references(design, gammas)
    scales = quantity_scales(design, ref)
    f = design_fields(design)
    jac = jacobians(design, gammas)
    nominal = quantities(el, f, gammas)
    rng = np.random.default_rng(seed)
    mc = {q: [] for q in QUANTITIES}  # type: dict[str, list[np.ndarray]]
    lin = {q: [] for q in QUANTITIES}  # type: dict[str, list[np.ndarray]]
    chunk = max(1, 20000 // max(1, len(gammas)))
    done = 0
    while done < n:
        k = min(chunk, n - done)
        draws = _draw(el, model, k, rng)
        exact = batched_quantities(
            draws["cp"], draws["cv"], draws["dp"], draws["dm"], draws["mp"], draws["mv"], f, gammas
        )
        first = _linear_errors(jac, el, draws)
        predicted = {
            "mu": nominal["mu"][None] + first["mu"],
            "V": nominal["V"][None] + first["V"][..., 0],
            "inertia": nominal["inertia"][None] + first["inertia"][:, 0].reshape(k, 3, 3),
        }
        for q, v in _rel_errors(exact, ref, scales).items():
            mc[q].append(v)
        for q, v in _rel_errors(predicted, ref, scales).items():
            lin[q].append(v)
        done += k
    sig = _sigmas(el, model)
    spos = np.concatenate([sig["cp"], sig["dp"], sig["mp"]])  # (N, 3)
    sval = np.zeros_like(spos)
    nc, nd = len(el.cv), len(el.dm)
    sval[:nc, 0] = sig["cv"]
    sval[nc : nc + nd] = sig["dm"]
    sval[nc + nd :, 0] = sig["mv"]
    out: dict[str, dict[str, Any]] = {}
    for q in QUANTITIES:
        var = np.einsum("nmdc,nc->md", jac.position[q] ** 2, spos**2) + np.einsum(
            "nmdc,nc->md", jac.value[q] ** 2, sval**2
        )
        if q == "inertia":
            rms = float(np.sqrt(var.max(initial=0.0)))
        else:
            rms = float(np.sqrt(var.sum(axis=1).max(initial=0.0)))
        out[q] = {
            "monte_carlo": np.concatenate(mc[q]),
            "linear": np.concatenate(lin[q]),
            "linear_rms": rms / scales[q],
        }
    return out


def monte_carlo(
    design: Design,
    model: ErrorModel,
    *,
    samples: int = 200,
    drift_samples: int | None = None,
    t_end: float = DEFAULT_T_END,
    levels: Sequence[float] = DEFAULT_LEVELS,
    seed: int = 0,
    rtol: float = DEFAULT_RTOL,
    target: float = DEFAULT_TARGET,
    material_errors: MaterialErrors | None = None,
) -> MonteCarloResult:
    """Monte Carlo of perturbed bodies: error distributions, I4 drift, linear prediction.

    Parameters
    ----------
    design : Design
    model : ErrorModel
        The manufacturing errors (one standard deviation each) at level 1.
    samples : int
        Perturbed bodies for the error distributions (1 .. MAX_SAMPLES).
    drift_samples : int, optional
        Perturbed bodies per level for the I4 drift (default ``samples``; 0: no simulation).
    t_end : float
        Duration of the simulations, s.
    levels : sequence of float
        Scale factors of the error model for the drift-against-tolerance curve (positive).
    seed : int
        Seed of the draws.
    rtol : float
        Integration tolerance of the ensemble.
    target : float
        Target of the sensitivity report included.
    material_errors : MaterialErrors, optional
        The materials' property errors, analysed in the report included.

    Returns
    -------
    MonteCarloResult
    """
    samples = _count(samples, "samples", 1)
    n_drift = samples if drift_samples is None else _count(drift_samples, "drift_samples", 0)
    t_end = as_finite_float(t_end, "t_end", positive=True)
    lv = np.array([as_finite_float(x, "levels", positive=True) for x in levels], dtype=float)
    if not 1 <= len(lv) <= MAX_LEVELS:
        raise input_error("levels", f"1 to {MAX_LEVELS} scale factors", list(levels))
    if model.is_zero:
        raise InputError(
            "tolerance: give at least one error (--position, --charge, --dipole, --mass)"
        )
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    report = tolerance_report(design, target, material_errors=material_errors)
    seconds["sensitivity"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    errors = error_distribution(design, model, samples, seed=seed)
    seconds["errors"] = time.perf_counter() - t0
    el = Elements.of(design)
    rng = np.random.default_rng([seed, 1])
    drift_mc = np.zeros((len(lv), n_drift))
    drift_lin = np.zeros((len(lv), n_drift))
    times = np.zeros(0)
    med = p90 = np.zeros(0)
    nominal_drift = 0.0
    if n_drift:
        bodies: list[Design] = [design]
        for level in lv:
            draws = _draw(el, model.scaled(float(level)), n_drift, rng)
            bodies += _designs_from_draws(design, draws)
        t0 = time.perf_counter()
        run = simulate_ensemble(bodies, t_end=t_end, rtol=rtol, atol=rtol)
        seconds["simulation"] = time.perf_counter() - t0
        nominal_drift = float(run.drift[0].max())
        per_body = run.drift[1:].max(axis=1).reshape(len(lv), n_drift)
        drift_mc = per_body
        one = int(np.argmin(np.abs(np.log(lv))))
        block = run.drift[1 + one * n_drift : 1 + (one + 1) * n_drift]
        times = run.times
        med = np.median(block, axis=0)
        p90 = np.quantile(block, 0.9, axis=0)
        t0 = time.perf_counter()
        drift_lin = _linear_drift(design, bodies[1:], t_end).reshape(len(lv), n_drift)
        seconds["linear_drift"] = time.perf_counter() - t0
    return MonteCarloResult(
        model=model,
        n=samples,
        errors=errors,
        levels=lv,
        drift_mc=drift_mc,
        drift_linear=drift_lin,
        drift_times=times,
        drift_median_over_time=med,
        drift_p90_over_time=p90,
        nominal_drift=nominal_drift,
        t_end=t_end,
        seconds=seconds,
        report=report,
    )


def _count(value: Any, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise input_error(name, f"an integer in {minimum}..{MAX_SAMPLES}", value)
    if not minimum <= int(value) <= MAX_SAMPLES:
        raise input_error(name, f"an integer in {minimum}..{MAX_SAMPLES}", value)
    return int(value)


def plot_drift(result: MonteCarloResult, ax: Any = None) -> Any:
    """Log-log plot of the I4 drift against the tolerance: Monte Carlo and linear response.

    Parameters
    ----------
    result : MonteCarloResult
    ax : matplotlib Axes, optional
        Drawn into; a new figure otherwise.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    pos = result.model.position
    if pos.value > 0.0 and not pos.relative:
        x = result.levels * pos.value
        ax.set_xlabel("position error (m, one standard deviation)")
    else:
        x = result.levels
        ax.set_xlabel(
            "error scale (1 = "
            + ", ".join(
                f"{k} {v}" for k, v in result.model.to_dict().items() if not v.startswith("0")
            )
            + ")"
        )
    mc_med = np.median(result.drift_mc, axis=1)
    mc_p90 = np.quantile(result.drift_mc, 0.9, axis=1)
    lin_med = np.median(result.drift_linear, axis=1)
    ax.loglog(x, mc_med, "o-", label="Monte Carlo (median)")
    ax.fill_between(x, mc_med, mc_p90, alpha=0.2, label="Monte Carlo (median..p90)")
    ax.loglog(x, lin_med, "s--", label="linear response (median)")
    if result.nominal_drift > 0.0:
        ax.axhline(result.nominal_drift, color="gray", lw=0.8, ls=":", label="nominal body")
    ax.set_ylabel(f"I4 relative drift to t = {fmt(result.t_end, PLAIN)} s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return ax


# ------------------------------------------------------------------------ robust design
# ------------------------------------------------------------------------ material properties


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
        command line, ``where = "--"``)."""
        out = {}
        for key, value in values.items():
            if key not in MATERIAL_ERROR_KEYS:
                raise input_error(where, "keys among " + ", ".join(MATERIAL_ERROR_KEYS), key)
            if value is None:
                continue
            name = "--" + key.replace("_", "-") if where == "--" else f"{where}.{key}"
            out[key] = check_material_error(value, name)
        return cls(**out)

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

    if design.medium is None or not design.materials:
        raise InputError(
            "tolerance: material errors need a physical design (a scene with [medium])"
        )
    legendre = tuple(design.field("magnetic"))
    if len(legendre) > 2 and any(legendre[2:]):
        raise InputError(
            "tolerance: material errors are analysed for magnetic fields of degree <= 2"
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
            out["volume_susceptibility"] = chi * (1.0 + e["chi_relative"][j])
        out["density_kg_per_m3"] = spec["density_kg_per_m3"] * (1.0 + e["density_relative"][j])
        if role == "magnet":
            out["remanent_magnetisation_A_per_m"] = spec["remanent_magnetisation_A_per_m"] * (
                1.0 + e["magnetisation_relative"][j]
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
            new_vol = vol / (1.0 + e["magnetisation_relative"][j])
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
        Range over orientations of each material's induced energy over the designed torques
        x 1 rad: the parasitic a relative error of 1 in its chi v leaves (exact: the energy is
        linear in chi v).
    nominal : float
        The design's own induced fraction (field_response; its round-off floor).
    monte_carlo, linear : ndarray, shape (samples,)
        The induced fraction of each perturbed body: recomputed from its parts by the field
        (:func:`~chargedesign.physical.realism.field_response`), and to first order from the
        sensitivity (moment formula).
    chi_needed, chi_negligible : float
        The relative accuracy of every material's chi (one standard deviation) at which the
        parasitic stays below the designed torques, and below ``RESPONSE_FRACTION`` of them,
        for 90 % of the batches (first order).
    """

    errors: MaterialErrors
    materials: list[str]
    sensitivity: np.ndarray
    nominal: float
    monte_carlo: np.ndarray
    linear: np.ndarray
    chi_needed: float
    chi_negligible: float

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
            f"standard deviation) for the induced parasitic to stay below the designed torques "
            f"in 90 % of the batches ({fmt(self.chi_negligible, ROUGH)} for it to be negligible); "
            f"susceptibility metrology reaches about {fmt(metrology, ORDER_SCI)} (calibrated ac "
            f"susceptometers, Chen & Skumryev 2010; SQUID magnetometers at percent level): "
            f"{reach} reach"
        )

    def to_dict(self) -> dict[str, Any]:
        return _jsonable(
            {
                "errors": self.errors.to_dict(),
                "samples": len(self.monte_carlo),
                "materials": list(self.materials),
                "sensitivity_fraction_per_unit_error": dict(
                    zip(self.materials, self.sensitivity.tolist(), strict=True)
                ),
                "nominal_induced_fraction": self.nominal,
                "induced_fraction": {
                    "monte_carlo": _quantiles(self.monte_carlo),
                    "linear": _quantiles(self.linear),
                },
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
            "induced_fraction_p90": float(np.quantile(self.monte_carlo, 0.9)),
            "chi_relative_needed": self.chi_needed,
        }

    def _text(self) -> str:
        mc, lin = _quantiles(self.monte_carlo), _quantiles(self.linear)
        lines = [
            "Material properties (errors at one standard deviation, one draw per material: "
            + ", ".join(f"{k} {fmt(v, PLAIN)}" for k, v in self.errors.to_dict().items())
            + f"; {len(self.monte_carlo)} bodies):",
            f"induced-magnetisation parasitic over the designed torques: median "
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
    body (Gaussian, one standard deviation = the relative error). The fraction reported is
    the range over orientations of the parts' induced energy over the designed torques x
    1 rad, as in the realism budget. Two routes: each perturbed body recomputed from its parts
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
        raise input_error("design", "a Design", design)
    if not isinstance(errors, MaterialErrors):
        raise input_error("errors", "MaterialErrors", errors)
    samples = _count(samples, "samples", 1)
    parts, groups = _material_groups(design)
    rate = typical_rate(design.parameters)
    legendre = tuple(design.field("magnetic"))
    if rate == 0 or not legendre:
        raise InputError("tolerance: material errors need a magnetic field and a typical motion")
    torque = design.parameters.C * rate**2 / 4.0
    gammas = fibonacci_directions(RESPONSE_ORIENTATIONS)
    per = np.zeros((len(groups), len(gammas)))
    for part in parts:
        j = groups.index((part["role"], part["name"]))
        per[j] += induced_energy(legendre, part["centres"], part["chi"] * part["volumes"], gammas)
    sensitivity = np.ptp(per, axis=1) / torque
    base = field_response(design)["induced_magnetisation_fraction"]["value"]
    nominal = float(base) if base is not None else math.inf
    nominal_energy = per.sum(axis=0)
    rng = np.random.default_rng(seed)
    draws = {
        key: getattr(errors, key) * rng.standard_normal((samples, len(groups)))
        for key in MATERIAL_ERROR_KEYS
    }
    # first order: chi v of each material changes by e_chi - e_rho (e_chi - e_M for magnets)
    volume_error = np.array(
        ["magnetisation_relative" if role == "magnet" else "density_relative" for role, _ in groups]
    )
    delta = draws["chi_relative"].copy()
    for j, key in enumerate(volume_error):
        delta[:, j] -= draws[key][:, j]
    linear = np.ptp(nominal_energy[None] + delta @ per, axis=1) / torque
    monte_carlo = np.empty(samples)
    for b in range(samples):
        body = _perturbed_materials(design, groups, {k: v[b] for k, v in draws.items()})
        value = field_response(body)["induced_magnetisation_fraction"]["value"]
        monte_carlo[b] = math.inf if value is None else value
    # the chi accuracy needed: the first-order parasitic is homogeneous of degree 1 in the
    # errors, so unit chi errors give it per unit accuracy (90 % of the batches)
    unit = np.random.default_rng([seed, 2]).standard_normal((max(samples, 1000), len(groups)))
    p90 = float(np.quantile(np.ptp(unit @ per, axis=1), 0.9)) / torque
    needed = 1.0 / p90 if p90 > 0 else math.inf
    return MaterialUncertainty(
        errors=errors,
        materials=[f"{role} {name}" for role, name in groups],
        sensitivity=sensitivity,
        nominal=nominal,
        monte_carlo=monte_carlo,
        linear=linear,
        chi_needed=needed,
        chi_negligible=RESPONSE_FRACTION * needed,
    )


def recorded_material_errors(design: Design) -> MaterialErrors | None:
    """The material errors a design records from its scene (design.json
    ``material_errors``, from ``[tolerance]``), or None."""
    recorded = design.material_errors
    if recorded is None:
        return None
    return MaterialErrors.from_table(recorded, "material_errors")
