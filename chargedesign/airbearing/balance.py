"""How precisely the platform must be built: linear response of I4 along the planned motion.

Along the ideal loop's motion (``omega' = f``, on I3 = 0, I4 constant) a small extra
angular acceleration ``d`` changes I4 in two ways, both first order:

- directly, at the rate ``dI4/domega . d`` (gradient by a 5-point stencil, exact for I4's
  quartic dependence on omega);
- by moving the state off the level I3 = 0 (``dI3/dt = (I gamma) . d``, I3 being conserved
  by the flow everywhere), where the flow itself changes I4 at ``Q dI3`` (I4 is an integral
  only on I3 = 0; ``Q`` is the derivative of the flow's I4 rate across the level).

The perturbations: an inertia error dJ the controller does not know (the ballast misplaced),
``d = -I^-1 (dJ f + omega x dJ omega)``; a centre of mass at r_c under gravity,
``d = I^-1 (-M g r_c x gamma)`` (normal to gamma: it keeps I3); the bearing's drag,
``d = -I^-1 b omega`` (it moves I3, and the second route then carries a tenth of its drift on
the unit-scale case). Integrated in time (trapezoid rule on the motion's samples), they give
the drift per unit error; a target drift divided by it is the tolerance. The tests compare
each against the simulated loop. The inertia's derivatives with respect to each ballast
part's position are the tolerance module's exact ones
(:func:`chargedesign.sensitivity.jacobians`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.platform import Ballast
from chargedesign.body import Design
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.sensitivity import jacobians
from chargedesign.simulation.direct import cross


@dataclass(frozen=True)
class Sensitivity:
    """I4's linear response along the planned motion (relative to |I4(0)|).

    Attributes
    ----------
    inertia : ndarray, shape (S, 3, 3)
        ``dI4(t) / dJ_ab / |I4(0)|``, 1/(kg m^2).
    imbalance : ndarray, shape (S, 3)
        ``dI4(t) / dr_c / |I4(0)|``, 1/m.
    drag : ndarray, shape (S,)
        ``dI4(t) / db / |I4(0)|``, 1/(N m s).
    """

    inertia: np.ndarray
    imbalance: np.ndarray
    drag: np.ndarray

    def inertia_drift(self, dJ: np.ndarray) -> float:
        """The relative I4 drift of an unknown inertia error dJ (3x3)."""
        return float(np.abs(np.einsum("sab,ab->s", self.inertia, dJ)).max())

    @property
    def imbalance_per_m(self) -> float:
        """Relative drift per metre of centre-of-mass offset, worst direction."""
        return float(np.linalg.norm(self.imbalance, axis=1).max())

    @property
    def drag_per_unit(self) -> float:
        return float(np.abs(self.drag).max())


def _i4_gradient(states: np.ndarray, plant: Plant, columns: int = 6) -> np.ndarray:
    """dI4/dx of the first ``columns`` state entries (5-point stencil, exact for quartics)."""
    h = 1e-3 * max(1.0, float(np.abs(states[:, 0:3]).max()))
    grad = np.zeros((len(states), columns))
    for a in range(columns):
        vals = []
        for k in (-2, -1, 1, 2):
            w = states[:, 0:6].copy()
            w[:, a] += k * h
            vals.append(plant.invariants(w)[1])
        grad[:, a] = (vals[0] - 8 * vals[1] + 8 * vals[2] - vals[3]) / (12 * h)
    return grad


def _i4_rate(states: np.ndarray, plant: Plant) -> np.ndarray:
    """dI4/dt along the flown model's flow (zero on its level, proportional to I3 off it)."""
    return np.einsum("sa,sa->s", _i4_gradient(states, plant), plant.reduced_rhs(states[:, 0:6]))


def _perturbing_accelerations(
    plant: Plant, omega: np.ndarray, gamma: np.ndarray, mass: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Perturbing accelerations per unit error, (S, 3, K): inertia (K = 9: dJ_ab), centre of
    mass (K = 3), drag (K = 1)."""
    inertia = plant.theorem_inertia
    eye = np.eye(3)
    f = plant.theorem_acceleration(omega, gamma)
    d_inertia = (
        -(
            np.einsum("ia,sb->siab", eye, f)
            + np.einsum(
                "sb,sia->siab",
                omega,
                np.stack([cross(omega, np.tile(e, (len(omega), 1))) for e in eye], axis=2),
            )
        ).reshape(len(omega), 3, 9)
        / inertia[None, :, None]
    )
    d_balance = (
        mass
        * STANDARD_GRAVITY
        * np.stack([cross(gamma, np.tile(e, (len(omega), 1))) for e in eye], axis=2)
        / inertia[None, :, None]
    )
    d_drag = (-omega / inertia)[:, :, None]
    return d_inertia, d_balance, d_drag


def sensitivity(plant: Plant, times: np.ndarray, states: np.ndarray, mass: float) -> Sensitivity:
    """The linear response along ``states`` (S, 6 or 9) at ``times`` (S,); ``mass`` in kg.

    A perturbing acceleration d changes I4 directly (``dI4/domega . d``) and moves the state
    off I3 = 0 (``dI3 = int (I gamma) . d``), where the flow itself changes I4 at
    ``Q dI3``; ``Q`` is the derivative of the flow's I4 rate across the level (r shifted,
    central difference).
    """
    omega, gamma = states[:, 0:3], states[:, 3:6]
    inertia = plant.theorem_inertia
    i4_0 = float(plant.invariants(states[:1, 0:6])[1][0])
    scale = abs(i4_0) if i4_0 != 0.0 else 1.0
    grad = _i4_gradient(states, plant, 3)
    eps = 1e-4 * max(1.0, float(np.abs(omega).max()))
    up, down = states[:, 0:6].copy(), states[:, 0:6].copy()
    up[:, 2] += eps
    down[:, 2] -= eps
    Q = (_i4_rate(up, plant) - _i4_rate(down, plant)) / (2 * eps * inertia[2] * gamma[:, 2])
    d_inertia, d_balance, d_drag = _perturbing_accelerations(plant, omega, gamma, mass)

    def response(d: np.ndarray) -> np.ndarray:  # integrated in time by the trapezoid rule
        rate_off = np.einsum("sa,sak->sk", gamma * inertia, d)
        off_level = cumulative_trapezoid(rate_off, times, axis=0, initial=0)
        rate = np.einsum("sa,sak->sk", grad, d) + Q[:, None] * off_level
        return cumulative_trapezoid(rate, times, axis=0, initial=0) / scale

    return Sensitivity(
        inertia=response(d_inertia).reshape(len(omega), 3, 3),
        imbalance=response(d_balance),
        drag=response(d_drag)[:, 0],
    )


def inertia_tolerances(sens: Sensitivity, target: float, C: float) -> dict[str, float]:
    """Largest unknown inertia errors (kg m^2) that keep the drift within ``target``.

    ``A_minus_B``: (A - B) with A + B kept; ``A_minus_2C``: A = B off 2C; ``product_xy`` etc.:
    one product of inertia.
    """
    cases = {
        "A_minus_B": np.diag([0.5, -0.5, 0.0]),
        "A_minus_2C": np.diag([0.5, 0.5, -0.5]),
        "product_xy": np.array([[0, 1, 0], [1, 0, 0], [0, 0, 0]], float),
        "product_xz": np.array([[0, 0, 1], [0, 0, 0], [1, 0, 0]], float),
        "product_yz": np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0]], float),
    }
    out = {}
    for name, dJ in cases.items():
        per_unit = sens.inertia_drift(dJ)
        out[name + "_kg_m2"] = target / per_unit if per_unit > 0 else float("inf")
    out["A_minus_B_relative"] = out["A_minus_B_kg_m2"] / (2.0 * C)
    return out


def part_tolerances(
    sens: Sensitivity, ballast: Ballast, plant: Plant, target: float, total_mass: float
) -> dict[str, np.ndarray]:
    """Per ballast part: the placement error (m, worst direction) that alone uses the target,
    through the inertia (exact derivatives, tolerance module) and through the balance."""
    design = Design(
        parameters=plant.params, mass_positions=ballast.positions, mass_values=ballast.masses
    )
    jac = jacobians(design, np.array([[0.0, 0.0, 1.0]]))
    d_inertia = jac.position["inertia"][:, 0]  # (n, 9, 3): dI_ij / dr_a
    flat = sens.inertia.reshape(len(sens.inertia), 9)  # (S, 9)
    per_m = np.linalg.norm(np.einsum("sk,nka->nsa", flat, d_inertia), axis=2).max(axis=1)
    through_inertia = np.where(per_m > 0, target / np.where(per_m > 0, per_m, 1.0), np.inf)
    # moving part i by dr moves the centre of mass by m_i dr / M
    per_m_balance = sens.imbalance_per_m * ballast.masses / total_mass
    through_balance = target / per_m_balance
    return {"through_inertia_m": through_inertia, "through_balance_m": through_balance}


__all__ = ["Sensitivity", "inertia_tolerances", "part_tolerances", "sensitivity"]
