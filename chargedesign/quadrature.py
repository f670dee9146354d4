"""Continuous bodies (charge or mass densities on solids and surfaces) as weighted point sets.

A :class:`ContinuousBody` is a ball, a spherical shell (a surface), a cylinder (axis along
body z) or a box (edges along the body axes), with a uniform density or a density that is a
polynomial in body coordinates (x, y, z about O, in m). :func:`quadrature_points` turns it
into nodes and weights, so that ``sum_j w_j f(x_j)`` approximates ``int f rho dV`` (``dS``
on a shell); every point-set route (moments, check, export) then handles it unchanged.

Rules and exactness (``order`` = d, the total polynomial degree integrated exactly; the
integrand is the density times whatever is integrated, so moments of order k of a density of
degree p need ``order >= k + p``). ``GL(n)`` is n-point Gauss-Legendre (exact to degree
2n - 1); ``T(n)`` the n-point trapezoid rule in an angle (exact for trigonometric
polynomials of degree <= n - 1):

==========  ===================================================  ==========================
shape       rule                                                 nodes
==========  ===================================================  ==========================
box         GL(n) in x, y, z, n = ceil((d + 1) / 2)               n^3
ball        GL(n_r) in r on [0, a] (weight r^2 in the integrand),  n_r n_t n_phi
            GL(n_t) in cos(theta), T(n_phi) in phi;
            n_r = ceil((d + 3) / 2), n_t = ceil((d + 1) / 2),
            n_phi = d + 1
shell       GL(n_t) in cos(theta) x T(n_phi) on the sphere r = a  n_t n_phi
cylinder    GL(n_z) in z, GL(n_rho) in rho on [0, a] (weight      n_z n_rho n_phi
            rho), T(n_phi) in phi; n_z = ceil((d + 1) / 2),
            n_rho = ceil((d + 2) / 2), n_phi = d + 1
==========  ===================================================  ==========================

Why these counts: on the ball a monomial of degree j <= d is ``r^j`` times a spherical
polynomial of degree j; with the Jacobian the radial integrand has degree j + 2 <= 2 n_r - 1.
After the exact phi sum only terms ``cos^a(theta) sin^(2b)(theta)`` survive, a polynomial of
degree <= d in cos(theta), exact for GL(n_t). The cylinder is the same argument in the disk
(radial degree j + 1). Beyond degree d the error of a smooth (analytic) density decays
geometrically in the node count per direction, as Gauss rules do (measured in docs/check.md).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from chargedesign.elements import ElementSet
from chargedesign.moments import monomial_matrix
from chargedesign.scene.design_continuous import (
    DENSITY_TYPES,
    KINDS,
    SHAPES,
    continuous_fields,
    density_fields,
)
from chargedesign.scene.keys import KEY
from chargedesign.validation import input_error


@dataclass(frozen=True)
class Density:
    """A charge or mass density: uniform, or a polynomial in body coordinates.

    Parameters
    ----------
    type : str
        ``"uniform"`` or ``"polynomial"``.
    value : float
        The uniform density (C/m^3 or kg/m^3 on solids, C/m^2 or kg/m^2 on a shell).
    coefficients : dict[str, float]
        Polynomial density ``sum_key coef * x^i y^j z^k`` in body coordinates about O (m),
        keyed by sorted axis letters (``"xxz"`` is x^2 z, ``""`` the constant term).
    """

    type: str = "uniform"
    value: float = 0.0
    coefficients: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        # the fields were checked where they were read (scene.design_continuous)
        assert self.type in DENSITY_TYPES, self.type
        object.__setattr__(self, "value", float(self.value))
        coeffs = {key: float(coef) for key, coef in self.coefficients.items()}
        object.__setattr__(self, "coefficients", coeffs)

    @property
    def degree(self) -> int:
        """Polynomial degree of the density (0 when uniform)."""
        if self.type == "uniform":
            return 0
        return max((len(k) for k, v in self.coefficients.items() if v != 0.0), default=0)

    def evaluate(self, points: np.ndarray) -> np.ndarray:
        """Density at body ``points``, ``ndarray, shape (n, 3)`` in m; returns shape (n,)."""
        if self.type == "uniform":
            return np.full(len(points), self.value)
        keys = list(self.coefficients)
        if not keys:
            return np.zeros(len(points))
        coefs = np.array([self.coefficients[k] for k in keys])
        return coefs @ monomial_matrix(points, keys)

    def to_dict(self) -> dict[str, Any]:
        if self.type == "uniform":
            return {"type": "uniform", "value": self.value}
        return {"type": "polynomial", "coefficients": dict(self.coefficients)}

    @classmethod
    def from_dict(cls, data: Any, where: str = "density") -> Density:
        """Build from design.json's ``{"type", "value" | "coefficients"}`` (checked by
        :func:`chargedesign.scene.design_continuous.density_fields`)."""
        return cls(**density_fields(data, where))


@dataclass(frozen=True)
class ContinuousBody:
    """A charge or mass distribution on a ball, spherical shell, cylinder or box.

    Parameters
    ----------
    kind : str
        ``"charge"`` or ``"mass"``.
    shape : str
        ``"ball"`` (solid), ``"shell"`` (the sphere surface; the density is per m^2),
        ``"cylinder"`` (solid, axis along body z, ``height`` along z, centred on ``center``)
        or ``"box"`` (solid, edges along body axes).
    center : ndarray, shape (3,)
        Centre in body axes, m.
    density : Density
        Uniform or polynomial density (polynomial in body coordinates about O, not about
        the centre).
    radius : float, optional
        m, > 0 (ball, shell, cylinder).
    height : float, optional
        m, > 0 (cylinder: full length along z).
    half_size : ndarray, shape (3,), optional
        Half edge lengths in m, each > 0 (box).
    """

    kind: str
    shape: str
    center: np.ndarray
    density: Density
    radius: float | None = None
    height: float | None = None
    half_size: np.ndarray | None = None

    def __post_init__(self) -> None:
        # the fields were checked where they were read (scene.design_continuous)
        assert self.kind in KINDS and self.shape in SHAPES, (self.kind, self.shape)
        assert isinstance(self.density, Density), self.density
        object.__setattr__(self, "center", np.asarray(self.center, dtype=float))
        for key in ("radius", "height"):
            value = getattr(self, key)
            if value is not None:
                object.__setattr__(self, key, float(value))
        if self.half_size is not None:
            half = np.broadcast_to(np.asarray(self.half_size, dtype=float), (3,)).copy()
            object.__setattr__(self, KEY.half_size, half)

    @property
    def _radius_m(self) -> float:
        """The radius in m (0 for a box)."""
        return 0.0 if self.radius is None else float(self.radius)

    @property
    def _height_m(self) -> float:
        """The cylinder's height in m (0 for other shapes)."""
        return 0.0 if self.height is None else float(self.height)

    @property
    def _half_m(self) -> np.ndarray:
        """The box's half edges in m, shape (3,) (zeros for other shapes)."""
        return np.zeros(3) if self.half_size is None else np.asarray(self.half_size)

    @property
    def measure(self) -> float:
        """Volume in m^3 (area in m^2 for a shell)."""
        if self.shape == "ball":
            return 4.0 / 3.0 * math.pi * self._radius_m**3
        if self.shape == "shell":
            return 4.0 * math.pi * self._radius_m**2
        if self.shape == "cylinder":
            return math.pi * self._radius_m**2 * self._height_m
        return float(8.0 * np.prod(self._half_m))

    @property
    def extent(self) -> float:
        """Largest distance of the body's points from its centre, m."""
        if self.shape in ("ball", "shell"):
            return self._radius_m
        if self.shape == "cylinder":
            return math.hypot(self._radius_m, 0.5 * self._height_m)
        return float(np.linalg.norm(self._half_m))

    def to_dict(self) -> dict[str, Any]:
        """The design.json mapping (see :func:`ContinuousBody.from_dict`)."""
        out: dict[str, Any] = {"kind": self.kind, "shape": self.shape}
        if self.radius is not None:
            out["radius"] = self.radius
        if self.height is not None:
            out["height"] = self.height
        if self.half_size is not None:
            out[KEY.half_size] = [float(h) for h in self.half_size]
        out["center"] = [float(c) for c in self.center]
        out["density"] = self.density.to_dict()
        return out

    @classmethod
    def from_dict(cls, data: Any, where: str = "continuous") -> ContinuousBody:
        """Build from ``{"kind", "shape", size keys, "center", "density"}``.

        Size keys: ``radius`` (ball, shell, cylinder), ``height`` (cylinder), ``half_size``
        (box: three numbers, or one for a cube). ``center`` defaults to the origin.
        """
        fields = continuous_fields(data, where)
        return cls(**{**fields, "density": Density(**fields["density"])})

    @classmethod
    def coerce(cls, value: Any, where: str = "continuous") -> ContinuousBody:
        """A ContinuousBody unchanged, or one built from its design.json mapping."""
        if isinstance(value, ContinuousBody):
            return value
        return cls.from_dict(value, where)


def _as_order(order: Any) -> int:
    """A rule's degree of exactness. The command line checks its own option's range
    (``check --quadrature-order``), so a bad order here is a caller's mistake."""
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)):
        raise TypeError(f"order: expected an integer >= 0 (degree of exactness), got {order!r}")
    if order < 0:
        raise ValueError(f"order: expected an integer >= 0 (degree of exactness), got {order!r}")
    return int(order)


@lru_cache(maxsize=256)
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1] (read-only arrays)."""
    t, w = np.polynomial.legendre.leggauss(n)
    t.setflags(write=False)
    w.setflags(write=False)
    return t, w


def _gauss_on(n: int, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    t, w = _gauss(n)
    half = 0.5 * (hi - lo)
    return lo + half * (t + 1.0), half * w


def rule_sizes(shape: str, order: int) -> dict[str, int]:
    """Nodes per direction of the rule exact to total degree ``order`` (see module docstring)."""
    d = _as_order(order)
    if shape == "box":
        n = (d + 2) // 2
        return {"x": n, "y": n, "z": n}
    if shape == "ball":
        return {"r": (d + 4) // 2, "cos_theta": (d + 2) // 2, "phi": d + 1}
    if shape == "shell":
        return {"cos_theta": (d + 2) // 2, "phi": d + 1}
    if shape == "cylinder":
        return {"z": (d + 2) // 2, "rho": (d + 3) // 2, "phi": d + 1}
    raise ValueError(f"shape: expected one of {', '.join(SHAPES)}, got {shape!r}")


def _sphere_rule(n_t: int, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit-sphere nodes (n, 3) and weights (sum 4 pi): GL in cos(theta) x trapezoid in phi."""
    t, wt = _gauss(n_t)
    phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
    s = np.sqrt(np.clip(1.0 - t * t, 0.0, None))
    nodes = np.empty((n_t, n_phi, 3))
    nodes[..., 0] = s[:, None] * np.cos(phi)[None, :]
    nodes[..., 1] = s[:, None] * np.sin(phi)[None, :]
    nodes[..., 2] = t[:, None]
    weights = np.repeat(wt * (2.0 * math.pi / n_phi), n_phi)
    return nodes.reshape(-1, 3), weights


def geometric_rule(body: ContinuousBody, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and volume (area) weights of the body's shape, without its density.

    Parameters
    ----------
    body : ContinuousBody or dict
        The body (its density is ignored; a design.json mapping is accepted).
    order : int
        Degree of exactness d >= 0: ``sum_j w_j p(x_j) = int p dV`` for every polynomial p
        of total degree <= d in body coordinates.

    Returns
    -------
    points : ndarray, shape (n, 3)
        Nodes in body axes, m.
    weights : ndarray, shape (n,)
        Positive weights in m^3 (m^2 on a shell); they sum to the volume (area).
    """
    body = ContinuousBody.coerce(body)
    sizes = rule_sizes(body.shape, order)
    if body.shape == "box":
        half = body._half_m
        axes = [_gauss_on(sizes[a], -h, h) for a, h in zip("xyz", half, strict=True)]
        grid = np.meshgrid(*(a[0] for a in axes), indexing="ij")
        wgrid = np.meshgrid(*(a[1] for a in axes), indexing="ij")
        pts = np.stack([g.ravel() for g in grid], axis=1)
        w = (wgrid[0] * wgrid[1] * wgrid[2]).ravel()
    elif body.shape in ("ball", "shell"):
        a = body._radius_m
        dirs, wdir = _sphere_rule(sizes["cos_theta"], sizes["phi"])
        if body.shape == "shell":
            pts, w = a * dirs, (a * a) * wdir
        else:
            r, wr = _gauss_on(sizes["r"], 0.0, a)
            pts = (r[:, None, None] * dirs[None, :, :]).reshape(-1, 3)
            w = ((wr * r * r)[:, None] * wdir[None, :]).ravel()
    else:  # cylinder
        a, h = body._radius_m, body._height_m
        z, wz = _gauss_on(sizes["z"], -0.5 * h, 0.5 * h)
        rho, wrho = _gauss_on(sizes["rho"], 0.0, a)
        n_phi = sizes["phi"]
        phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
        pts = np.empty((len(z), len(rho), n_phi, 3))
        pts[..., 0] = rho[None, :, None] * np.cos(phi)[None, None, :]
        pts[..., 1] = rho[None, :, None] * np.sin(phi)[None, None, :]
        pts[..., 2] = z[:, None, None]
        w = (wz[:, None, None] * (wrho * rho)[None, :, None]) * np.full(n_phi, 2 * math.pi / n_phi)
        pts, w = pts.reshape(-1, 3), w.ravel()
    return pts + body.center[None, :], w


def quadrature_points(body: ContinuousBody, order: int) -> tuple[np.ndarray, np.ndarray]:
    """A continuous body as a weighted point set: charges in C or masses in kg at nodes.

    Parameters
    ----------
    body : ContinuousBody or dict
        The body (a design.json mapping is accepted).
    order : int
        Degree of exactness d of the geometric rule (see module docstring). Integrals of
        ``rho * p`` are exact when ``deg(rho) + deg(p) <= d``.

    Returns
    -------
    points : ndarray, shape (n, 3)
        Nodes in body axes, m.
    weights : ndarray, shape (n,)
        ``density(node) * volume weight``: charges in C (kind ``charge``) or masses in kg
        (kind ``mass``).

    Raises
    ------
    InputError
        Bad body or order; a mass body whose density is negative at a node.
    """
    body = ContinuousBody.coerce(body)
    pts, w = geometric_rule(body, order)
    weights = w * body.density.evaluate(pts)
    if body.kind == "mass":
        check_mass_weights(float(weights.min()))
    return pts, weights


def required_order(body: ContinuousBody, integrand_degree: int) -> int:
    """Degree of exactness that integrates ``density * p`` exactly for ``deg(p)`` given."""
    return ContinuousBody.coerce(body).density.degree + _as_order(integrand_degree)


@dataclass(kw_only=True, repr=False)
class GatheredElements(ElementSet):
    """Every charge and mass as a point (continuous bodies as quadrature nodes; the masses
    include the carriers' and magnets' own) and the dipoles, in body axes (m; C, kg, A m^2):
    the one element type, as the check and the simulation read it; ``quadrature``: per
    continuous body its ``kind``, ``shape``, ``order`` and ``nodes``."""

    quadrature: list[dict[str, Any]] = field(default_factory=list)


def gather_elements(
    design: Any, integrand_degree: int | Mapping[str, int], order: int | None = None
) -> GatheredElements:
    """A design's point elements plus its continuous bodies as quadrature nodes.

    Each continuous body (ContinuousBody or its design.json mapping) joins the charges or
    the masses with a rule of degree of exactness ``density degree + integrand degree``
    (``integrand_degree``: one degree for both kinds, or one per kind ``charge``/``mass``),
    or ``order`` when given. The checker and the simulation call this with their own
    integrand degrees.

    Returns
    -------
    GatheredElements
        The masses include the carriers' and magnets' own (as ``point_elements()`` gives).
    """
    points = design.point_elements()
    cp, cv = [points.charge_positions], [points.charge_values]
    mp, mv = [points.mass_positions], [points.mass_values]
    info = []
    for i, raw in enumerate(getattr(design, "continuous", None) or []):
        body = ContinuousBody.coerce(raw, f"continuous[{i}]")
        if order is not None:
            body_order = order
        elif isinstance(integrand_degree, Mapping):
            body_order = required_order(body, integrand_degree[body.kind])
        else:
            body_order = required_order(body, integrand_degree)
        pts, w = quadrature_points(body, body_order)
        (cp if body.kind == "charge" else mp).append(pts)
        (cv if body.kind == "charge" else mv).append(w)
        info.append({"kind": body.kind, "shape": body.shape, "order": body_order, "nodes": len(w)})
    return GatheredElements(
        charge_positions=np.concatenate(cp),
        charge_values=np.concatenate(cv),
        mass_positions=np.concatenate(mp),
        mass_values=np.concatenate(mv),
        dipole_positions=points.dipole_positions,
        dipole_moments=points.dipole_moments,
        quadrature=info,
    )


def check_mass_weights(smallest: float) -> None:
    """A mass body's quadrature weights (density x volume weight): none negative."""
    if smallest < 0.0:
        raise input_error("continuous.density", "a mass density >= 0 at every node", smallest)
