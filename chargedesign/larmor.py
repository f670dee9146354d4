"""The theorem's n is a uniform rotation of axes about Z (Larmor's theorem).

If ``(omega0(t), gamma(t))`` solves the theorem's equations with ``n = 0`` (K, c, d, kappa,
lambda, rho kept), then ``omega = omega0 - n gamma`` solves them with ``n``: the n-motion is
the n = 0 motion read in axes turning at rate ``n`` about the space Z axis. ``gamma`` (the
vertical in body axes) is the same in both readings; only the angular velocity changes, by
the turning axes' own ``n Z``. The exact proof is :mod:`chargedesign.model.certificate`'s
Larmor certificate; this module holds the numeric map and the reading a design records.

A body can realise n in two ways (``design.json`` key ``larmor``, scene ``[design] larmor``):

- ``charges``: the paper's (p6) reading, second moments of charge (a uniform charge-to-mass
  ratio with Larmor frequency n);
- ``frame``: the body realises the theorem with ``n = 0``; its motion, read in axes turning at
  ``rate`` about Z, is the theorem's motion with ``n = rate``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from chargedesign.params import Parameters
from chargedesign.validation import as_finite_float, check_choice, input_error
from chargedesign.vocabulary import LARMOR_READINGS


def check_object(value: Any, keys: Sequence[str], where: str) -> None:
    """Refuse anything but a dict with exactly ``keys`` in one line."""
    if not isinstance(value, dict) or set(value) != set(keys):
        raise input_error(where, "an object with keys " + ", ".join(keys), value)


__all__ = [
    "LARMOR_READINGS",
    "LarmorReading",
    "body_parameters",
    "from_turning_axes",
    "to_turning_axes",
]


@dataclass(frozen=True)
class LarmorReading:
    """How a body realises the theorem's n.

    Attributes
    ----------
    reading : str
        ``charges`` or ``frame`` (:data:`~chargedesign.vocabulary.LARMOR_READINGS`).
    rate : float
        The theorem's n, 1/s: the rate of the turning axes for ``frame``.
    """

    reading: str
    rate: float

    def __post_init__(self) -> None:
        check_choice(self.reading, LARMOR_READINGS, "larmor.reading")
        object.__setattr__(self, "rate", as_finite_float(self.rate, "larmor.rate"))

    @property
    def is_frame(self) -> bool:
        return self.reading == "frame"

    def to_dict(self) -> dict[str, Any]:
        """design.json's ``larmor`` object."""
        return {"reading": self.reading, "rate": self.rate}

    @classmethod
    def from_dict(cls, value: Any, where: str = "larmor") -> LarmorReading:
        check_object(value, ("reading", "rate"), where)
        return cls(value["reading"], value["rate"])


def body_parameters(parameters: Parameters, reading: LarmorReading | None) -> Parameters:
    """The parameters the body's own elements realise: ``n = 0`` for ``frame``, else as given."""
    if reading is not None and reading.is_frame:
        return replace(parameters, n=0.0)
    return parameters


def to_turning_axes(states: Any, rate: float) -> np.ndarray:
    """Body-axis states ``[p, q, r, gamma1, gamma2, gamma3]`` of the n = 0 motion, read in
    axes turning at ``rate`` about Z: ``omega -> omega - rate gamma``, gamma unchanged.

    Parameters
    ----------
    states : array_like, shape (6,) or (m, 6)
    rate : float
        The turning axes' rate n, 1/s.
    """
    x = np.array(states, dtype=float)
    x[..., :3] -= rate * x[..., 3:6]
    return x


def from_turning_axes(states: Any, rate: float) -> np.ndarray:
    """The inverse of :func:`to_turning_axes`: ``omega -> omega + rate gamma``."""
    x = np.array(states, dtype=float)
    x[..., :3] += rate * x[..., 3:6]
    return x
