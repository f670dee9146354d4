"""The checks of a case's point body against the case: inertia, element torques, I3's level.

A case of (ep) is designed by the one design program (:func:`chargedesign.designer.pipeline.
design_from_scene` on the case's conditions). Its body is then moved element by element: the
torque of every
element in its field (``q (E + v x B)``, ``sigma x B`` and the force ``grad(sigma . B)``,
``-m grad Phi_g``) at sample attitudes and angular velocities is compared with the case's
Euler-Poisson torque ``gamma x dV/dgamma - omega x mu`` (:func:`element_torques`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from chargedesign.fields import AxisymmetricField
from chargedesign.moment_conditions import physical_l_dot_gamma
from chargedesign.physical.holder import point_inertia

#: attitudes and angular velocities of the element-level torque comparison
TORQUE_SAMPLES = 64


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


def case_checks(case: Any, design: Any) -> dict[str, float]:
    """A point body's elements against the case they were designed for: the inertia from
    the masses and the torque of every element in its field against the case's
    Euler-Poisson torque at :data:`TORQUE_SAMPLES` states (both relative to the case's
    largest), and the charges' ``l . gamma`` offset from the case's (:func:`level_offset`).
    """
    from chargedesign.model.case_numeric import case_functions  # sympy: a case only

    fields = {k: tuple(v) for k, v in design.fields.items()}
    charges = (design.charge_positions, design.charge_values)
    masses = (design.mass_positions, design.mass_values)
    gammas, omegas = torque_samples()
    body = element_torques(
        fields, charges, (design.dipole_positions, design.dipole_moments), masses, gammas, omegas
    )
    reference = case_torques(case_functions(case), gammas, omegas)
    scale = max(float(np.max(np.abs(reference))), 1e-300)
    target = np.diag([float(m) for m in case.inertia])
    inertia = point_inertia(*masses)  # the whole inertia's points term, one formula
    offset, spread = level_offset(case, fields, charges, gammas)
    return {
        "inertia_rel_err": float(np.max(np.abs(inertia - target))) / float(np.max(target)),
        "torque_rel_err": float(np.max(np.abs(body - reference))) / scale,
        "level_offset": offset,
        "level_spread": spread,
    }


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
    "case_checks",
    "case_torques",
    "element_torques",
    "level_offset",
    "torque_samples",
]
