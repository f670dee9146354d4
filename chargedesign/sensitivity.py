"""The sensitivity kernel: exact first derivatives of a body's mu, V and inertia with respect
to every element (:func:`jacobians`), and the per-candidate placement sensitivity the robust
design objective prices (:func:`sensitivity_weights`).

The formulas are in :mod:`chargedesign.tolerancing`'s docstring; the tolerance report and the
Monte Carlo (orchestration) build on this kernel there.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.checker import sample_orientations
from chargedesign.elements import ElementSet
from chargedesign.errors import InputError
from chargedesign.fields import AxisymmetricField
from chargedesign.model import evaluators
from chargedesign.validation import as_points

#: the quantities whose errors are analysed, in the check's names
QUANTITIES = ("mu", "V", "inertia")
DEFAULT_ORIENTATIONS = 200


# ------------------------------------------------------------------------ element access
def analysed_elements(design: Design) -> ElementSet:
    """The elements the analysis perturbs: the design's point elements with every mass (the
    ballast plus the carriers' and magnets' own) a point of its own
    (:meth:`~chargedesign.elements.ElementSet.point_elements`); a design with continuous bodies
    is refused."""
    check_point_elements(design.continuous)
    return design.point_elements()


def element_labels(el: ElementSet) -> list[tuple[str, int]]:
    """``(kind, index)`` of every element, in the analysis' order: charges, dipoles, masses."""
    return (
        [("charge", i) for i in range(len(el.charge_values))]
        + [("dipole", i) for i in range(len(el.dipole_moments))]
        + [("mass", i) for i in range(len(el.mass_values))]
    )


def with_masses(design: Design, positions: np.ndarray, values: np.ndarray) -> Design:
    """A copy of ``design`` whose mass points (:func:`analysed_elements`) are replaced."""
    return with_arrays(design, mass_positions=positions, mass_values=values)


def with_arrays(design: Design, **arrays: Any) -> Design:
    points = design.point_elements()  # every mass in the mass arrays (see analysed_elements)
    fields_ = {k: getattr(points, k) for k in ELEMENT_ARRAYS}
    fields_.update(arrays)
    return Design(
        parameters=design.parameters,
        fields=dict(design.fields),
        realises=list(design.realises),
        larmor=design.larmor,
        **fields_,
    )


ELEMENT_ARRAYS = (
    "charge_positions",
    "charge_values",
    "mass_positions",
    "mass_values",
    "dipole_positions",
    "dipole_moments",
)


def design_fields(design: Design) -> dict[str, AxisymmetricField]:
    return {
        k: AxisymmetricField(tuple(design.field(k))) for k in ("magnetic", "electric", "gravity")
    }


def orientations(n: int, seed: int = 0) -> np.ndarray:
    return sample_orientations(n, seed)


def check_theorem_design(design: Design, where: str = "design") -> None:
    """Refuse a design of a ``[case]`` not of the theorem's form, in one line naming ``where``.

    The tolerances are measured against the theorem's mu, V and inertia at the design's
    parameters (:func:`references`). A case of the theorem's form
    (:func:`~chargedesign.model.catalogue.theorem_parameters`) has the theorem's body and
    parameters, so those are its own figures; any other case's design.json keeps placeholder
    parameters (a Kowalevski body's report measured its V = C a gamma1 against V = 0).
    """
    record = design.further_keys.get("case")
    if record is None:
        return
    from chargedesign.model.case_numeric import case_from_record  # sympy: a case only
    from chargedesign.model.catalogue import theorem_parameters

    case = case_from_record(record)
    if theorem_parameters(case) is None:
        raise InputError(
            f"{where}: tolerance takes a design of the theorem, not of a case of another form "
            f"({case.name}: its V, l or inertia are not the theorem's, which the tolerances "
            "are measured against)"
        )


def references(design: Design, gammas: np.ndarray) -> dict[str, Any]:
    """The theorem's mu, centred V and inertia at ``gammas``, which the design's are measured
    against (a case's design only of the theorem's form: :func:`check_theorem_design`)."""
    check_theorem_design(design)
    # what the elements themselves realise (n = 0 for a frame body: n is the axes' rate)
    params = design.body_parameters
    mu = np.asarray(evaluators.gyroscopic(gammas, params), dtype=float)
    V = np.asarray(evaluators.potential(gammas, params), dtype=float)
    check_theorem_finite(bool(np.all(np.isfinite(mu)) and np.all(np.isfinite(V))))
    V = V - V.mean()
    return {
        "mu": mu,
        "V": V,
        "inertia": np.diag([2.0 * params.C, 2.0 * params.C, params.C]),
    }


# ------------------------------------------------------------------------ the quantities
def quantities(el: ElementSet, f: Mapping[str, AxisymmetricField], gammas: np.ndarray) -> dict:
    """mu (m, 3), V (m,) centred, inertia (3, 3) of the elements (batched over nothing)."""
    m = len(gammas)
    mu = np.zeros((m, 3))
    V = np.zeros(m)
    if len(el.charge_values):
        if not f["magnetic"].is_zero:
            G = f["magnetic"].gradient_body(el.charge_positions, gammas)
            s = np.einsum("mni,ni->mn", G, el.charge_positions)
            mu += np.einsum("mn,n,ni->mi", s, el.charge_values, el.charge_positions)
        if not f["electric"].is_zero:
            V += f["electric"].potential_body(el.charge_positions, gammas) @ el.charge_values
    if len(el.dipole_moments) and not f["magnetic"].is_zero:
        V += np.einsum(
            "mki,ki->m", f["magnetic"].gradient_body(el.dipole_positions, gammas), el.dipole_moments
        )
    if len(el.mass_values) and not f["gravity"].is_zero:
        V += f["gravity"].potential_body(el.mass_positions, gammas) @ el.mass_values
    r = el.mass_positions
    S = np.einsum("ij,ij->i", r, r)
    inertia = np.eye(3) * (el.mass_values @ S) - np.einsum("n,ni,nj->ij", el.mass_values, r, r)
    return {"mu": mu, "V": V - V.mean(), "inertia": inertia}


def batched_quantities(
    cp: np.ndarray,
    cv: np.ndarray,
    dp: np.ndarray,
    dm: np.ndarray,
    mp: np.ndarray,
    mv: np.ndarray,
    f: Mapping[str, AxisymmetricField],
    gammas: np.ndarray,
) -> dict[str, np.ndarray]:
    """As :func:`quantities` for B bodies at once (arrays with a leading body axis).

    Returns mu (B, m, 3), V (B, m) centred, inertia (B, 3, 3).
    """
    B, m = len(cv), len(gammas)
    mu = np.zeros((B, m, 3))
    V = np.zeros((B, m))
    n = cv.shape[1]
    if n:
        if not f["magnetic"].is_zero:
            G = f["magnetic"].gradient_body(cp.reshape(-1, 3), gammas).reshape(m, B, n, 3)
            s = np.einsum("mbni,bni->bmn", G, cp)
            mu += np.einsum("bmn,bn,bni->bmi", s, cv, cp)
        if not f["electric"].is_zero:
            P = f["electric"].potential_body(cp.reshape(-1, 3), gammas).reshape(m, B, n)
            V += np.einsum("mbn,bn->bm", P, cv)
    k = dm.shape[1]
    if k and not f["magnetic"].is_zero:
        G = f["magnetic"].gradient_body(dp.reshape(-1, 3), gammas).reshape(m, B, k, 3)
        V += np.einsum("mbki,bki->bm", G, dm)
    nm = mv.shape[1]
    if nm and not f["gravity"].is_zero:
        P = f["gravity"].potential_body(mp.reshape(-1, 3), gammas).reshape(m, B, nm)
        V += np.einsum("mbn,bn->bm", P, mv)
    S = np.einsum("bni,bni->bn", mp, mp)
    inertia = np.einsum("bn,bn->b", mv, S)[:, None, None] * np.eye(3) - np.einsum(
        "bn,bni,bnj->bij", mv, mp, mp
    )
    return {"mu": mu, "V": V - V.mean(axis=1, keepdims=True), "inertia": inertia}


@dataclass
class Jacobians:
    """Exact first derivatives of mu, V and the inertia with respect to every element.

    Attributes
    ----------
    labels : list of (kind, index)
        One per element, in the order charges, dipoles, masses.
    position : dict[str, ndarray]
        Per quantity, shape (n_elements, m, d, 3): ``d Q_a(g) / d r_j`` (d = 3 for mu, 1 for
        V, 9 for the inertia with m = 1). Units: Q's units per m.
    value : dict[str, ndarray]
        Per quantity, shape (n_elements, m, d, 3): derivative by the element's value (C, kg:
        only the first of the 3 columns is used) or dipole moment components (A m^2).
    value_width : ndarray, shape (n_elements,)
        1 for charges and masses, 3 for dipoles.
    """

    labels: list[tuple[str, int]]
    position: dict[str, np.ndarray]
    value: dict[str, np.ndarray]
    value_width: np.ndarray


def jacobians(design: Design, gammas: np.ndarray) -> Jacobians:
    """The exact derivatives of the check's error vectors (see the module docstring).

    Parameters
    ----------
    design : Design
    gammas : ndarray, shape (m, 3)
        Unit vectors (orientations).

    Returns
    -------
    Jacobians
    """
    el = analysed_elements(design)
    f = design_fields(design)
    g = as_points(gammas, "gammas")
    m = len(g)
    labels = element_labels(el)
    N = len(labels)
    dims = {"mu": 3, "V": 1, "inertia": 9}
    pos = {q: np.zeros((N, m if q != "inertia" else 1, d, 3)) for q, d in dims.items()}
    val = {q: np.zeros((N, m if q != "inertia" else 1, d, 3)) for q, d in dims.items()}
    width = np.array([3 if k == "dipole" else 1 for k, _ in labels])
    nc, nd = len(el.charge_values), len(el.dipole_moments)
    eye = np.eye(3)
    if nc:
        sl = slice(0, nc)
        if not f["magnetic"].is_zero:
            G = f["magnetic"].gradient_body(el.charge_positions, g)  # (m, n, 3)
            H = f["magnetic"].hessian_body(el.charge_positions, g)  # (m, n, 3, 3)
            s = np.einsum("mni,ni->mn", G, el.charge_positions)
            grad_s = G + np.einsum("mnij,nj->mni", H, el.charge_positions)
            # d mu_a / d r_b = q (r_a grad_s_b + s delta_ab)
            jac = np.einsum("na,mnb->nmab", el.charge_positions, grad_s) + np.einsum(
                "mn,ab->nmab", s, eye
            )
            pos["mu"][sl] = el.charge_values[:, None, None, None] * jac
            val["mu"][sl, :, :, 0] = np.einsum("mn,na->nma", s, el.charge_positions)
        if not f["electric"].is_zero:
            Ge = f["electric"].gradient_body(el.charge_positions, g)
            Pe = f["electric"].potential_body(el.charge_positions, g)
            pos["V"][sl, :, 0, :] = el.charge_values[:, None, None] * np.transpose(Ge, (1, 0, 2))
            val["V"][sl, :, 0, 0] = Pe.T
    if nd and not f["magnetic"].is_zero:
        sl = slice(nc, nc + nd)
        G = f["magnetic"].gradient_body(el.dipole_positions, g)
        H = f["magnetic"].hessian_body(el.dipole_positions, g)
        pos["V"][sl, :, 0, :] = np.einsum("mkij,kj->kmi", H, el.dipole_moments)
        val["V"][sl, :, 0, :] = np.transpose(G, (1, 0, 2))
    nm = len(el.mass_values)
    if nm:
        sl = slice(nc + nd, nc + nd + nm)
        r, w = el.mass_positions, el.mass_values
        if not f["gravity"].is_zero:
            Gg = f["gravity"].gradient_body(r, g)
            Pg = f["gravity"].potential_body(r, g)
            pos["V"][sl, :, 0, :] = w[:, None, None] * np.transpose(Gg, (1, 0, 2))
            val["V"][sl, :, 0, 0] = Pg.T
        S = np.einsum("ij,ij->i", r, r)
        dI_dm = S[:, None, None] * eye - np.einsum("ni,nj->nij", r, r)
        val["inertia"][sl, 0, :, 0] = dI_dm.reshape(nm, 9)
        # d I_ij / d r_a = m (2 r_a delta_ij - delta_ia r_j - r_i delta_ja)
        dI_dr = (
            2.0 * np.einsum("na,ij->nija", r, eye)
            - np.einsum("ia,nj->nija", eye, r)
            - np.einsum("ni,ja->nija", r, eye)
        )
        pos["inertia"][sl, 0] = w[:, None, None] * dI_dr.reshape(nm, 9, 3)
    # V is compared up to a constant: its derivatives are centred over the orientations too
    pos["V"] -= pos["V"].mean(axis=1, keepdims=True)
    val["V"] -= val["V"].mean(axis=1, keepdims=True)
    return Jacobians(labels=labels, position=pos, value=val, value_width=width)


def row_norm(J: np.ndarray, quantity: str) -> np.ndarray:
    """Worst-direction gain of (N, m, d, c) blocks, max over orientations: shape (N,).

    mu: spectral norm (Euclidean error); V: the vector norm; inertia: the largest row norm
    (the check's error is the largest absolute entry).
    """
    if quantity == "mu":
        gains = np.linalg.norm(J, ord=2, axis=(2, 3))
    else:
        gains = np.linalg.norm(J, axis=3).max(axis=2)
    return gains.max(axis=1)


def quantity_scales(design: Design, ref: Mapping[str, Any]) -> dict[str, float]:
    out = {
        "mu": float(np.linalg.norm(ref["mu"], axis=1).max(initial=0.0)),
        "V": float(np.abs(ref["V"]).max(initial=0.0)),
        "inertia": 2.0 * design.parameters.C,
    }
    # a zero reference (mu when n = K = 0): absolute errors (scale 1)
    return {k: (v if v > 0.0 else 1.0) for k, v in out.items()}


def sensitivity_weights(
    points: Any,
    source: str,
    fields: Mapping[str, Sequence[float]],
    parameters: Any,
    *,
    n_orientations: int = DEFAULT_ORIENTATIONS,
) -> np.ndarray:
    """First-order position sensitivity of a unit element at each candidate point.

    The error a displacement ``delta`` of an element of weight ``w`` at point ``p`` adds to
    quantity Q is at most ``|w| c_Q(p) |delta|`` (worst direction), relative to Q's scale.
    The returned ``c(p) = max_Q c_Q(p)`` (1/m per unit weight) turns the objective
    ``sum_j c_j |w_j|`` (charges, masses; ``||sigma_j||`` for dipoles) into the first-order
    worst-case relative error per metre of placement error: minimising it (alone or mixed
    with the sparsity objective) gives a body that tolerates the largest errors.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Candidate positions, m (body axes).
    source : {"charges", "dipoles", "masses"}
    fields : mapping
        Legendre coefficients per field kind.
    parameters : Parameters
        The theorem's parameters (the scales of mu, V and the inertia).
    n_orientations : int
        Orientations sampled.

    Returns
    -------
    ndarray, shape (n,)
        ``c_j`` in 1/(m * weight unit): weight unit C, A m^2 or kg.
    """
    pts = as_points(points, "points")
    if source not in ("charges", "dipoles", "masses"):
        raise ValueError(f"source: expected one of charges, dipoles, masses, got {source!r}")
    n = len(pts)
    unit = np.ones(n)
    zeros3, zeros = np.zeros((0, 3)), np.zeros(0)
    arrays: dict[str, Any] = {
        "charge_positions": zeros3,
        "charge_values": zeros,
        "dipole_positions": zeros3,
        "dipole_moments": zeros3,
        "mass_positions": zeros3,
        "mass_values": zeros,
    }
    if source == "charges":
        arrays.update(charge_positions=pts, charge_values=unit)
    elif source == "masses":
        arrays.update(mass_positions=pts, mass_values=unit)
    design = Design(
        parameters=parameters, fields={k: tuple(v) for k, v in fields.items()}, **arrays
    )
    gammas = orientations(n_orientations, 0)
    scales = quantity_scales(design, references(design, gammas))
    if source == "dipoles":
        # |dV/dr| = |H sigma| <= ||H||_2 |sigma|: the spectral norm of the field's Hessian
        f = AxisymmetricField(tuple(fields.get("magnetic", ())))
        if f.is_zero or n == 0:
            return np.zeros(n)
        H = f.hessian_body(pts, gammas)
        H = H - H.mean(axis=0, keepdims=True)  # V is compared up to a constant
        return np.linalg.norm(H, ord=2, axis=(2, 3)).max(axis=0) / scales["V"]
    jac = jacobians(design, gammas)
    out = np.zeros(n)
    for q in QUANTITIES:
        out = np.maximum(out, row_norm(jac.position[q], q) / scales[q])
    return out


def check_point_elements(continuous: Any) -> None:
    """The tolerance report's elements are points: refuse a design with continuous bodies."""
    if continuous:
        raise InputError(
            "tolerance: designs with continuous bodies are not supported (point elements only)"
        )


def check_theorem_finite(finite: bool) -> None:
    """The theorem's mu and V at the sampled orientations of ``tolerance``: all finite."""
    if not finite:
        raise InputError("tolerance: the theorem's mu or V is not finite at a sampled orientation")
