"""The conditions engine: target parameters and fields -> linear conditions on moments.

Data types are fixed here so that the design stage can rely on them; the derivation
(``derive_conditions``) is built by coefficient matching on |gamma| = 1.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from chargedesign.moments import monomial_matrix

SOURCES = ("charges", "dipoles", "masses")


@dataclass(frozen=True)
class LinearCondition:
    """One linear condition ``sum_k coefficients[k] * moment[k] = value`` on one source.

    Moment keys: sorted axis letters for charges and masses (``"xxz"``), and
    ``"<component>:<letters>"`` for dipoles (``"z:x"`` is ``sum sigma_z x``).
    ``provenance`` says which term of mu, V or the inertia the condition realises.
    """

    source: str
    coefficients: dict[str, float]
    value: float
    provenance: str


@dataclass
class LinearConditions:
    """All conditions of a target, with the fields they assume."""

    conditions: list[LinearCondition]
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def for_source(self, source: str) -> list[LinearCondition]:
        return [c for c in self.conditions if c.source == source]

    def system(self, source: str, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The linear system ``A w = b`` for weights at candidate ``positions`` (n, 3).

        For charges and masses ``w`` has shape (n,); for dipoles ``w`` is the flattened
        (n, 3) moment array (row-major: sigma_1x, sigma_1y, sigma_1z, sigma_2x, ...).
        Returns ``A`` of shape (m, n) or (m, 3n) and ``b`` of shape (m,).
        """
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
