"""The mass rows with the whole inertia: every part's own inertia and the holder's.

The conditions ask the masses' moments (inertia ``A = B = 2C``, centre of mass at O, and any
gravity moments) of point masses. A real part is a sphere (:mod:`chargedesign.physical.
holder`): its moments are the point's plus its own spread, and a holder adds a sphere about O
less a sphere of holder material at each part. The design meets the rows with all of it:

- a part in a bore replaces holder material, so what its mass adds is exactly
  ``m (1 - rho_h / rho)`` at its centre (plus the spreads): the ballast's columns are scaled
  by ``kappa = 1 - rho_h / rho_ballast`` (1 without a holder), a linear exact correction;
- the rest (the parts' own spreads, ``~ m^(5/3)``, the magnets' and carriers' bores, the
  holder's sphere) is the correction ``c(m)`` taken off the right-hand side: the rows are
  ``kappa A m + c(m) = b``. It is solved by fixed-point iteration, each round a least-norm
  polish on the support; it contracts like ``(5/3) (own / C) / kappa``, about 2e-2 for the
  K = 0 example, and ends when a round changes ``c`` by less than :data:`CONVERGED` of b.

The holder's radius encloses the parts with its wall; it only grows between rounds (rounded to
the holder's step), so the iteration ends.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chargedesign.physical.holder import (
    Holder,
    PartSpheres,
    enclosing_radius,
    holder_for,
    part_moments,
    parts_from_arrays,
)
from chargedesign.physical.materials import Material

#: a round that changes the correction by less than this fraction of the rows' size ends it
CONVERGED = 4e-16
#: rounds of the fixed point before it is refused as not converging
MAX_ROUNDS = 60


@dataclass
class Convergence:
    """How the whole-inertia iteration ended: ``rounds`` and the last round's change of the
    correction over the rows' size."""

    rounds: int = 0
    change: float = math.inf

    def to_dict(self) -> dict[str, float]:
        return {"rounds": self.rounds, "last_change_relative": self.change}


class WholeTerms:
    """The parts-and-holder terms of the mass rows for one set of carriers.

    ``rows``: the mass conditions (``coefficients`` by moment key); ``points``: the candidate
    sites; the carriers fixed at ``carrier_sites``.
    """

    def __init__(self, setup, carrier_sites: np.ndarray) -> None:
        spec = setup.spec
        self.setup = setup
        self.carrier_sites = np.asarray(carrier_sites, dtype=int)
        rows = setup.conditions.for_source("masses")
        self.keys = sorted({k for row in rows for k in row.coefficients})
        self.matrix = np.array([[row.coefficients.get(k, 0.0) for k in self.keys] for row in rows])
        self.b = np.array([row.value for row in rows], dtype=float)
        self.scale = max(float(np.max(np.abs(self.b), initial=0.0)), 1e-300)
        self.holder: Material | None = spec.holder
        self.magnet = spec.magnet
        self.attached = spec.ballast.density
        #: the holder's radius so far (:meth:`holder_of` only lets it grow; :meth:`restart`)
        self.radius = 0.0
        #: the largest holder the candidates could need: every cell filled
        reach = float(np.max(np.linalg.norm(setup.points, axis=1) + setup.cell_radius))
        self.largest = enclosing_radius(
            PartSpheres([], np.zeros((1, 3)), np.zeros(1), [[(0.0, 0.0, reach)]])
        )

    def restart(self) -> None:
        """Let the holder's radius follow the next parts (after a new solve of the program)."""
        self.radius = 0.0

    def kappa(self, density: float) -> float:
        """What a kilogram of a part of this density adds in a bore: ``1 - rho_h / rho``."""
        return 1.0 if self.holder is None else 1.0 - self.holder.density / density

    def _carriers(self):
        setup = self.setup
        k = len(self.carrier_sites)
        return (
            setup.points[self.carrier_sites],
            np.full(k, setup.carrier_mass),
            np.full(k, setup.carrier_radius),
            self.setup.spec.carrier.shell_thickness,
        )

    def parts(
        self,
        sigma: np.ndarray | None = None,
        masses: np.ndarray | None = None,
        densities: np.ndarray | None = None,
    ) -> PartSpheres:
        """The parts as spheres: the carriers, and from per-site ``sigma`` (n, 3) and
        ``masses`` (n,) (zero at the carriers) the magnets (with any attached ballast) and the
        ballast (of ``densities`` (n,), default the ballast's)."""
        points = self.setup.points
        n = len(points)
        sigma = np.zeros((n, 3)) if sigma is None else sigma
        masses = np.zeros(n) if masses is None else masses
        densities = np.full(n, self.attached) if densities is None else densities
        norms = np.linalg.norm(sigma, axis=1)
        magnets = np.flatnonzero(norms > 0)
        ballast = np.flatnonzero((norms == 0) & (masses > 0))
        M = self.magnet.magnetisation or 1.0
        return parts_from_arrays(
            carriers=self._carriers(),
            magnets=(
                points[magnets],
                masses[magnets],
                norms[magnets] / M,
                self.magnet.density,
                self.attached,
            ),
            ballast=(points[ballast], masses[ballast], densities[ballast]),
        )

    def holder_of(self, parts: PartSpheres) -> Holder | None:
        """The holder for these parts (its radius never below the last one's)."""
        if self.holder is None:
            return None
        self.radius = max(self.radius, enclosing_radius(parts))
        return holder_for(self.holder, parts, self.radius)

    def total_rows(self, parts: PartSpheres) -> np.ndarray:
        """The rows' values of the parts as spheres and the holder (its bores included)."""
        moments = part_moments(parts, self.keys).sum(axis=1)
        holder = self.holder_of(parts)
        if holder is not None:
            moments = moments + holder.moments(self.keys)
        return self.matrix @ moments

    def correction(self, parts: PartSpheres, lhs: np.ndarray) -> np.ndarray:
        """``c = rows(parts, holder) - lhs``, with ``lhs`` what the program's own rows give
        for these masses (``kappa A m`` plus the carriers)."""
        return self.total_rows(parts) - lhs

    def initial(self) -> np.ndarray:
        """The correction before any magnet or ballast: the carriers as spheres and the
        holder at its largest, without the program's carrier term."""
        parts = self.parts()
        Am, _ = self.setup.systems["masses"]
        carriers = Am[:, self.carrier_sites] @ np.full(
            len(self.carrier_sites), self.setup.carrier_mass
        )
        if self.holder is None:
            return self.total_rows(parts) - carriers
        moments = part_moments(parts, self.keys).sum(axis=1)
        moments = moments + holder_for(self.holder, parts, self.largest).moments(self.keys)
        return self.matrix @ moments - carriers

    def change(self, new: np.ndarray, old: np.ndarray) -> float:
        return float(np.max(np.abs(new - old), initial=0.0)) / self.scale

    def residual(self, parts: PartSpheres) -> float:
        """The whole rows' relative residual for these parts."""
        if not len(self.b):
            return 0.0
        top = max(float(np.linalg.norm(self.b)), 1e-300)
        return float(np.linalg.norm(self.total_rows(parts) - self.b)) / top
