"""The theorem's parameters as a validated value object.

SI units: C in kg m^2; n, K in 1/s; kappa, lambda, rho in 1/s^2; c, d dimensionless.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from chargedesign.formatting import PLAIN, fmt
from chargedesign.results import Result
from chargedesign.validation import as_finite_float, check_instance, check_keys

# names as written in scenes and design.json (``lambda`` is a Python keyword: attribute ``lam``)
from chargedesign.vocabulary import PARAMETER_NAMES as PARAMETER_NAMES


@dataclass(frozen=True)
class Parameters(Result):
    """Parameters of the Yehia-Elmandouh case (A = B = 2C).

    Parameters
    ----------
    C : float
        Moment of inertia about the symmetry axis, kg m^2 (> 0). A = B = 2C.
    c, d : float
        Dimensionless shape parameters of the K and kappa terms.
    n, K : float
        Gyroscopic strengths, 1/s.
    kappa, lam, rho : float
        Potential strengths, 1/s^2 (``lam`` is the paper's lambda). lambda and rho are
        singular on gamma3 = 0 and cannot be realised by charges; the model accepts them.
    """

    C: float = 1.0
    c: float = 0.0
    d: float = 0.0
    n: float = 0.0
    K: float = 0.0
    kappa: float = 0.0
    lam: float = 0.0
    rho: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            name = "lambda" if f.name == "lam" else f.name
            value = as_finite_float(
                getattr(self, f.name), f"parameter {name}", positive=f.name == "C"
            )
            object.__setattr__(self, f.name, value)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], where: str = "parameters") -> Parameters:
        """Build from a mapping with the contract's names; omitted ones are 0, C defaults to 1."""
        check_instance(data, Mapping, where, "a table of parameters")
        check_keys(data, PARAMETER_NAMES, where)
        kwargs = {("lam" if k == "lambda" else k): v for k, v in data.items()}
        return cls(**kwargs)

    def as_dict(self) -> dict[str, float]:
        """The contract's mapping (key ``lambda``)."""
        out = asdict(self)
        out["lambda"] = out.pop("lam")
        return {k: out[k] for k in PARAMETER_NAMES}

    def to_dict(self) -> dict[str, float]:
        """The contract's mapping (key ``lambda``); the result protocol's name for
        :meth:`as_dict`."""
        return self.as_dict()

    def _text(self) -> str:
        return ", ".join(f"{k} = {fmt(v, PLAIN)}" for k, v in self.as_dict().items())

    def replace(self, **changes: float) -> Parameters:
        if "lambda" in changes:
            changes["lam"] = changes.pop("lambda")
        return replace(self, **changes)

    @property
    def singular(self) -> bool:
        """True when lambda or rho is non-zero (terms singular on the plane gamma3 = 0)."""
        return self.lam != 0.0 or self.rho != 0.0
