"""The conditions' data types, shared with the design stage.

:class:`LinearCondition` is one condition ``sum_k coefficients[k] * moment[k] = value`` on
one source; :class:`LinearConditions` all of them, with the fields they assume and the
choices made (``system(source, positions)`` builds ``A`` and ``b``). Importing them is cheap
(no sympy).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.moment_conditions.constants import DEFAULT_LENGTH_RULE, SOURCES
from chargedesign.moment_conditions.text import format_conditions
from chargedesign.moments import monomial_matrix
from chargedesign.results import Result


@dataclass(frozen=True)
class LinearCondition:
    """One linear condition ``sum_k coefficients[k] * moment[k] = value`` on one source.

    Moment keys: sorted axis letters for charges and masses (``"xxz"``), and
    ``"<component>:<letters>"`` for dipoles (``"z:x"`` is ``sum sigma_z x``).
    ``provenance`` says which term of mu, V or the inertia the condition realises.
    ``exact_value`` (and ``exact_coefficients``) hold the exact rational values as strings
    (``"-7/10"``) when the conditions were derived with ``exact=True``; empty otherwise.
    """

    source: str
    coefficients: dict[str, float]
    value: float
    provenance: str
    exact_value: str = ""
    exact_coefficients: dict[str, str] = field(default_factory=dict)

    @property
    def single_key(self) -> str | None:
        """The moment key when the condition fixes a single moment, else None."""
        return next(iter(self.coefficients)) if len(self.coefficients) == 1 else None

    @property
    def fixed_value(self) -> float:
        """``value / coefficient`` for a single-moment condition (the moment's value)."""
        key = self.single_key
        if key is None:
            raise ValueError("fixed_value: the condition involves several moments")
        return self.value / self.coefficients[key]

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "source": self.source,
            "coefficients": dict(self.coefficients),
            "value": self.value,
            "provenance": self.provenance,
        }
        if self.exact_value:
            out["exact_value"] = self.exact_value
            out["exact_coefficients"] = dict(self.exact_coefficients)
        return out


@dataclass(repr=False)
class LinearConditions(Result):
    """All conditions of a target, with the fields they assume.

    Attributes
    ----------
    conditions : list of LinearCondition
    fields : dict[str, tuple[float, ...]]
        Legendre coefficients of the magnetic, electric and gravity fields the conditions
        assume (given by the user, or derived: see ``notes``).
    notes : list of str
        The choices made (which source realises which degree of V, forced and default
        field strengths, what the design stage must still enforce).
    realise : tuple of str
        What the conditions realise (subset of ``mu``, ``V``, ``inertia``).
    field_origin : dict[str, str]
        ``"given"`` or ``"derived"`` per field kind.
    length : float or None
        The body length scale (m) the default field strengths were chosen for; None when no
        strength was chosen by default (nothing depends on the body's size).
    length_assumed : bool
        True when no length was given and :data:`DEFAULT_LENGTH` (1 m) was used for a default
        strength (:func:`chargedesign.designer.design_body` then re-derives the conditions for
        the candidates' size, :meth:`for_length`).
    default_strengths : dict[str, float]
        The field coefficients chosen by default, e.g. ``{"electric e4": 1e-06}`` (V/m^4).
    """

    conditions: list[LinearCondition]
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    realise: tuple[str, ...] = ()
    field_origin: dict[str, str] = field(default_factory=dict)
    length: float | None = None
    length_assumed: bool = False
    default_strengths: dict[str, float] = field(default_factory=dict)
    #: the derivation with its inputs bound, awaiting ``length`` (set by derive_conditions;
    #: a callable rather than an import of it keeps types below derive)
    _rederive: Callable[..., LinearConditions] | None = field(
        default=None, repr=False, compare=False
    )

    def for_length(self, length: float) -> LinearConditions:
        """The same derivation with the default field strengths chosen for ``length`` (m).

        Returns ``self`` when no strength depends on the body length (nothing was chosen by
        default) or when the conditions were not made by :func:`derive_conditions`.
        """
        if not self.default_strengths or self._rederive is None:
            return self
        return self._rederive(length=length)

    def for_source(self, source: str) -> list[LinearCondition]:
        return [c for c in self.conditions if c.source == source]

    def system(self, source: str, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The linear system ``A w = b`` for weights at candidate ``positions`` (n, 3).

        For charges and masses ``w`` has shape (n,); for dipoles ``w`` is the flattened
        (n, 3) moment array (row-major: sigma_1x, sigma_1y, sigma_1z, sigma_2x, ...).
        Returns ``A`` of shape (m, n) or (m, 3n) and ``b`` of shape (m,).
        """
        if source not in SOURCES:
            raise ValueError(f"source: expected one of {', '.join(SOURCES)}, got {source!r}")
        rows = self.for_source(source)
        pts = np.asarray(positions, dtype=np.float64)
        n = len(pts)
        width = 3 * n if source == "dipoles" else n
        A = np.zeros((len(rows), width))
        b = np.array([row.value for row in rows], dtype=np.float64)
        for a, row in enumerate(rows):
            for key, coef in row.coefficients.items():
                if source == "dipoles":
                    comp, letters = key.split(":")
                    col = "xyz".index(comp)
                    A[a, col::3] += coef * monomial_matrix(pts, [letters])[0]
                else:
                    A[a] += coef * monomial_matrix(pts, [key])[0]
        return A, b

    def fixed_moments(self, source: str) -> dict[str, float]:
        """Moments fixed individually by a single-moment condition: ``{key: value}``."""
        out: dict[str, float] = {}
        for row in self.for_source(source):
            key = row.single_key
            if key is not None:
                out[key] = row.fixed_value
        return out

    def combinations(self) -> list[LinearCondition]:
        """Conditions that involve several moments (e.g. degree-4 harmonic moments)."""
        return [c for c in self.conditions if c.single_key is None]

    def to_dict(self) -> dict[str, Any]:
        """The JSON form of ``chargedesign conditions --json`` (contract keys first)."""
        out: dict[str, Any] = {s: self.fixed_moments(s) for s in SOURCES}
        out["combinations"] = [c.to_dict() for c in self.combinations()]
        out["fields"] = {
            kind: {"legendre": list(self.fields.get(kind, ())), "origin": origin}
            for kind, origin in self.field_origin.items()
        }
        out["realise"] = list(self.realise)
        if self.default_strengths:
            out["default_strengths"] = {
                "length_m": self.length,
                "length_assumed": self.length_assumed,
                "rule": DEFAULT_LENGTH_RULE,
                "values": dict(self.default_strengths),
            }
        out["notes"] = list(self.notes)
        out["conditions"] = [c.to_dict() for c in self.conditions]
        return out

    # result protocol (chargedesign.results)
    def _summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {s: len(self.for_source(s)) for s in SOURCES}
        out["realise"] = list(self.realise)
        out["fields"] = ",".join(k for k, v in self.fields.items() if len(v))
        if self.default_strengths:
            out["default_strengths"] = len(self.default_strengths)
        return out

    def _text(self) -> str:
        return format_conditions(self)
