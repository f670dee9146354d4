"""A body of charges, dipoles and masses for a case of (ep) with polynomial V and mu.

The general step of designing a case (the workbench issue, item 4): the conditions engine
derives the case's moment conditions (:func:`chargedesign.moment_conditions.case.
derive_case_conditions`: mu by charges in the magnetic field, V degree by degree by masses in
gravity, dipoles in the magnetic field or charges in the electric field, the inertia by
masses), and the designer's own problem places each source on the candidates
(:func:`design_source`). The body is then moved element by element: the torque of every
element in its field (``q (E + v x B)``, ``sigma x B`` and the force ``grad(sigma . B)``,
``-m grad Phi_g``) at sample attitudes and angular velocities is compared with the case's
Euler-Poisson torque ``gamma x dV/dgamma - omega x mu`` (:func:`element_torques`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.candidates import CandidateSet, candidates_from_points
from chargedesign.designer.case_masses import inertia_of
from chargedesign.designer.pipeline import design_source
from chargedesign.fields import AxisymmetricField
from chargedesign.moment_conditions import LinearConditions, physical_l_dot_gamma
from chargedesign.moment_conditions.case import derive_case_conditions
from chargedesign.results import Result
from chargedesign.scene.design import DesignOptions
from chargedesign.scene.keys import KEY

#: attitudes and angular velocities of the element-level torque comparison
TORQUE_SAMPLES = 64


@dataclass(repr=False)
class CaseElementBody(Result):
    """Charges, dipoles and masses that realise a case, with the torque recomputed.

    Attributes
    ----------
    name : str
    conditions : LinearConditions
        What the elements were designed to meet (fields included).
    charge_positions, charge_values : ndarray
        m, C.
    dipole_positions, dipole_moments : ndarray
        m, A m^2 (shape (n, 3)).
    mass_positions, mass_values : ndarray
        m, kg.
    inertia : ndarray, shape (3, 3)
        Recomputed from the masses, kg m^2.
    target_inertia : ndarray, shape (3, 3)
    torque_rel_err : float
        Largest ``|T_elements - T_case|`` over the samples, relative to the largest
        ``|T_case|`` (:func:`element_torques`).
    level_offset : float
        ``l . gamma`` of the charges (their canonical angular momentum about Z) minus the
        case's ``l . gamma``, kg m^2/s: a constant on the sphere when mu is matched, so the
        body's ``I3`` is the case's plus this constant (a conditional case's level ``h`` is
        the body's ``h + level_offset``).
    level_spread : float
        The largest deviation of that difference from its mean over the samples (0 up to
        rounding when mu is matched; kg m^2/s).
    """

    name: str
    conditions: LinearConditions
    charge_positions: np.ndarray
    charge_values: np.ndarray
    dipole_positions: np.ndarray
    dipole_moments: np.ndarray
    mass_positions: np.ndarray
    mass_values: np.ndarray
    inertia: np.ndarray
    target_inertia: np.ndarray
    torque_rel_err: float
    level_offset: float = 0.0
    level_spread: float = 0.0

    @property
    def fields(self) -> dict[str, tuple[float, ...]]:
        return {k: tuple(v) for k, v in self.conditions.fields.items() if len(v)}

    @property
    def inertia_rel_err(self) -> float:
        scale = float(np.max(np.abs(self.target_inertia)))
        return float(np.max(np.abs(self.inertia - self.target_inertia))) / scale

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "fields": {k: {"legendre": list(v)} for k, v in self.fields.items()},
            "charges": {
                "positions": self.charge_positions.tolist(),
                "values": self.charge_values.tolist(),
            },
            "dipoles": {
                "positions": self.dipole_positions.tolist(),
                "moments": self.dipole_moments.tolist(),
            },
            "masses": {
                "positions": self.mass_positions.tolist(),
                "values": self.mass_values.tolist(),
            },
            "inertia": self.inertia.tolist(),
            "inertia_rel_err": self.inertia_rel_err,
            "torque_rel_err": self.torque_rel_err,
            "level_offset": self.level_offset,
            "level_spread": self.level_spread,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "name": self.name,
            KEY.n_charges: len(self.charge_values),
            "n_dipoles": len(self.dipole_moments),
            "n_masses": len(self.mass_values),
            "inertia_rel_err": self.inertia_rel_err,
            "torque_rel_err": self.torque_rel_err,
        }


def element_torques(
    fields: dict[str, tuple[float, ...]],
    charges: tuple[np.ndarray, np.ndarray],
    dipoles: tuple[np.ndarray, np.ndarray],
    masses: tuple[np.ndarray, np.ndarray],
    gammas: np.ndarray,
    omegas: np.ndarray,
) -> np.ndarray:
    """The torque about O of every element in its field, summed, in body axes, N m.

    Per orientation (``gammas`` (m, 3) unit, ``omegas`` (m, 3) rad/s; a point r moves with
    ``v = omega x r``): charges ``r x q (E + v x B)``, dipoles ``sigma x B + r x grad(sigma . B)``
    (``B = -grad Phi_m``, ``grad(sigma . B) = -Hess(Phi_m) sigma``), masses
    ``r x (-m grad Phi_g)``. Returns (m, 3).
    """
    total = np.zeros((len(gammas), 3))
    magnetic = AxisymmetricField(tuple(fields.get("magnetic", ())))
    electric = AxisymmetricField(tuple(fields.get("electric", ())))
    gravity = AxisymmetricField(tuple(fields.get("gravity", ())))
    r, q = charges
    if len(q):
        B = -magnetic.gradient_body(r, gammas)  # (m, n, 3)
        E = -electric.gradient_body(r, gammas)
        v = np.cross(omegas[:, None, :], r[None, :, :])
        force = q[None, :, None] * (E + np.cross(v, B))
        total += np.cross(r[None, :, :], force).sum(axis=1)
    r, sigma = dipoles
    if len(sigma):
        B = -magnetic.gradient_body(r, gammas)
        H = magnetic.hessian_body(r, gammas)  # (m, n, 3, 3)
        force = -np.einsum("mnij,nj->mni", H, sigma)
        total += np.cross(sigma[None, :, :], B).sum(axis=1)
        total += np.cross(r[None, :, :], force).sum(axis=1)
    r, m = masses
    if len(m) and not gravity.is_zero:
        force = -m[None, :, None] * gravity.gradient_body(r, gammas)
        total += np.cross(r[None, :, :], force).sum(axis=1)
    return total


def case_torques(functions: Any, gammas: np.ndarray, omegas: np.ndarray) -> np.ndarray:
    """The case's Euler-Poisson torque ``gamma x dV/dgamma - omega x mu(gamma)``, (m, 3)."""
    dV = functions.potential_gradient(gammas)
    mu = functions.gyroscopic(gammas)
    return np.cross(gammas, dV) - np.cross(omegas, mu)


def torque_samples(count: int = TORQUE_SAMPLES, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Unit ``gammas`` and ``omegas`` (rad/s, unit-normal components) for the comparison."""
    rng = np.random.default_rng(seed)
    gammas = rng.standard_normal((count, 3))
    gammas /= np.linalg.norm(gammas, axis=1)[:, None]
    return gammas, rng.standard_normal((count, 3))


def design_case_elements(
    case: Any,
    candidates: CandidateSet | np.ndarray,
    fields: dict[str, tuple[float, ...]] | None = None,
    options: DesignOptions | None = None,
    *,
    conditions: LinearConditions | None = None,
) -> CaseElementBody:
    """Design charges, dipoles and masses on ``candidates`` (m) that realise ``case``.

    ``fields``: given fields (legendre per kind); the others are derived
    (:func:`~chargedesign.moment_conditions.case.derive_case_conditions`, for the candidates'
    size); ``conditions``: already derived for these candidates (derived here otherwise).

    Raises
    ------
    InputError, InfeasibleError, SolverError
    """
    from chargedesign.model.case_numeric import case_functions  # sympy: a case only

    cand = (
        candidates if isinstance(candidates, CandidateSet) else candidates_from_points(candidates)
    )
    if conditions is None:
        length = float(np.max(np.linalg.norm(cand.points, axis=1)))
        conditions = derive_case_conditions(case, fields or None, length=length)
    opts = options or DesignOptions()
    placed: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for source in ("charges", "dipoles", "masses"):
        if not conditions.for_source(source):
            shape = (0, 3) if source == "dipoles" else (0,)
            placed[source] = (np.zeros((0, 3)), np.zeros(shape))
            continue
        weights, _ = design_source(source, conditions, cand, opts)
        size = np.linalg.norm(weights, axis=1) if weights.ndim == 2 else np.abs(weights)
        keep = size > 0
        placed[source] = (cand.points[keep], weights[keep])
    gammas, omegas = torque_samples()
    used = {k: tuple(v) for k, v in conditions.fields.items()}
    body = element_torques(
        used, placed["charges"], placed["dipoles"], placed["masses"], gammas, omegas
    )
    functions = case_functions(case)
    reference = case_torques(functions, gammas, omegas)
    scale = max(float(np.max(np.abs(reference))), 1e-300)
    offset, spread = level_offset(case, used, placed["charges"], gammas)
    return CaseElementBody(
        name=case.name,
        conditions=conditions,
        charge_positions=placed["charges"][0],
        charge_values=placed["charges"][1],
        dipole_positions=placed["dipoles"][0],
        dipole_moments=placed["dipoles"][1],
        mass_positions=placed["masses"][0],
        mass_values=placed["masses"][1],
        inertia=inertia_of(*placed["masses"]),
        target_inertia=np.diag([float(m) for m in case.inertia]),
        torque_rel_err=float(np.max(np.abs(body - reference))) / scale,
        level_offset=offset,
        level_spread=spread,
    )


def level_offset(
    case: Any,
    fields: dict[str, tuple[float, ...]],
    charges: tuple[np.ndarray, np.ndarray],
    gammas: np.ndarray,
) -> tuple[float, float]:
    """``(mean, spread)`` of the charges' ``l . gamma`` (``sum q psi``, the natural
    axisymmetric gauge) minus the case's ``l . gamma`` at ``gammas``, kg m^2/s. A case given
    by ``mu`` fixes ``l . gamma`` only up to a constant: its offset is then a choice."""
    import sympy as sp

    from chargedesign.model.case import GAMMA

    positions, values = charges
    magnetic = fields.get("magnetic", ())
    body = (
        physical_l_dot_gamma(positions, values, magnetic, gammas)
        if len(values) and any(magnetic)
        else np.zeros(len(gammas))
    )
    own = sp.lambdify(GAMMA, case.l_dot_gamma, modules="numpy")
    target = np.broadcast_to(
        np.asarray(own(gammas[:, 0], gammas[:, 1], gammas[:, 2]), dtype=float), (len(gammas),)
    )
    difference = body - target
    mean = float(np.mean(difference))
    return mean, float(np.max(np.abs(difference - mean)))


__all__ = [
    "TORQUE_SAMPLES",
    "CaseElementBody",
    "case_torques",
    "design_case_elements",
    "element_torques",
    "level_offset",
    "torque_samples",
]
