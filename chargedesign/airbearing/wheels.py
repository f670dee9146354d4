"""The wheel array: its axes, and its torque and momentum sized from the planned motions.

The planned motions are the scene's start, or starts planned near the stable relative
equilibrium (:func:`chargedesign.airbearing.layout.plan_motions`); the wheels are sized for
the largest need among them (:class:`PlannedNeeds`).

The wheels are internal: with no external torque the total angular momentum
``L = J omega + h`` is constant in space, so ``|h| = |L - J omega| <= |L| + |J omega|``. With
the wheels at rest at the start, ``|L| = |J omega(0)|``: the wheels' momentum is bounded by
``|J omega(0)| + max_t |J omega(t)|`` along the motion (the bound the report gives).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import continuous_loop
from chargedesign.errors import InfeasibleError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.physical.state_of_the_art import MOUNT_MATERIALS, REACTION_WHEELS
from chargedesign.scene.testbed import TestbedOptions


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


#: a wheel's rim: a steel disc of thickness WHEEL_THICKNESS x its radius
WHEEL_THICKNESS = 0.3


@dataclass(frozen=True)
class WheelGeometry:
    """Where the wheels sit: centres (k, 3) m, bounding-sphere radii (k,) m, disc radii (k,)
    m, masses (k,) kg (counted within the platform's mass) and spin inertias (k,) kg m^2."""

    positions: np.ndarray
    radii: np.ndarray
    disc_radii: np.ndarray
    masses: np.ndarray
    spin_inertia: np.ndarray


def wheel_geometry(
    axes: np.ndarray,
    momentum: float,
    ball_radius: float,
    envelope: float,
    clear: Callable[[np.ndarray, np.ndarray], np.ndarray],
) -> WheelGeometry:
    """Steel disc wheels that store ``momentum`` (N m s) at the rated speed of
    :data:`~chargedesign.physical.state_of_the_art.REACTION_WHEELS`, each on its spin axis
    just off the ball, on the side of the axis that ``clear(centres, radii)`` allows.

    Raises
    ------
    InfeasibleError
        When a wheel fits on neither side (inside the envelope, clear of the keep-out cone).
    """
    speed = REACTION_WHEELS["speed_rad_per_s"].value
    density = MOUNT_MATERIALS["steel"][1].value
    spin = momentum / speed
    disc = (spin / (0.5 * density * math.pi * WHEEL_THICKNESS)) ** 0.2  # 1/2 m r^2 = spin
    mass = density * math.pi * disc**2 * WHEEL_THICKNESS * disc
    bound = math.hypot(disc, WHEEL_THICKNESS * disc / 2.0)
    distance = ball_radius + 1.1 * bound
    positions = []
    for k, axis in enumerate(axes):
        for side in (1.0, -1.0):
            centre = side * distance * axis
            if distance + bound <= envelope and clear(centre[None], np.array([bound]))[0]:
                positions.append(centre)
                break
        else:
            raise InfeasibleError(
                f"testbed: wheel {k} ({fmt(2 * disc * 1e3)} mm rim) fits on neither side of its "
                "axis inside the envelope and clear of the bearing's keep-out cone; give a "
                "larger platform_radius_m, another wheels array or a smaller tilt_limit_deg"
            )
    count = len(axes)
    return WheelGeometry(
        np.array(positions),
        np.full(count, bound),
        np.full(count, disc),
        np.full(count, mass),
        np.full(count, spin),
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


@dataclass(frozen=True)
class PlannedNeeds:
    """What the planned motions ask of the wheels: each motion's needs and the largest.

    Attributes
    ----------
    starts : ndarray, shape (motions, 6)
        The planned starts (the scene's first).
    motions : list of WheelNeeds
        Each start's needs (the ideal continuous loop).
    """

    starts: np.ndarray
    motions: Sequence[WheelNeeds]

    @property
    def torque_motion(self) -> int:
        """The index of the motion that needs the most torque on one wheel."""
        return int(np.argmax([m.torque for m in self.motions]))

    @property
    def momentum_motion(self) -> int:
        """The index of the motion that needs the most momentum on one wheel."""
        return int(np.argmax([m.momentum for m in self.motions]))

    @property
    def torque(self) -> float:
        return self.motions[self.torque_motion].torque

    @property
    def momentum(self) -> float:
        return self.motions[self.momentum_motion].momentum


def planned_needs(
    plant: Plant, starts: np.ndarray, axes: np.ndarray, t_end: float, samples: int = 2001
) -> PlannedNeeds:
    """The wheel needs of every planned start (one ideal-loop integration each)."""
    return PlannedNeeds(
        starts=starts,
        motions=[wheel_needs(plant, x0, axes, t_end, samples) for x0 in starts],
    )


def _motion_name(index: int, start: np.ndarray) -> str:
    """A planned motion named in one line: the scene's start, or a further start's state."""
    if index == 0:
        return "motion 0 (the scene's initial_p, initial_q, initial_gamma)"
    state = ", ".join(f"{fmt(v, PRECISE)}" for v in start)
    return (
        f"planned motion {index} (start [p, q, r, gamma] = [{state}], at the energy of "
        "initial_p, initial_q, initial_gamma; see planned_motions)"
    )


def wheel_limits(planned: PlannedNeeds, opts: TestbedOptions) -> tuple[float, float, float]:
    """(max torque N m, max momentum N m s, torque resolution N m) of each wheel.

    Sized from the planned motions' largest needs times the margin when the scene gives no
    limits; checked against them when it does.

    Raises
    ------
    InfeasibleError
        When a given limit is below what a planned motion needs (one line naming the limit
        and the motion).
    """
    torque = opts.max_torque_N_m
    momentum = opts.max_momentum_N_m_s
    t_end = opts.t_end_s
    if torque is not None and torque < planned.torque:
        k = planned.torque_motion
        raise InfeasibleError(
            f"testbed.max_torque_N_m: the wheels ({fmt(torque, PRECISE)} N m) are too weak for "
            f"{_motion_name(k, planned.starts[k])}, which needs {fmt(planned.torque, PRECISE)} N m"
            " on one "
            f"wheel over t_end_s = {fmt(t_end, PLAIN)} s; give stronger wheels or a slower motion"
        )
    if momentum is not None and momentum < planned.momentum:
        k = planned.momentum_motion
        raise InfeasibleError(
            f"testbed.max_momentum_N_m_s: the wheels ({fmt(momentum, PRECISE)} N m s) store too"
            " little "
            f"for {_motion_name(k, planned.starts[k])}, which needs"
            f" {fmt(planned.momentum, PRECISE)} N m s "
            f"on one wheel (bound {fmt(planned.motions[k].momentum_bound, PRECISE)} N m s from the "
            "conserved angular momentum); give larger wheels or a slower motion"
        )
    torque = torque if torque is not None else opts.wheel_margin * planned.torque
    momentum = momentum if momentum is not None else opts.wheel_margin * planned.momentum
    resolution = opts.torque_resolution_N_m or 2.0 * torque / 2**16
    opts.check_torque_step(resolution, planned.torque)
    return torque, momentum, resolution


__all__ = [
    "PlannedNeeds",
    "WheelGeometry",
    "WheelNeeds",
    "planned_needs",
    "wheel_axes",
    "wheel_geometry",
    "wheel_limits",
    "wheel_needs",
]
