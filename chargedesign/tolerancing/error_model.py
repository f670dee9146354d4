"""Manufacturing errors: one error size (:class:`Spread`, parsed from ``20um`` or ``1%``), the
Gaussian :class:`ErrorModel`, the draws of perturbed element arrays and their first-order
effect on mu, V and the inertia.

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.elements import ElementSet
from chargedesign.scene.spreads import NO_SPREAD, Spread, parse_spread
from chargedesign.sensitivity import QUANTITIES, Jacobians


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

    position: Spread = NO_SPREAD
    charge: Spread = NO_SPREAD
    dipole: Spread = NO_SPREAD
    mass: Spread = NO_SPREAD

    @classmethod
    def parse(
        cls,
        position: Any = None,
        charge: Any = None,
        dipole: Any = None,
        mass: Any = None,
    ) -> ErrorModel:
        def one(v: Any, name: str, length: bool = False) -> Spread:
            return NO_SPREAD if v is None else parse_spread(v, name, length)

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


def standard_deviations(el: ElementSet, model: ErrorModel) -> dict[str, np.ndarray]:
    """Standard deviations per element array entry (same shapes as the arrays)."""

    def pos(r: np.ndarray) -> np.ndarray:
        s = model.position
        base = np.linalg.norm(r, axis=1) if s.relative else np.ones(len(r))
        return np.repeat((s.value * base)[:, None], 3, axis=1)

    def val(w: np.ndarray, s: Spread) -> np.ndarray:
        return s.value * (np.abs(w) if s.relative else np.ones_like(w))

    dip = model.dipole
    dsig = dip.value * (
        np.linalg.norm(el.dipole_moments, axis=1)
        if dip.relative
        else np.ones(len(el.dipole_moments))
    )
    return {
        "cp": pos(el.charge_positions),
        "cv": val(el.charge_values, model.charge),
        "dp": pos(el.dipole_positions),
        "dm": np.repeat(dsig[:, None], 3, axis=1),
        "mp": pos(el.mass_positions),
        "mv": val(el.mass_values, model.mass),
    }


#: the drawn arrays' keys and the element arrays they perturb, in the order they are drawn
DRAWN_ARRAYS = (
    ("cp", "charge_positions"),
    ("cv", "charge_values"),
    ("dp", "dipole_positions"),
    ("dm", "dipole_moments"),
    ("mp", "mass_positions"),
    ("mv", "mass_values"),
)


def perturbed_arrays(el: ElementSet, model: ErrorModel, n: int, rng: np.random.Generator) -> dict:
    """Perturbed element arrays of ``n`` bodies (leading axis n) and their unit draws."""
    sig = standard_deviations(el, model)
    out = {}
    for key, name in DRAWN_ARRAYS:
        base = getattr(el, name)
        z = rng.standard_normal((n, *base.shape))
        out[key] = base[None] + sig[key][None] * z
    # masses stay non-negative (a relative error of several tens of percent could flip one)
    out["mv"] = np.abs(out["mv"])
    return out


def element_rows(el: ElementSet, arrays: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Arrays keyed as :data:`DRAWN_ARRAYS` (leading axes allowed) as one row per element,
    charges, then dipoles, then masses (the Jacobians' order): positions (..., N, 3) and
    values (..., N, 3), a charge's or a mass's in column 0, a dipole moment's in all three."""
    nc, nd = len(el.charge_values), len(el.dipole_moments)
    pos = np.concatenate([arrays["cp"], arrays["dp"], arrays["mp"]], axis=-2)
    val = np.zeros(pos.shape)
    val[..., :nc, 0] = arrays["cv"]
    val[..., nc : nc + nd, :] = arrays["dm"]
    val[..., nc + nd :, 0] = arrays["mv"]
    return pos, val


def linear_errors(jac: Jacobians, el: ElementSet, draws: Mapping[str, np.ndarray]) -> dict:
    """First-order change of each quantity: dict of (B, m, d) arrays."""
    changes = {key: draws[key] - getattr(el, name) for key, name in DRAWN_ARRAYS}
    dpos, dval = element_rows(el, changes)  # (B, N, 3) each
    return {
        q: np.einsum("nmdc,bnc->bmd", jac.position[q], dpos)
        + np.einsum("nmdc,bnc->bmd", jac.value[q], dval)
        for q in QUANTITIES
    }
