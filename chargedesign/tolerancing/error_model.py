"""Manufacturing errors: one error size (:class:`Spread`, parsed from ``20um`` or ``1%``), the
Gaussian :class:`ErrorModel`, the draws of perturbed element arrays and their first-order
effect on mu, V and the inertia.

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.formatting import PLAIN, fmt
from chargedesign.sensitivity import QUANTITIES, Elements, Jacobians
from chargedesign.tolerancing.common import LENGTH_UNITS
from chargedesign.validation import as_finite_float, input_error


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


def standard_deviations(el: Elements, model: ErrorModel) -> dict[str, np.ndarray]:
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


def perturbed_arrays(el: Elements, model: ErrorModel, n: int, rng: np.random.Generator) -> dict:
    """Perturbed element arrays of ``n`` bodies (leading axis n) and their unit draws."""
    sig = standard_deviations(el, model)
    out = {}
    for key in ("cp", "cv", "dp", "dm", "mp", "mv"):
        base = getattr(el, key)
        z = rng.standard_normal((n, *base.shape))
        out[key] = base[None] + sig[key][None] * z
    # masses stay non-negative (a relative error of several tens of percent could flip one)
    out["mv"] = np.abs(out["mv"])
    return out


def linear_errors(jac: Jacobians, el: Elements, draws: Mapping[str, np.ndarray]) -> dict:
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
