"""Platform and ballast: the convex mass program with parts that have sizes.

The platform is a given structure (mass, inertia about the bearing's centre O, centre of
mass). Ballast spheres of one material bring the total to the theorem's inertia
``diag(2C, 2C, C)`` (products zero) with the centre of mass at O. A sphere of mass m and
radius a at r adds ``m (|r|^2 1 - r r^T) + (2/5) m a^2 1``; its first moment ``m r``.

Without the spheres' own inertia the conditions are linear in the masses: a linear program
over candidate sites (least total mass; its optimum is a vertex with at most 9 parts). The
own inertia ``(2/5) m a^2 = (2/5) m (3 m / 4 pi rho)^(2/3)`` is then added by Gauss-Newton on
the chosen sites (exact Jacobian), which closes the conditions to round-off.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from chargedesign.errors import InfeasibleError, SolverError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.physical.limits import overlapping_pairs
from chargedesign.scene.testbed import TestbedOptions

#: the upper triangle of a symmetric 3x3 matrix (row, column)
_UPPER = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


@dataclass(frozen=True)
class Platform:
    """The base structure: mass (kg), inertia about O (3x3, kg m^2), centre of mass (m)."""

    mass_kg: float
    inertia: np.ndarray
    com: np.ndarray
    radius_m: float

    @classmethod
    def from_options(cls, opts: TestbedOptions, up: np.ndarray | None = None) -> Platform:
        """The scene's structure, or the default: a thin spherical shell (a cage) of radius R
        about O with an opening for the pedestal, the cap of the keep-out cone's half-angle
        alpha about ``-up`` (no opening for a full-sphere bearing: the floating ball).

        For the shell from the pole ``up`` to polar angle pi - alpha (areal density uniform,
        ``c = cos alpha``): centre of mass ``R (1 - c) / 2`` along up; with
        ``s2 = (c - c^3/3 + 2/3) / (1 + c)`` the mean of sin^2 of the polar angle, inertia
        ``M R^2 s2`` about up and ``M R^2 (1 - s2 / 2)`` across it (both 2/3 M R^2 for the
        whole sphere, c = -1... i.e. alpha = 0)."""
        m, R = opts.platform_mass_kg, opts.platform_radius_m
        u = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, float)
        alpha = 0.0 if opts.bearing == "full_sphere" else math.radians(opts.keep_out_half_angle_deg)
        c = math.cos(alpha)
        s2 = (c - c**3 / 3.0 + 2.0 / 3.0) / (1.0 + c)
        shell = m * R**2 * ((1.0 - s2 / 2.0) * np.eye(3) + (s2 - (1.0 - s2 / 2.0)) * np.outer(u, u))
        inertia = (
            np.array(opts.platform_inertia_kg_m2)
            if opts.platform_inertia_kg_m2 is not None
            else shell
        )
        com = (
            np.array(opts.platform_com_m)
            if opts.platform_com_m is not None
            else R * (1.0 - c) / 2.0 * u
        )
        return cls(mass_kg=m, inertia=inertia, com=com, radius_m=R)

    def with_structure(
        self, mass: float, first_moment: np.ndarray, inertia: np.ndarray
    ) -> Platform:
        """This platform with further structure (posts): its mass (kg), first moment (kg m)
        and inertia about O (3x3) added."""
        total = self.mass_kg + mass
        com = (self.mass_kg * self.com + first_moment) / total
        return Platform(total, self.inertia + inertia, com, self.radius_m)


@dataclass(frozen=True)
class Ballast:
    """Ballast spheres: positions (n, 3) m, masses (n,) kg, radii (n,) m, one material."""

    positions: np.ndarray
    masses: np.ndarray
    radii: np.ndarray
    material: str
    density: float

    @property
    def total_mass(self) -> float:
        return float(self.masses.sum())


def sphere_radii(masses: np.ndarray, density: float) -> np.ndarray:
    return np.cbrt(3.0 * masses / (4.0 * math.pi * density))


def parts_inertia(positions: np.ndarray, masses: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Inertia about O of spheres (3x3): point masses plus each sphere's own 2/5 m a^2."""
    r2 = np.einsum("ij,ij->i", positions, positions)
    own = 0.4 * masses * radii**2
    return np.eye(3) * float(masses @ r2 + own.sum()) - np.einsum(
        "n,ni,nj->ij", masses, positions, positions
    )


def total_inertia(platform: Platform, ballast: Ballast) -> np.ndarray:
    return platform.inertia + parts_inertia(ballast.positions, ballast.masses, ballast.radii)


def total_com(platform: Platform, ballast: Ballast) -> np.ndarray:
    moment = platform.mass_kg * platform.com + ballast.masses @ ballast.positions
    return moment / (platform.mass_kg + ballast.total_mass)


def candidate_sites(outer: float, inner: float, spacing: float, clearance: float) -> np.ndarray:
    """Grid sites (n, 3) with ``inner + clearance <= |r| <= outer - clearance``: a part of
    radius up to the clearance stays inside the envelope and off the bearing's ball."""
    k = math.floor(outer / spacing)
    axis = spacing * np.arange(-k, k + 1)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    norm = np.linalg.norm(grid, axis=1)
    return grid[(norm <= outer - clearance) & (norm >= inner + clearance)]


def _rows(positions: np.ndarray) -> np.ndarray:
    """(9, n): the first moments (3) and the inertia's upper triangle (6) per unit mass."""
    r2 = np.einsum("ij,ij->i", positions, positions)
    rows = [positions[:, a] for a in range(3)]
    for i, j in _UPPER:
        rows.append((r2 if i == j else 0.0) - positions[:, i] * positions[:, j])
    return np.array(rows)


def _targets(platform: Platform, C: float) -> np.ndarray:
    want = np.diag([2.0 * C, 2.0 * C, C]) - platform.inertia
    return np.concatenate([-platform.mass_kg * platform.com, [want[i, j] for i, j in _UPPER]])


def design_ballast(
    platform: Platform,
    C: float,
    opts: TestbedOptions,
    allowed: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> Ballast:
    """The least-mass ballast that gives ``diag(2C, 2C, C)`` about O and the centre at O.

    ``allowed(centres (n, 3), radii (n,))`` says which spheres may sit where (clear of the
    bearing's keep-out cone and of the wheels); every site is tried with the grid's
    clearance as its radius, and the sized parts are checked again.

    Raises
    ------
    InfeasibleError
        When no ballast inside the envelope (off the bearing's ball) reaches the target, or
        the parts overlap or leave the envelope once sized.
    """
    spacing = opts.ballast_spacing_m or platform.radius_m / 5.0
    clearance = spacing / 2.0
    for attempt in range(6):
        ballast = _ballast_on_grid(platform, C, opts, spacing, clearance, allowed)
        try:
            check_fit(ballast, platform.radius_m, opts.bearing_radius_m, allowed)
            return ballast
        except InfeasibleError:
            if attempt == 5:
                raise
        # parts larger than the grid allowed for: keep them clear of the walls and apart
        largest = float(ballast.radii.max())
        clearance = max(clearance, 1.05 * largest)
        if opts.ballast_spacing_m is None:
            spacing = max(spacing, 2.1 * largest)
    raise AssertionError("unreachable")  # pragma: no cover


def _ballast_on_grid(
    platform: Platform,
    C: float,
    opts: TestbedOptions,
    spacing: float,
    clearance: float,
    allowed: Callable[[np.ndarray, np.ndarray], np.ndarray] | None,
) -> Ballast:
    sites = candidate_sites(platform.radius_m, opts.bearing_radius_m, spacing, clearance)
    if allowed is not None and len(sites):
        sites = sites[allowed(sites, np.full(len(sites), clearance))]
    if len(sites) == 0:
        raise InfeasibleError(
            "testbed: no room for ballast between the bearing's ball and the envelope; give a "
            "larger platform_radius_m or a denser ballast_material"
        )
    rows, target = _rows(sites), _targets(platform, C)
    own = np.zeros(9)
    for _ in range(4):  # the spheres' own inertia moves the LP's target: re-solve with it
        masses = _least_mass(rows, target - own, platform, C)
        radii = sphere_radii(masses, opts.ballast_density)
        own[3:6] = float((0.4 * masses * radii**2).sum())
    keep = masses > 1e-9 * masses.max()
    return polished(platform, C, opts, sites[keep], masses[keep])


def polished(
    platform: Platform, C: float, opts: TestbedOptions, positions: np.ndarray, masses: np.ndarray
) -> Ballast:
    """The ballast on ``positions`` whose masses (from ``masses``) close the conditions for
    this platform exactly, each sphere's own inertia included."""
    masses = _polish(positions, masses, _targets(platform, C), opts.ballast_density)
    return Ballast(
        positions=positions,
        masses=masses,
        radii=sphere_radii(masses, opts.ballast_density),
        material=opts.ballast_material,
        density=opts.ballast_density,
    )


def _least_mass(rows: np.ndarray, target: np.ndarray, platform: Platform, C: float) -> np.ndarray:
    """The LP: least total mass with ``rows @ m = target``, ``m >= 0`` (HiGHS)."""
    from scipy.optimize import linprog

    scale = np.abs(rows).max(axis=1) + 1e-300  # equilibrate (first and second moments differ)
    lp = linprog(
        np.ones(rows.shape[1]),
        A_eq=rows / scale[:, None],
        b_eq=target / scale,
        bounds=(0, None),
        method="highs",
    )
    if lp.status == 2:
        raise InfeasibleError(
            f"testbed: no ballast inside the platform's envelope (radius "
            f"{fmt(platform.radius_m, PLAIN)} m) brings the inertia to A = B = 2C ="
            f" {fmt(2 * C, PLAIN)} kg m^2 "
            "with the centre at O; give a larger C, a larger platform_radius_m or a lighter, "
            "smaller platform"
        )
    if lp.status != 0:
        raise SolverError(f"testbed: the ballast program failed ({lp.message})")
    return np.asarray(lp.x, float)


def _polish(
    positions: np.ndarray, masses: np.ndarray, target: np.ndarray, rho: float
) -> np.ndarray:
    """Gauss-Newton on the masses with each sphere's own inertia (2/5) m a^2 included."""
    rows = _rows(positions)
    own_rows = np.zeros((9, 1))
    own_rows[3:6, 0] = 1.0  # the own inertia adds to the three diagonal entries
    k = (3.0 / (4.0 * math.pi * rho)) ** (2.0 / 3.0)  # a^2 = k m^(2/3)
    m = masses.copy()
    for _ in range(50):
        residual = rows @ m + own_rows[:, 0] * (0.4 * k * m ** (5.0 / 3.0)).sum() - target
        if np.abs(residual).max() <= 1e-15 * np.abs(target).max():
            break
        jac = rows + own_rows * (2.0 / 3.0 * k * m ** (2.0 / 3.0))[None, :]
        m = m - np.linalg.lstsq(jac, residual, rcond=None)[0]
        if (m <= 0).any():
            raise InfeasibleError(
                "testbed: the ballast's own inertia cannot be absorbed on the chosen sites; "
                "give a denser ballast_material or a larger platform_radius_m"
            )
    return m


def check_fit(
    ballast: Ballast,
    outer: float,
    inner: float,
    allowed: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> None:
    """Every part inside the envelope, off the ball, apart, and where ``allowed`` lets it be.

    Raises
    ------
    InfeasibleError
        Naming the first part that does not fit.
    """
    if allowed is not None:
        bad = np.flatnonzero(~allowed(ballast.positions, ballast.radii))
        if bad.size:
            i = int(bad[0])
            raise InfeasibleError(
                f"testbed: ballast part {i} ({fmt(ballast.masses[i])} kg, radius "
                f"{fmt(ballast.radii[i] * 1e3)} mm) enters the bearing's keep-out cone or a "
                "wheel; give a denser ballast_material, a larger platform_radius_m or a "
                "smaller tilt_limit_deg"
            )
    r = np.linalg.norm(ballast.positions, axis=1)
    out = np.flatnonzero((r + ballast.radii > outer) | (r - ballast.radii < inner))
    if out.size:
        i = int(out[0])
        raise InfeasibleError(
            f"testbed: ballast part {i} ({fmt(ballast.masses[i])} kg, radius "
            f"{fmt(ballast.radii[i] * 1e3)} mm) does not fit between the bearing's ball and the "
            "envelope; give a denser ballast_material, a larger platform_radius_m or a smaller "
            "ballast_spacing_m"
        )
    touching, _ = overlapping_pairs(ballast.positions, ballast.radii)
    if len(touching):
        i, j = (int(x) for x in touching[0])
        raise InfeasibleError(
            f"testbed: ballast parts {i} and {j} overlap; give a denser ballast_material or a "
            "larger ballast_spacing_m"
        )


__all__ = [
    "Ballast",
    "Platform",
    "candidate_sites",
    "check_fit",
    "design_ballast",
    "parts_inertia",
    "polished",
    "sphere_radii",
    "total_com",
    "total_inertia",
]
