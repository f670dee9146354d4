"""The axes a simulation writes its motion in: inertial, or turning at n about Z (Larmor).

A ``frame`` body (design.json ``larmor = {"reading": "frame", "rate": n}``) realises the
theorem with n = 0: its elements' physics is integrated as it is (n = 0), and read in axes
turning at ``n`` about the space Z axis its motion is the theorem's motion with n
(:mod:`chargedesign.model.larmor` proves this exactly). Reading a state in the turning axes:

- ``omega -> omega - n gamma`` (:func:`chargedesign.larmor.to_turning_axes`): the angular
  velocity relative to axes whose own angular velocity is ``n Z = n gamma`` in body axes;
- the attitude ``R -> Rz(-n t) R`` (quaternion ``q -> q_z(-n t) q``), so gamma = R^T e_Z is
  unchanged;
- the integrals are the turning axes' (:meth:`.RigidBodySystem.integrals` with ``rate``).

A ``charges`` body (or a design without ``larmor``, or the bare reduced model) realises n with
its charges: its motion with n is already the theorem's in inertial axes. It has only that
reading: ``axes = "turning"`` on it is refused (one line), ``inertial`` is its default.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.larmor import to_turning_axes
from chargedesign.simulation.system import quaternion_gamma
from chargedesign.vocabulary import SIMULATION_AXES

__all__ = [
    "SIMULATION_AXES",
    "resolve_axes",
    "turning_poincare",
    "turning_states",
]


def resolve_axes(requested: str | None, larmor: Any, where: str = "axes") -> tuple[str, float]:
    """The axes a run is read in and their rate about Z (1/s; 0 for inertial axes).

    Parameters
    ----------
    requested : {"turning", "inertial"} or None
        None: ``turning`` for a ``frame`` body, ``inertial`` otherwise.
    larmor : LarmorReading or None
        The design's reading (None: no design, or a file without ``larmor``: charges).
    where : str
        The option's name in error messages.

    Raises
    ------
    InputError
        ``turning`` asked for a body without a frame reading.
    """
    frame = larmor is not None and larmor.is_frame
    axes = requested if requested is not None else ("turning" if frame else "inertial")
    if axes not in SIMULATION_AXES:  # the scene's checked [simulation] axes
        raise ValueError(f"{where}: expected one of {', '.join(SIMULATION_AXES)}, got {axes!r}")
    if axes == "inertial":
        return axes, 0.0
    if not frame:
        raise InputError(
            f"{where}: turning needs a frame body (design.json larmor.reading = 'frame'); this "
            "body has the charges reading (its charges realise n, or it is the reduced model): "
            "its motion is the theorem's in inertial axes"
        )
    # a frame body at rate 0 is read in turning axes that do not turn: the same numbers
    return axes, float(larmor.rate)


def _quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a b`` of quaternions ``(w, x, y, z)``, shapes (m, 4)."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.column_stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def turning_states(times: np.ndarray, states: np.ndarray, rate: float) -> np.ndarray:
    """States ``(p, q, r, w, x, y, z)`` read in axes turning at ``rate`` about Z.

    Parameters
    ----------
    times : ndarray, shape (T,)
        Sample times, s (the turning axes coincide with the inertial ones at t = 0).
    states : ndarray, shape (T, 7)
        Angular velocity in body axes (1/s) and the attitude quaternion (body to space).
    rate : float
        The axes' rate n about space Z, 1/s.

    Returns
    -------
    ndarray, shape (T, 7)
        ``omega - n gamma`` and the quaternion of ``Rz(-n t) R``.
    """

    out = np.array(states, dtype=float)
    gamma = quaternion_gamma(out[:, 3:])
    out[:, :3] = to_turning_axes(np.hstack([out[:, :3], gamma]), rate)[:, :3]
    half = -0.5 * rate * np.asarray(times, dtype=float)
    turn = np.column_stack([np.cos(half), np.zeros_like(half), np.zeros_like(half), np.sin(half)])
    out[:, 3:] = _quaternion_product(turn, out[:, 3:])
    return out


def turning_poincare(points: np.ndarray | None, rate: float) -> np.ndarray | None:
    """Section points ``(t, p, q, r, gamma1, gamma2, gamma3)`` with omega read in the
    turning axes (the crossing times and gamma are the same in both readings)."""
    if points is None:
        return None
    out = np.array(points, dtype=float)
    out[:, 1:] = to_turning_axes(out[:, 1:], rate)
    return out
