"""Mounts: every part (ballast sphere, wheel) sits on a radial post from the bearing's ball,
and the posts bend under the part's weight as gravity turns in body axes.

A post is a solid cylinder of diameter d and length L from the ball's surface (radius R_b)
out to the part's surface, along the part's direction e; the part (mass m, radius a) sits
with its centre a beyond the post's tip. Under a force F normal to the post at the part's
centre (the tip load F and the moment F a), Euler-Bernoulli bending moves the centre by
``F (L^3/3 + a L^2 + a^2 L) / (E I)``, ``I = pi d^4 / 64``; along the post it compresses
by ``F L / (E A)``. Gravity is ``-g gamma`` in body axes, so part i moves by
``-g m_i [c_n (1 - e e^T) + c_a e e^T] gamma`` and the centre of mass by
``K gamma`` with ``K = -(g / M) sum m_i^2 [...]``. Only the part of ``K gamma`` normal to gamma
makes a torque; its largest size over all attitudes, ``(k_max - k_min) / 2`` for K's
eigenvalues, is the centre-of-mass offset the mounts add (a constant offset is trimmed and
estimated; this one turns with the attitude). The posts' own weight is small beside the
parts' and is left out of the bending; their mass and inertia are part of the platform.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.physical.state_of_the_art import MOUNT_MATERIALS

#: a post's diameter: this fraction of its part's diameter, within the bounds below
POST_FRACTION = 0.3
POST_MIN_DIAMETER_M = 0.004
POST_MAX_DIAMETER_M = 0.025
#: the shortest post (a part touching the ball still has a collar), m
POST_MIN_LENGTH_M = 0.002


@dataclass(frozen=True)
class Mounts:
    """One post per part: directions (n, 3), root and tip radii from O (n,), diameters (n,),
    the parts' masses and radii, and the material."""

    directions: np.ndarray
    root_m: np.ndarray
    tip_m: np.ndarray
    diameters_m: np.ndarray
    part_masses: np.ndarray
    part_radii: np.ndarray
    material: str

    @property
    def lengths_m(self) -> np.ndarray:
        return self.tip_m - self.root_m

    @property
    def masses(self) -> np.ndarray:
        density = MOUNT_MATERIALS[self.material][1].value
        return density * math.pi * self.diameters_m**2 / 4.0 * self.lengths_m

    @property
    def stiffness_N_per_m(self) -> np.ndarray:
        """Each post's bending stiffness at its part's centre, N/m."""
        return 1.0 / self._compliances()[0]

    def _compliances(self) -> tuple[np.ndarray, np.ndarray]:
        """(normal, axial) compliance at each part's centre, m/N."""
        E = MOUNT_MATERIALS[self.material][0].value
        L, a, d = self.lengths_m, self.part_radii, self.diameters_m
        second_moment = math.pi * d**4 / 64.0
        normal = (L**3 / 3.0 + a * L**2 + a**2 * L) / (E * second_moment)
        axial = L / (E * math.pi * d**2 / 4.0)
        return normal, axial

    def inertia(self) -> np.ndarray:
        """The posts' inertia about O (3x3): solid cylinders along their directions."""
        m, s1, s2, rho = self.masses, self.root_m, self.tip_m, self.diameters_m / 2.0
        e = self.directions
        across = m * ((s1**2 + s1 * s2 + s2**2) / 3.0 + rho**2 / 4.0)
        along = m * rho**2 / 2.0
        eye = np.eye(3)
        outer = np.einsum("ni,nj->nij", e, e)
        return np.einsum("n,nij->ij", across, eye - outer) + np.einsum("n,nij->ij", along, outer)

    def first_moment(self) -> np.ndarray:
        return (self.masses * (self.root_m + self.tip_m) / 2.0) @ self.directions

    def com_matrix(self, total_mass: float) -> np.ndarray:
        """K (3x3): the centre of mass moves by ``K gamma`` under gravity ``-g gamma``, m."""
        normal, axial = self._compliances()
        e = self.directions
        outer = np.einsum("ni,nj->nij", e, e)
        per_part = normal[:, None, None] * (np.eye(3) - outer) + axial[:, None, None] * outer
        weights = self.part_masses**2 * STANDARD_GRAVITY / total_mass
        return -np.einsum("n,nij->ij", weights, per_part)

    def offset_m(self, total_mass: float) -> float:
        """The largest attitude-dependent centre-of-mass offset normal to gravity, m."""
        k = np.linalg.eigvalsh(self.com_matrix(total_mass))
        return float(k[-1] - k[0]) / 2.0

    def to_list(self) -> list[dict]:
        stiffness = self.stiffness_N_per_m
        return [
            {
                "kind": "post",
                "material": self.material,
                "diameter_m": float(d),
                "length_m": float(L),
                "mass_kg": float(m),
                "stiffness_N_per_m": float(k),
                "direction": e.tolist(),
            }
            for d, L, m, k, e in zip(
                self.diameters_m,
                self.lengths_m,
                self.masses,
                stiffness,
                self.directions,
                strict=True,
            )
        ]


def radial_posts(
    centres: np.ndarray,
    radii: np.ndarray,
    masses: np.ndarray,
    ball_radius: float,
    material: str,
    room_rad: np.ndarray | None = None,
) -> Mounts:
    """A radial post from the ball to each part (centres (n, 3), radii (n,), masses (n,)).

    ``room_rad`` (n,): each direction's angular room to the keep-out cone; a post is thinned
    so that it stays clear of the cone at its root (its widest angle seen from O)."""
    dist = np.linalg.norm(centres, axis=1)
    directions = centres / dist[:, None]
    tip = np.maximum(dist - radii, ball_radius + POST_MIN_LENGTH_M)
    diameters = np.clip(POST_FRACTION * 2.0 * radii, POST_MIN_DIAMETER_M, POST_MAX_DIAMETER_M)
    if room_rad is not None:
        diameters = np.minimum(diameters, 2.0 * ball_radius * np.sin(np.maximum(room_rad, 0.0)))
    return Mounts(
        directions,
        np.full(len(dist), ball_radius),
        tip,
        diameters,
        np.asarray(masses, float),
        np.asarray(radii, float),
        material,
    )


__all__ = ["Mounts", "radial_posts"]
