"""The wheel array: its axes, and its torque and momentum sized from the planned motion.

The wheels are internal: with no external torque the total angular momentum
``L = J omega + h`` is constant in space, so ``|h| = |L - J omega| <= |L| + |J omega|``. With
the wheels at rest at the start, ``|L| = |J omega(0)|``: the wheels' momentum is bounded by
``|J omega(0)| + max_t |J omega(t)|`` along the motion (the bound the report gives).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import continuous_loop
from chargedesign.airbearing.options import TestbedOptions
from chargedesign.errors import InfeasibleError
from chargedesign.formatting import PLAIN, PRECISE, fmt


def wheel_axes(kind: str, pyramid_angle_deg: float) -> np.ndarray:
    """Unit spin axes (k, 3): the body axes, or four wheels at the angle from body z."""
    if kind == "orthogonal":
        return np.eye(3)
    b = math.radians(pyramid_angle_deg)
    return np.array(
        [
            [math.sin(b) * math.cos(a), math.sin(b) * math.sin(a), math.cos(b)]
            for a in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)
        ]
    )


@dataclass(frozen=True)
class WheelNeeds:
    """What the planned motion asks of the wheels (the continuous, ideal loop).

    Attributes
    ----------
    torque : float
        Largest |torque| of any wheel, N m.
    momentum : float
        Largest |momentum| of any wheel, N m s.
    momentum_norm : float
        Largest |h| (all wheels), N m s.
    momentum_bound : float
        ``|J omega(0)| + max |J omega|``, N m s (>= momentum_norm).
    times, states : ndarray
        The ideal loop's samples (s) and states (samples, 9).
    """

    torque: float
    momentum: float
    momentum_norm: float
    momentum_bound: float
    times: np.ndarray
    states: np.ndarray


def wheel_needs(
    plant: Plant, x0: np.ndarray, axes: np.ndarray, t_end: float, samples: int = 2001
) -> WheelNeeds:
    """The wheel torque and momentum the planned motion needs (ideal continuous loop)."""
    times, states = continuous_loop(plant, x0, t_end, samples)
    share = np.linalg.pinv(axes.T)  # body -> wheels, least norm
    torque = plant.command(states) @ share.T
    momentum = states[:, 6:9] @ share.T
    body_momentum = np.linalg.norm(states[:, 0:3] @ plant.inertia, axis=1)
    return WheelNeeds(
        torque=float(np.abs(torque).max()),
        momentum=float(np.abs(momentum).max()),
        momentum_norm=float(np.linalg.norm(states[:, 6:9], axis=1).max()),
        momentum_bound=float(body_momentum[0] + body_momentum.max()),
        times=times,
        states=states,
    )


def wheel_limits(needs: WheelNeeds, opts: TestbedOptions) -> tuple[float, float, float]:
    """(max torque N m, max momentum N m s, torque resolution N m) of each wheel.

    Sized from the needs times the margin when the scene gives no limits; checked against
    the needs when it does.

    Raises
    ------
    InfeasibleError
        When a given limit is below what the motion needs (one line naming both).
    """
    torque = opts.max_torque_N_m
    momentum = opts.max_momentum_N_m_s
    if torque is not None and torque < needs.torque:
        raise InfeasibleError(
            f"testbed.max_torque_N_m: the wheels ({fmt(torque, PRECISE)} N m) are too weak for the"
            " motion, "
            f"which needs {fmt(needs.torque, PRECISE)} N m on one wheel (from initial_p, initial_q,"
            " "
            f"initial_gamma over t_end_s = {fmt(needs.times[-1], PLAIN)} s); give stronger wheels"
            " or a "
            "slower motion"
        )
    if momentum is not None and momentum < needs.momentum:
        raise InfeasibleError(
            f"testbed.max_momentum_N_m_s: the wheels ({fmt(momentum, PRECISE)} N m s) store too"
            " little "
            f"for the motion, which needs {fmt(needs.momentum, PRECISE)} N m s on one wheel (bound "
            f"{fmt(needs.momentum_bound, PRECISE)} N m s from the conserved angular momentum); give"
            " larger "
            "wheels or a slower motion"
        )
    torque = torque if torque is not None else opts.wheel_margin * needs.torque
    momentum = momentum if momentum is not None else opts.wheel_margin * needs.momentum
    resolution = opts.torque_resolution_N_m or 2.0 * torque / 2**16
    return torque, momentum, resolution


__all__ = ["WheelNeeds", "wheel_axes", "wheel_limits", "wheel_needs"]
