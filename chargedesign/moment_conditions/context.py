"""The state one derivation carries through the mu, V and inertia steps, and its wording."""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

from chargedesign.formatting import FULL, fmt
from chargedesign.moment_conditions.algebra import SourceSystem
from chargedesign.moment_conditions.constants import FIELD_LETTERS
from chargedesign.params import Parameters


@dataclass
class DerivationContext:
    """One derivation: the exact inputs, the fields in use, one exact system per source, notes."""

    params: Parameters
    P: list[Fraction]  # C, c, d, n, K, kappa
    exact: bool
    fields: dict[str, list[Fraction]]  # exact legendre coefficients in use
    derivable: set[str]  # field kinds the engine may still choose (electric)
    systems: dict[str, SourceSystem]
    notes: list[str]
    length: Fraction = Fraction(1)  # body length scale (m) for default strengths
    length_given: bool = False
    defaults: dict[str, Fraction] = field(default_factory=dict)  # strengths chosen by default
    #: a case's V on the sphere (harmonic label -> (exact coefficient, text)); None: the theorem's
    v_target: dict[str, tuple[Fraction, str]] | None = None
    #: which source realises each degree of V (None: DEGREE_PREFERENCE / DEFAULT_PREFERENCE)
    preference: dict[int, tuple[str, ...]] | None = None
    #: per field kind: "given" (by the scene) or "derived" (by the engine)
    origin: dict[str, str] = field(default_factory=dict)

    def coefficient(self, kind: str, k: int) -> Fraction:
        coeffs = self.fields.get(kind, [])
        return coeffs[k - 1] if k <= len(coeffs) else Fraction(0)

    def set_coefficient(self, kind: str, k: int, value: Fraction) -> None:
        coeffs = self.fields.setdefault(kind, [])
        while len(coeffs) < k:
            coeffs.append(Fraction(0))
        coeffs[k - 1] = value


def decimal_text(value: Fraction) -> str:
    """Short decimal text of an exact value (for messages and notes)."""
    return fmt(float(value), FULL)


def field_coefficient_name(kind: str, k: int) -> str:
    """How a field's degree-k coefficient is named in notes (letter, degree, legendre index)."""
    if kind == "magnetic" and k == 1:
        return "a1 (legendre[0])"
    if kind == "magnetic" and k == 2:
        return "a2 (legendre[1] = 2 a2)"
    return f"{FIELD_LETTERS[kind]}{k} (legendre[{k - 1}])"
