"""Forward check of a design: recompute mu, V, the torques and the inertia from the fields.

The route is deliberately independent of the moments and of the body-frame shortcuts used to
derive the conditions: for each orientation gamma the body is *rotated*. With a rotation
``R`` whose last row is gamma (``R^T e_Z = gamma``) and whose first row is a random unit
vector perpendicular to gamma (the fields are axisymmetric, so the answer must not depend on
it), every element sits at ``X = R r`` in space; the harmonic potentials, their gradients
and Hessians are evaluated there in space axes with this module's own Cartesian recurrences
(a second implementation, sharing no code with :mod:`chargedesign.fields`; the tests and the
benchmark compare the two), forces, energies and torques are summed in space axes and the
sums are rotated back to body axes with ``R^T``. Compared with the theorem
(:mod:`chargedesign.model.evaluators`):

- ``mu``: the integral ``mu = -sum q (r . B) r`` (B in body axes).
- ``gyroscopic_torque``: the Lorentz torque ``sum r x q (v x B)`` of the charges moving with
  ``v = omega x r`` for a random ``omega`` per orientation, against ``mu x omega``. Sign:
  Euler-Poisson ``omega' I + omega x (omega I + mu) = gamma x dV/dgamma`` reads
  ``I omega' + omega x I omega = mu x omega + gamma x dV/dgamma``, so the torque of the
  velocity-dependent forces is ``mu x omega``. (Indeed ``r x ((omega x r) x B) =
  -(r . B) r x omega``.)
- ``V``: ``sum q Phi_e + sum m Phi_g - sum sigma . B``, up to an additive constant.
- ``potential_torque``: ``sum X x F`` of the charges (``F = -q grad Phi_e``), the masses
  (``F = -m grad Phi_g``) and the dipoles (``sigma x B + X x grad(sigma . B)``), rotated back,
  against ``gamma x dV/dgamma``.
- ``inertia``: ``sum m (|r|^2 1 - r r^T)`` against ``diag(2C, 2C, C)``.

Relative error of a quantity x(gamma) against its reference x_ref(gamma) over the sampled
orientations:

    rel_err = max_g |x(g) - x_ref(g)| / max_g |x_ref(g)|

with ``|.|`` the Euclidean norm. For V the constant is removed first (x and x_ref each minus
its mean over the orientations; the difference of the means is ``V_offset``), so the
denominator is the reference's spread. The inertia is one matrix (largest absolute entry of
the difference over the largest entry of ``diag(2C, 2C, C)``). A reference that is zero at
every orientation (mu when n = K = 0) has no relative error: rel_err is then the absolute
error divided by the gross contributions (``basis = "gross"``).

Rounding floor. When the elements' contributions are far larger than the quantity (weak
fields force large charges whose contributions cancel), a floating-point evaluation is
only as accurate as its unit roundoff times ``cancellation = gross / max |x_ref|``, with
``gross`` the sum over the elements of the size of their contributions
(:func:`contribution_sizes`): ``rounding_floor = ROUNDING_FACTOR * (unit * cancellation +
EPS)``. A claimed quantity passes when ``rel_err <= tol``; it fails as ``unverifiable``
when its floor exceeds ``tol`` (unless the error is beyond ``tol`` by more than the floor:
then it is a plain ``fail``). With ``precision="auto"`` the sums are evaluated in
double-double (:func:`evaluate_accurate`, unit 2^-104) whenever a claimed quantity's double
floor exceeds ``ACCURATE_FRACTION * tol``, so a correct but heavily cancelling body is
verified, and a wrong one is measured, not hidden under a floor.

Per effect (``lorentz``: charges in B; ``electric``: charges in E; ``gravity``: masses;
``magnetization``: dipoles; ``inertia``: masses) the report gives the effect's size and the
agreement of two routes within the effect (informational): Lorentz torque against
``mu_design x omega``, and for the potential effects the force torque against
``gamma x grad`` of a polynomial fitted to the effect's sampled energies (degree of the
field; the tangential gradient is unique on the sphere).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.elements import ElementSet
from chargedesign.errors import SolverError
from chargedesign.fields import AxisymmetricField
from chargedesign.moments import moment_keys, monomial_matrix, parse_moment_key
from chargedesign.quadrature import ContinuousBody, quadrature_points
from chargedesign.results import Result
from chargedesign.validation import as_finite_float, input_error
from chargedesign.vocabulary import (
    CHECK_DEFAULT_ORIENTATIONS,
    CHECK_DEFAULT_TOL,
    CHECK_EFFECTS,
    FIELD_NAMES,
    PRECISIONS,
)

DEFAULT_TOL = CHECK_DEFAULT_TOL
DEFAULT_ORIENTATIONS = CHECK_DEFAULT_ORIENTATIONS
#: per-effect route agreement (informational) is skipped for an effect whose rounding floor
#: (its torque against its gross contributions) exceeds this (it would only measure rounding)
NOISE_FLOOR = 1e-6
#: unit roundoff of double precision
EPS = float(np.finfo(np.float64).eps)
#: rounding floor of an evaluation = ROUNDING_FACTOR * (unit * cancellation + EPS), the
#: cancellation measured with :func:`contribution_sizes`; the largest error measured (double
#: against double-double, 154 bodies, fields of degree up to 8) is 5.3 in these units, 2.1
#: with fields of degree <= 4 (docs/check.md)
ROUNDING_FACTOR = 32.0
#: ``precision="auto"`` evaluates in double-double when a claimed quantity's double-precision
#: rounding floor exceeds this fraction of the tolerance
ACCURATE_FRACTION = 0.01
#: element-orientation pairs per vectorised block (its temporaries then stay in the L2 cache)
BLOCK_PAIRS = 1 << 13

#: quantity -> the design claim (``realises`` item) that makes it a pass/fail check
QUANTITY_CLAIMS = {
    "mu": "mu",
    "gyroscopic_torque": "mu",
    "V": "V",
    "potential_torque": "V",
    "inertia": "inertia",
}
EFFECTS = CHECK_EFFECTS


# --------------------------------------------------------------------------- results
@dataclass
class QuantityResult:
    """One compared quantity.

    Attributes
    ----------
    name : str
        ``mu``, ``gyroscopic_torque``, ``V``, ``potential_torque`` or ``inertia``.
    rel_err : float
        Largest error over the orientations divided by ``scale`` (see ``basis``).
    abs_err : float
        Largest absolute error (SI units of the quantity).
    scale : float
        The denominator: ``max |x_ref|`` over the orientations (V: the spread of x_ref), or
        the gross contributions when the reference is zero.
    worst_gamma : tuple of float or None
        The orientation of the largest error (None for the inertia).
    claimed : bool
        Whether the design claims it (then it is compared with the tolerance).
    passed : bool or None
        True for status ``pass``, False for ``fail`` and ``unverifiable``, None when not
        claimed (informational).
    status : str
        ``pass``, ``fail``, ``unverifiable`` (the rounding floor of the evaluation exceeds the
        tolerance and the error is not certainly beyond it) or ``info`` (not claimed).
    reason : str or None
        Why a claimed quantity did not pass (one line), else None.
    basis : str
        ``reference`` (rel_err relative to ``max |x_ref|``) or ``gross`` (the reference is
        zero: absolute error relative to the gross contributions).
    gross : float
        Largest (over the orientations) sum of the elements' absolute contributions.
    cancellation : float
        ``gross / max |x_ref|`` (inf for a zero reference): how many times larger the
        cancelling contributions are than the quantity.
    rounding_floor : float
        Attainable accuracy (same units as rel_err) of the evaluation that produced rel_err.
    double_rounding_floor : float
        Attainable accuracy of evaluating this body in double precision (the double kernel,
        ``chargedesign simulate``): ``ROUNDING_FACTOR * EPS * (cancellation + 1)``.
    precision : str
        Arithmetic of the evaluation: ``double`` or ``double-double``.
    """

    name: str
    rel_err: float
    abs_err: float
    scale: float
    worst_gamma: tuple[float, float, float] | None
    claimed: bool
    passed: bool | None
    status: str = "info"
    reason: str | None = None
    basis: str = "reference"
    gross: float = 0.0
    cancellation: float = 0.0
    rounding_floor: float = 0.0
    double_rounding_floor: float = 0.0
    precision: str = "double"

    def to_dict(self) -> dict[str, Any]:
        return {
            "rel_err": self.rel_err,
            "abs_err": self.abs_err,
            "scale": self.scale,
            "worst_gamma": None if self.worst_gamma is None else list(self.worst_gamma),
            "claimed": self.claimed,
            "passed": self.passed,
            "status": self.status,
            "reason": self.reason,
            "basis": self.basis,
            "gross": self.gross,
            # JSON has no infinity: a zero reference has no finite cancellation ratio
            "cancellation": self.cancellation if math.isfinite(self.cancellation) else None,
            "rounding_floor": self.rounding_floor,
            "double_rounding_floor": self.double_rounding_floor,
            "precision": self.precision,
        }


@dataclass
class EffectResult:
    """One physical effect: its size and the agreement of two routes within it.

    Attributes
    ----------
    name : str
        ``lorentz``, ``electric``, ``gravity``, ``magnetization`` or ``inertia``.
    source : str
        ``charges``, ``masses`` or ``dipoles``.
    n_elements : int
        Elements taking part (point elements plus quadrature nodes of continuous bodies).
    active : bool
        True when the effect has both elements and (where it needs one) a non-zero field.
    size : dict[str, float]
        Largest magnitudes over the orientations: ``mu``, ``gyroscopic_torque`` (lorentz);
        ``V_spread`` (max - min of the energy), ``torque`` (electric, gravity,
        magnetization); ``total_mass`` (inertia).
    route_rel_err : float or None
        Relative disagreement of two routes within the effect (informational), or None
        when not computed (inactive, too few orientations for the fit, or an effect whose
        torque cancels so far that its rounding floor exceeds ``NOISE_FLOOR``).
    worst_gamma : tuple of float or None
        Where ``route_rel_err`` occurs.
    """

    name: str
    source: str
    n_elements: int
    active: bool
    size: dict[str, float]
    route_rel_err: float | None = None
    worst_gamma: tuple[float, float, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "n_elements": self.n_elements,
            "active": self.active,
            "size": dict(self.size),
            "route_rel_err": self.route_rel_err,
            "worst_gamma": None if self.worst_gamma is None else list(self.worst_gamma),
        }


@dataclass(repr=False)
class CheckReport(Result):
    """Everything :func:`check_design` found.

    Attributes
    ----------
    tol : float
        Relative tolerance of the pass/fail decisions.
    n_orientations : int
        Orientations sampled.
    seed : int
        Seed of the random orientations, azimuths and angular velocities.
    claimed : list[str]
        The design's ``realises``.
    quantities : dict[str, QuantityResult]
        ``mu``, ``gyroscopic_torque``, ``V``, ``potential_torque``, ``inertia``.
    effects : dict[str, EffectResult]
        ``lorentz``, ``electric``, ``gravity``, ``magnetization``, ``inertia``.
    V_offset : float
        The additive constant of the design's V over the theorem's (mean difference), J.
    quadrature : list[dict]
        Per continuous body: kind, shape, degree of exactness used, nodes.
    n_pairs : int
        Element-orientation pairs evaluated.
    notes : list[str]
        Remarks (singular potential terms, nothing claimed, a body verified only in
        double-double, ...).
    precision : str
        Arithmetic of the compared sums: ``double`` or ``double-double``.
    """

    tol: float
    n_orientations: int
    seed: int
    claimed: list[str]
    quantities: dict[str, QuantityResult]
    effects: dict[str, EffectResult]
    V_offset: float
    quadrature: list[dict[str, Any]] = field(default_factory=list)
    n_pairs: int = 0
    notes: list[str] = field(default_factory=list)
    precision: str = "double"

    @property
    def passed(self) -> bool:
        """True when every claimed quantity is verified within the tolerance."""
        return all(q.passed is not False for q in self.quantities.values())

    @property
    def failures(self) -> list[str]:
        """Names of the claimed quantities that did not pass (``fail`` or ``unverifiable``)."""
        return [name for name, q in self.quantities.items() if q.passed is False]

    @property
    def unverifiable(self) -> list[str]:
        """Names of the claimed quantities whose rounding floor exceeds the tolerance."""
        return [name for name, q in self.quantities.items() if q.status == "unverifiable"]

    def to_dict(self) -> dict[str, Any]:
        """JSON mapping: the contract's keys first (``mu_rel_err``, ``V_rel_err``, ...)."""
        out: dict[str, Any] = {}
        for name in ("mu", "V", "inertia", "gyroscopic_torque", "potential_torque"):
            out[f"{name}_rel_err"] = self.quantities[name].rel_err
        out["passed"] = self.passed
        out["tol"] = self.tol
        out["failures"] = self.failures
        out["unverifiable"] = self.unverifiable
        out["reasons"] = {k: q.reason for k, q in self.quantities.items() if q.reason}
        out["precision"] = self.precision
        out["claimed"] = list(self.claimed)
        out["n_orientations"] = self.n_orientations
        out["seed"] = self.seed
        out["n_pairs"] = self.n_pairs
        out["V_offset"] = self.V_offset
        out["quantities"] = {k: v.to_dict() for k, v in self.quantities.items()}
        out["effects"] = {k: v.to_dict() for k, v in self.effects.items()}
        out["quadrature"] = list(self.quadrature)
        out["notes"] = list(self.notes)
        return out

    # result protocol (chargedesign.results): text, compact repr, notebook table
    def _summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {"passed": self.passed, "tol": self.tol}
        for name in ("mu", "V", "inertia"):
            q = self.quantities.get(name)
            if q is not None:
                out[f"{name}_rel_err"] = q.rel_err
        out["precision"] = self.precision
        out["n_orientations"] = self.n_orientations
        if self.failures:
            out["failures"] = list(self.failures)
        return out

    def _text(self) -> str:
        return "\n".join(summary_lines(self))

    def _html_rows(self) -> dict[str, Any]:
        rows = self._summary()
        for name, q in self.quantities.items():
            rows[name] = f"{q.status}: rel_err {q.rel_err:.3e} (floor {q.rounding_floor:.1e})"
        rows.update({f"note {i + 1}": n for i, n in enumerate(self.notes)})
        return rows


# ----------------------------------------------------------------------- orientations
def sample_orientations(n: int, seed: int = 0) -> np.ndarray:
    """A deterministic, well-spread set of unit vectors gamma.

    The first ``n - n // 2`` (rounded down to even) lie on a Fibonacci sphere
    ``z_i = 1 - (2 i + 1) / n_f`` (an even count never hits the equator gamma3 = 0 exactly,
    where the theorem's singular terms blow up); the rest are uniformly random (seeded).

    Returns
    -------
    ndarray, shape (n, 3)
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise input_error("n_orientations", "an integer >= 1", n)
    n = int(n)
    n_fib = n - n // 2
    n_fib -= n_fib % 2
    i = np.arange(n_fib)
    z = 1.0 - (2.0 * i + 1.0) / max(n_fib, 1)
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    s = np.sqrt(1.0 - z * z)
    fib = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
    rng = np.random.default_rng(seed)
    rand = rng.standard_normal((n - n_fib, 3))
    rand /= np.linalg.norm(rand, axis=1, keepdims=True)
    return np.concatenate([fib, rand], axis=0)


def rotation_matrices(gammas: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Rotations R (body to space) with ``R^T e_Z = gamma`` and a random azimuth.

    Rows of R are ``u``, ``gamma x u``, ``gamma`` with ``u`` a random unit vector
    perpendicular to gamma, so ``det R = +1``.

    Returns
    -------
    ndarray, shape (m, 3, 3)
    """
    m = len(gammas)
    trial = rng.standard_normal((m, 3))
    u = trial - np.einsum("ij,ij->i", trial, gammas)[:, None] * gammas
    norm = np.linalg.norm(u, axis=1)
    bad = norm < 1e-6  # vanishingly rare: fall back to a fixed perpendicular axis
    if np.any(bad):
        axis = np.where(np.abs(gammas[bad, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        u[bad] = axis - np.einsum("ij,ij->i", axis, gammas[bad])[:, None] * gammas[bad]
        norm[bad] = np.linalg.norm(u[bad], axis=1)
    u /= norm[:, None]
    # a second Gram-Schmidt pass: after the first, u . gamma is only eps * |trial| / |u|
    # (1e-14 when the trial is nearly parallel to gamma), and a rotation that far from
    # orthogonal shears the body by as much, which a cancelling body feels 50-fold
    u -= np.einsum("ij,ij->i", u, gammas)[:, None] * gammas
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    R = np.empty((m, 3, 3))
    R[:, 0] = u
    R[:, 1] = np.cross(gammas, u)
    R[:, 2] = gammas
    return R


# --------------------------------------------------------------------------- elements
@dataclass(kw_only=True)
class Elements(ElementSet):
    """Every element as a point in body axes (m): charges (C) and masses (kg) including the
    carriers' and magnets' masses and the quadrature nodes of continuous bodies, dipoles
    (A m^2); ``quadrature`` describes the continuous bodies' rules (kind, shape, order,
    nodes)."""

    quadrature: list[dict[str, Any]] = field(default_factory=list)


def _integrand_degree(kind: str, degrees: dict[str, int]) -> int:
    """Polynomial degree (in body coordinates) of every integrand the check uses."""
    if kind == "charge":
        # V and torque of E: Phi_e, r x grad Phi_e (degree L_e); mu and the Lorentz torque:
        # r (r . B), r x ((omega x r) x B) (degree L_m + 1, or 0 without a field).
        lorentz = degrees["magnetic"] + 1 if degrees["magnetic"] else 0
        return max(degrees["electric"], lorentz)
    return max(degrees["gravity"], 2)  # V, torque of gravity; inertia (degree 2)


def collect_elements(
    design: Design, quadrature_order: int | None = None
) -> tuple[Elements, dict[str, int]]:
    """Point elements plus continuous bodies as quadrature nodes (weights in C or kg).

    The degree of exactness of each body's rule is ``density degree + integrand degree``
    (exact for every polynomial integrand of the check) unless ``quadrature_order`` is given.
    Integrand degrees: charges ``max(L_e, L_m + 1)`` (``Phi_e``, ``r x grad Phi_e``;
    ``r (r . B)``, ``r x ((omega x r) x B)``), masses ``max(L_g, 2)`` (gravity; inertia),
    with ``L`` the degree of each field.

    Returns
    -------
    elements : Elements
    degrees : dict[str, int]
        Degree of each field kind (0: no field).
    """
    degrees = {k: AxisymmetricField(design.field(k)).degree for k in FIELD_NAMES}
    points = design.point_elements()
    cp, cv = [points.charge_positions], [points.charge_values]
    mp, mv = [points.mass_positions], [points.mass_values]
    info = []
    for i, raw in enumerate(design.continuous):
        body = ContinuousBody.coerce(raw, f"continuous[{i}]")
        order = (
            body.density.degree + _integrand_degree(body.kind, degrees)
            if quadrature_order is None
            else quadrature_order
        )
        pts, w = quadrature_points(body, order)
        (cp if body.kind == "charge" else mp).append(pts)
        (cv if body.kind == "charge" else mv).append(w)
        info.append({"kind": body.kind, "shape": body.shape, "order": order, "nodes": len(w)})
    elements = Elements(
        charge_positions=np.concatenate(cp),
        charge_values=np.concatenate(cv),
        mass_positions=np.concatenate(mp),
        mass_values=np.concatenate(mv),
        dipole_positions=points.dipole_positions,
        dipole_moments=points.dipole_moments,
        quadrature=info,
    )
    return elements, degrees


# ------------------------------------------------------------------------ the kernel
# The check evaluates the zonal harmonics u_k = R^k P_k(Z/R) with its own Cartesian
# recurrences (independent of chargedesign.fields, which differentiates in S = R^2):
#   (k + 1) u_{k+1} = (2k + 1) Z u_k - k S u_{k-1},        u_0 = 1, u_1 = Z
#   d u_k / dZ = k u_{k-1}                                 (at fixed X, Y)
#   d u_k / dX = -X v_{k-1},  v_{k+1} = S v_{k-1} + (2k + 1) u_k,   v_0 = 0, v_1 = 1
#   d v_k / dX = X t_k,       t_{k+1} = S t_{k-1} - (2k - 1) v_{k-1}, t_0 = t_1 = 0
# (v_k = R^(k-1) P_k'(Z/R)). So for Phi = sum f_k u_k, with transverse components X, Y:
#   grad Phi = (-X T, -Y T, D),  D = sum f_k k u_{k-1},  T = sum f_k v_{k-1}
#   Hess: XX = -(T + X^2 W), XY = -X Y W, XZ = -X E, ZZ = sum f_k k (k-1) u_{k-2}
#   with W = sum f_k t_{k-1}, E = sum f_k k v_{k-2} (and YY, YZ alike).
#
# Every temporary comes from a workspace of block-sized buffers that are reused from block
# to block: allocating and freeing them per block lets the C allocator hand the pages back
# to the system and fault them in again, which measured 3 to 5 times slower.


class _Workspace:
    """Reusable buffers of shape (rows, n); ``take`` hands out views of the first rows."""

    def __init__(self, rows: int, n: int) -> None:
        self.shape = (rows, n)
        self._free: list[np.ndarray] = []

    def take(self, rows: int) -> np.ndarray:
        base = self._free.pop() if self._free else np.empty(self.shape)
        return base[:rows]

    def give(self, *arrays: Any) -> None:
        """Return buffers (floats and repeats are ignored, so callers may over-give)."""
        for a in arrays:
            if isinstance(a, np.ndarray):
                base = a if a.base is None else a.base
                if base.shape == self.shape and not any(b is base for b in self._free):
                    self._free.append(base)


def _prodsum(ws: _Workspace, rows: int, terms: list[tuple[float, Any, Any]]) -> np.ndarray | float:
    """``sum_i c_i A_i B_i`` into a workspace buffer (a float when every factor is a float).

    Factors are floats, arrays of shape (rows, n), (n,) or (rows, 1) (broadcast).
    """
    out: np.ndarray | None = None
    tmp: np.ndarray | None = None
    const = 0.0
    for c, a, b in terms:
        a_scalar, b_scalar = isinstance(a, float), isinstance(b, float)
        if a_scalar and b_scalar:
            const += c * a * b
            continue
        if c == 0.0 or (a_scalar and a == 0.0) or (b_scalar and b == 0.0):
            continue
        if out is None:
            target = out = ws.take(rows)
        else:
            if tmp is None:
                tmp = ws.take(rows)
            target = tmp
        if a_scalar or b_scalar:
            arr, scale = (b, c * a) if a_scalar else (a, c * b)
            np.multiply(arr, scale, out=target)
        else:
            np.multiply(a, b, out=target)
            if c != 1.0:
                target *= c
        if target is not out:
            out += target
    ws.give(tmp)
    if out is None:
        return const
    if const != 0.0:
        out += const
    return out


@dataclass
class _Zonal:
    """Sums of one field at a block of points (workspace buffers or floats)."""

    value: Any = None
    D: Any = None
    T: Any = None
    W: Any = None
    E: Any = None
    ZZ: Any = None


def _zonal(
    coeffs: np.ndarray, Z: np.ndarray, S: np.ndarray, order: int, ws: _Workspace
) -> tuple[_Zonal, list[Any]]:
    """Potential (order 0), gradient sums (1) and Hessian sums (2) at points (Z, S = R^2).

    Parameters
    ----------
    coeffs : ndarray, shape (K,)
        Legendre coefficients f_1 .. f_K (trailing zeros removed).
    Z : ndarray, shape (rows, n)
        Axial space coordinate, m.
    S : ndarray, shape (n,)
        Squared distance from O, m^2 (rotation invariant).
    order : int
        Highest derivative wanted.
    ws : _Workspace
        Where the buffers come from.

    Returns
    -------
    The sums and the list of buffers to give back to ``ws`` when done.
    """
    rows = Z.shape[0]
    K = len(coeffs)
    f = [0.0, *(float(c) for c in coeffs)]  # f[k] = f_k
    u: list[Any] = [1.0, Z]
    for k in range(1, K):
        u.append(
            _prodsum(ws, rows, [((2 * k + 1) / (k + 1), Z, u[k]), (-k / (k + 1), S, u[k - 1])])
        )
    out = _Zonal()
    out.value = _prodsum(ws, rows, [(f[k], u[k], 1.0) for k in range(1, K + 1)])
    scratch: list[Any] = u[2:]
    if order >= 1:
        v: list[Any] = [0.0, 1.0]
        for k in range(1, K - 1):
            v.append(_prodsum(ws, rows, [(1.0, S, v[k - 1]), (2.0 * k + 1.0, u[k], 1.0)]))
        out.D = _prodsum(ws, rows, [(f[k] * k, u[k - 1], 1.0) for k in range(1, K + 1)])
        out.T = _prodsum(ws, rows, [(f[k], v[k - 1], 1.0) for k in range(1, K + 1)])
        scratch += v[2:]
    if order >= 2:
        t: list[Any] = [0.0, 0.0]
        for k in range(1, K - 1):
            t.append(_prodsum(ws, rows, [(1.0, S, t[k - 1]), (-(2.0 * k - 1.0), v[k - 1], 1.0)]))
        out.W = _prodsum(ws, rows, [(f[k], t[k - 1], 1.0) for k in range(1, K + 1)])
        out.E = _prodsum(ws, rows, [(f[k] * k, v[k - 2], 1.0) for k in range(2, K + 1)])
        out.ZZ = _prodsum(ws, rows, [(f[k] * k * (k - 1), u[k - 2], 1.0) for k in range(2, K + 1)])
        scratch += t[2:]
    ws.give(*scratch)
    return out, [out.value, out.D, out.T, out.W, out.E, out.ZZ]


def _rotate_points(
    R: np.ndarray, r: np.ndarray, buffer: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Space components ``X = R r`` of body points: three (m, n) views of ``buffer`` (one GEMM).

    ``buffer`` has shape (3 * rows_max, n).
    """
    m, n = len(R), len(r)
    XR = buffer[: 3 * m]
    np.matmul(R.reshape(3 * m, 3), r.T, out=XR)
    XR3 = XR.reshape(m, 3, n)
    return XR3[:, 0], XR3[:, 1], XR3[:, 2]


def _ein(a: Any, b: Any, w: np.ndarray | None = None) -> np.ndarray:
    """``sum_n a b (w)`` per row: shape (rows,) (no temporary)."""
    if w is None:
        return np.einsum("mn,mn->m", a, b)
    return np.einsum("mn,mn,n->m", a, b, w)


@dataclass
class RotatedSums:
    """Per-orientation sums over the elements (m rows), SI units.

    ``mu`` (kg m^2/s) and ``gyro`` (N m, Lorentz torque) from the charges; ``energy`` (J)
    and ``torque`` (N m) per potential effect (``electric``, ``gravity``,
    ``magnetization``); ``*_gross`` the per-orientation sums of the elements' absolute
    contributions (the scale of the per-effect route agreement's gate; the pass/fail floors
    use :func:`contribution_sizes`). Vectors are in space axes inside the kernel and in body
    axes once :func:`evaluate_rotated` returns.
    """

    mu: np.ndarray
    gyro: np.ndarray
    mu_gross: np.ndarray
    energy: dict[str, np.ndarray]
    energy_gross: dict[str, np.ndarray]
    torque: dict[str, np.ndarray]
    torque_gross: dict[str, np.ndarray]


POTENTIAL_EFFECTS = ("electric", "gravity", "magnetization")


def _new_sums(m: int) -> RotatedSums:
    return RotatedSums(
        mu=np.zeros((m, 3)),
        gyro=np.zeros((m, 3)),
        mu_gross=np.zeros(m),
        energy={k: np.zeros(m) for k in POTENTIAL_EFFECTS},
        energy_gross={k: np.zeros(m) for k in POTENTIAL_EFFECTS},
        torque={k: np.zeros((m, 3)) for k in POTENTIAL_EFFECTS},
        torque_gross={k: np.zeros(m) for k in POTENTIAL_EFFECTS},
    )


def _full(ws: _Workspace, rows: int, value: Any) -> np.ndarray:
    """A (rows, n) buffer holding ``value`` (used when a sum came out as a float)."""
    out = ws.take(rows)
    out[...] = value
    return out


def _scalar_potential_block(
    X: tuple[np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    w: np.ndarray,
    coeffs: np.ndarray,
    name: str,
    out: RotatedSums,
    rows: slice,
    absw: np.ndarray,
    absw_r: np.ndarray,
    ws: _Workspace,
) -> None:
    """Energy ``sum w Phi`` and torque ``sum X x (-w grad Phi)`` of charges or masses."""
    x, y, z = X
    m = x.shape[0]
    zs, bufs = _zonal(coeffs, z, S, 1, ws)
    value = zs.value if isinstance(zs.value, np.ndarray) else _full(ws, m, zs.value)
    out.energy[name][rows] = value @ w
    np.abs(value, out=value)
    out.energy_gross[name][rows] = value @ absw
    # grad Phi = (-x T, -y T, D): X x grad Phi = (y (D + z T), -x (D + z T), 0)
    lever = _prodsum(ws, m, [(1.0, zs.D, 1.0), (1.0, z, zs.T)])
    lever = lever if isinstance(lever, np.ndarray) else _full(ws, m, lever)
    out.torque[name][rows, 0] = -_ein(y, lever, w)
    out.torque[name][rows, 1] = _ein(x, lever, w)
    np.abs(lever, out=lever)
    out.torque_gross[name][rows] = lever @ absw_r
    ws.give(*bufs, lever, value)


def _lorentz_block(
    X: tuple[np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    q: np.ndarray,
    coeffs: np.ndarray,
    omega_space: np.ndarray,
    out: RotatedSums,
    rows: slice,
    absq_r: np.ndarray,
    ws: _Workspace,
) -> None:
    """mu = -sum q (X . B) X and the Lorentz torque sum X x q ((Omega x X) x B)."""
    x, y, z = X
    m = x.shape[0]
    zs, bufs = _zonal(coeffs, z, S, 1, ws)
    ps = _prodsum
    bx = ps(ws, m, [(1.0, x, zs.T)])  # B = -grad Phi = (x T, y T, -D)
    by = ps(ws, m, [(1.0, y, zs.T)])
    bz = ps(ws, m, [(-1.0, zs.D, 1.0)])
    bx, by, bz = (b if isinstance(b, np.ndarray) else _full(ws, m, b) for b in (bx, by, bz))
    xb = ps(ws, m, [(1.0, x, bx), (1.0, y, by), (1.0, z, bz)])
    assert isinstance(xb, np.ndarray)
    out.mu[rows, 0] = -_ein(x, xb, q)
    out.mu[rows, 1] = -_ein(y, xb, q)
    out.mu[rows, 2] = -_ein(z, xb, q)
    np.abs(xb, out=xb)
    out.mu_gross[rows] = xb @ absq_r
    ox, oy, oz = (omega_space[:, i, None] for i in range(3))
    vx = ps(ws, m, [(1.0, oy, z), (-1.0, oz, y)])
    vy = ps(ws, m, [(1.0, oz, x), (-1.0, ox, z)])
    vz = ps(ws, m, [(1.0, ox, y), (-1.0, oy, x)])
    fx = ps(ws, m, [(1.0, vy, bz), (-1.0, vz, by)])
    fy = ps(ws, m, [(1.0, vz, bx), (-1.0, vx, bz)])
    fz = ps(ws, m, [(1.0, vx, by), (-1.0, vy, bx)])
    out.gyro[rows, 0] = _ein(y, fz, q) - _ein(z, fy, q)
    out.gyro[rows, 1] = _ein(z, fx, q) - _ein(x, fz, q)
    out.gyro[rows, 2] = _ein(x, fy, q) - _ein(y, fx, q)
    ws.give(*bufs, bx, by, bz, xb, vx, vy, vz, fx, fy, fz)


def _dipoles_block(
    X: tuple[np.ndarray, np.ndarray, np.ndarray],
    sig: tuple[np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    coeffs: np.ndarray,
    out: RotatedSums,
    rows: slice,
    ws: _Workspace,
) -> None:
    """Energy ``-sum sigma . B`` and torque ``sum sigma x B + X x grad(sigma . B)``."""
    x, y, z = X
    sx, sy, sz = sig
    m = x.shape[0]
    zs, bufs = _zonal(coeffs, z, S, 2, ws)
    ps = _prodsum
    bx = ps(ws, m, [(1.0, x, zs.T)])
    by = ps(ws, m, [(1.0, y, zs.T)])
    bz = ps(ws, m, [(-1.0, zs.D, 1.0)])
    energy = ps(ws, m, [(-1.0, sx, bx), (-1.0, sy, by), (-1.0, sz, bz)])
    energy = energy if isinstance(energy, np.ndarray) else _full(ws, m, energy)
    out.energy["magnetization"][rows] = energy.sum(axis=1)
    np.abs(energy, out=energy)
    out.energy_gross["magnetization"][rows] = energy.sum(axis=1)
    # F = grad(sigma . B) = -H sigma with H the Hessian of Phi.
    xw = ps(ws, m, [(1.0, x, zs.W)])
    yw = ps(ws, m, [(1.0, y, zs.W)])
    hxx = ps(ws, m, [(-1.0, zs.T, 1.0), (-1.0, x, xw)])
    hyy = ps(ws, m, [(-1.0, zs.T, 1.0), (-1.0, y, yw)])
    hxy = ps(ws, m, [(-1.0, x, yw)])
    hxz = ps(ws, m, [(-1.0, x, zs.E)])
    hyz = ps(ws, m, [(-1.0, y, zs.E)])
    hzz = zs.ZZ
    fx = ps(ws, m, [(-1.0, hxx, sx), (-1.0, hxy, sy), (-1.0, hxz, sz)])
    fy = ps(ws, m, [(-1.0, hxy, sx), (-1.0, hyy, sy), (-1.0, hyz, sz)])
    fz = ps(ws, m, [(-1.0, hxz, sx), (-1.0, hyz, sy), (-1.0, hzz, sz)])
    tx = ps(ws, m, [(1.0, sy, bz), (-1.0, sz, by), (1.0, y, fz), (-1.0, z, fy)])
    ty = ps(ws, m, [(1.0, sz, bx), (-1.0, sx, bz), (1.0, z, fx), (-1.0, x, fz)])
    tz = ps(ws, m, [(1.0, sx, by), (-1.0, sy, bx), (1.0, x, fy), (-1.0, y, fx)])
    tx, ty, tz = (t if isinstance(t, np.ndarray) else _full(ws, m, t) for t in (tx, ty, tz))
    out.torque["magnetization"][rows, 0] = tx.sum(axis=1)
    out.torque["magnetization"][rows, 1] = ty.sum(axis=1)
    out.torque["magnetization"][rows, 2] = tz.sum(axis=1)
    norm = ps(ws, m, [(1.0, tx, tx), (1.0, ty, ty), (1.0, tz, tz)])
    assert isinstance(norm, np.ndarray)
    np.sqrt(norm, out=norm)
    out.torque_gross["magnetization"][rows] = norm.sum(axis=1)
    ws.give(*bufs, bx, by, bz, energy, xw, yw, hxx, hyy, hxy, hxz, hyz)
    ws.give(fx, fy, fz, tx, ty, tz, norm)


def _to_body(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R^T v`` per orientation: space vectors (m, 3) to body axes."""
    return np.einsum("mci,mc->mi", R, v)


def evaluate_rotated(
    elements: Elements,
    fields: dict[str, tuple[float, ...]],
    R: np.ndarray,
    omegas: np.ndarray,
    *,
    block_pairs: int = BLOCK_PAIRS,
) -> RotatedSums:
    """Rotated-body sums for every orientation, vectors rotated back to body axes.

    Parameters
    ----------
    elements : Elements
        Charges (C), masses (kg), dipoles (A m^2) in body axes (m).
    fields : dict[str, tuple of float]
        Legendre coefficients of ``magnetic``, ``electric``, ``gravity``.
    R : ndarray, shape (m, 3, 3)
        Body-to-space rotations.
    omegas : ndarray, shape (m, 3)
        Angular velocities in body axes, rad/s (for the Lorentz torque).
    block_pairs : int
        Element-orientation pairs per vectorised block.

    Returns
    -------
    RotatedSums
        Every vector in body axes.
    """
    m = len(R)
    sums = _new_sums(m)
    coeffs = {k: _trimmed(fields.get(k, ())) for k in FIELD_NAMES}
    omega_space = np.einsum("mij,mj->mi", R, omegas)

    def blocks(n: int) -> tuple[int, list[slice]]:
        step = max(1, min(m, block_pairs // max(n, 1)))
        return step, [slice(s, min(m, s + step)) for s in range(0, m, step)]

    r, q = elements.charge_positions, elements.charge_values
    if len(q) and (len(coeffs["magnetic"]) or len(coeffs["electric"])):
        S = np.einsum("ij,ij->i", r, r)
        absq = np.abs(q)
        absq_r = absq * np.sqrt(S)
        step, slices = blocks(len(q))
        ws = _Workspace(step, len(q))
        buffer = np.empty((3 * step, len(q)))
        for rows in slices:
            X = _rotate_points(R[rows], r, buffer)
            if len(coeffs["magnetic"]):
                _lorentz_block(
                    X, S, q, coeffs["magnetic"], omega_space[rows], sums, rows, absq_r, ws
                )
            if len(coeffs["electric"]):
                _scalar_potential_block(
                    X, S, q, coeffs["electric"], "electric", sums, rows, absq, absq_r, ws
                )
    r, w = elements.mass_positions, elements.mass_values
    if len(w) and len(coeffs["gravity"]):
        S = np.einsum("ij,ij->i", r, r)
        absw = np.abs(w)
        step, slices = blocks(len(w))
        ws = _Workspace(step, len(w))
        buffer = np.empty((3 * step, len(w)))
        for rows in slices:
            X = _rotate_points(R[rows], r, buffer)
            _scalar_potential_block(
                X, S, w, coeffs["gravity"], "gravity", sums, rows, absw, absw * np.sqrt(S), ws
            )
    r, sigma = elements.dipole_positions, elements.dipole_moments
    if len(sigma) and len(coeffs["magnetic"]):
        S = np.einsum("ij,ij->i", r, r)
        step, slices = blocks(len(sigma))
        ws = _Workspace(step, len(sigma))
        buffer = np.empty((3 * step, len(sigma)))
        sig_buffer = np.empty((3 * step, len(sigma)))
        for rows in slices:
            X = _rotate_points(R[rows], r, buffer)
            sig = _rotate_points(R[rows], sigma, sig_buffer)
            _dipoles_block(X, sig, S, coeffs["magnetic"], sums, rows, ws)
    sums.mu = _to_body(R, sums.mu)
    sums.gyro = _to_body(R, sums.gyro)
    for k in sums.torque:
        sums.torque[k] = _to_body(R, sums.torque[k])
    return sums


# ------------------------------------------------------------------ accurate evaluation
# Double-double numbers: an unevaluated sum hi + lo of two doubles, |lo| <= ulp(hi) / 2, about
# 106 bits (Dekker 1971; Hida, Li & Bailey's QD library for the add/multiply variants used).
# Products use Dekker's split (numpy has no fused multiply-add); every operation is a fixed
# sequence of numpy ufuncs, so it vectorises like the double kernel, some 20 to 40 times
# slower per pair (bench/check.py measures it).
_SPLITTER = 134217729.0  # 2^27 + 1
#: unit roundoff of the double-double operations used (a few times 2^-106; conservative)
DD_UNIT = 2.0**-104


def _split(a: Any) -> tuple[Any, Any]:
    t = _SPLITTER * a
    hi = t - (t - a)
    return hi, a - hi


def _two_prod(a: Any, b: Any) -> tuple[Any, Any]:
    """``a * b = p + e`` exactly (Dekker)."""
    p = a * b
    ah, al = _split(a)
    bh, bl = _split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """``a + b = s + e`` exactly (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _fast_two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """``a + b = s + e`` exactly when ``|a| >= |b|``."""
    s = a + b
    return s, b - (s - a)


class _DD:
    """Double-double array ``hi + lo`` (numpy broadcasting; operands: _DD, ndarray, float).

    A float or float64 array operand is taken as exact (it is an input of the check).
    """

    __slots__ = ("hi", "lo")
    __array_ufunc__ = None  # ndarray op _DD defers to _DD's reflected operators

    def __init__(self, hi: Any, lo: Any = None) -> None:
        self.hi = np.asarray(hi, dtype=np.float64)
        self.lo = np.zeros_like(self.hi) if lo is None else lo

    def __getitem__(self, index: Any) -> _DD:
        return _DD(self.hi[index], self.lo[index])

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.hi.shape)

    def __neg__(self) -> _DD:
        return _DD(-self.hi, -self.lo)

    def __add__(self, other: Any) -> _DD:
        if isinstance(other, _DD):
            s, e = _two_sum(self.hi, other.hi)
            t, f = _two_sum(self.lo, other.lo)
            s, e = _fast_two_sum(s, e + t)
            return _DD(*_fast_two_sum(s, e + f))
        s, e = _two_sum(self.hi, other)
        return _DD(*_fast_two_sum(s, e + self.lo))

    __radd__ = __add__

    def __sub__(self, other: Any) -> _DD:
        return self + (-other)

    def __rsub__(self, other: Any) -> _DD:
        return (-self) + other

    def __mul__(self, other: Any) -> _DD:
        if isinstance(other, _DD):
            p, e = _two_prod(self.hi, other.hi)
            return _DD(*_fast_two_sum(p, e + (self.hi * other.lo + self.lo * other.hi)))
        p, e = _two_prod(self.hi, other)
        return _DD(*_fast_two_sum(p, e + self.lo * other))

    __rmul__ = __mul__

    def __truediv__(self, other: float) -> _DD:
        """Division by a double (used for the recurrences' integer denominators)."""
        q1 = self.hi / other
        p, e = _two_prod(q1, other)
        s, f = _two_sum(self.hi, -p)
        q2 = (s + ((f - e) + self.lo)) / other
        return _DD(*_fast_two_sum(q1, q2))

    def sqrt(self) -> _DD:
        q = np.sqrt(self.hi)
        p, e = _two_prod(q, q)
        return _DD(*_fast_two_sum(q, (((self.hi - p) - e) + self.lo) / (2.0 * q)))

    def total(self, axis: int = -1) -> _DD:
        """Pairwise double-double sum along ``axis`` (the axis is removed)."""
        x = _DD(np.moveaxis(self.hi, axis, 0), np.moveaxis(self.lo, axis, 0))
        if x.hi.shape[0] == 0:
            return _DD(np.zeros(x.hi.shape[1:]))
        while x.hi.shape[0] > 1:
            half = x.hi.shape[0] // 2
            pair = x[:half] + x[half : 2 * half]
            if x.hi.shape[0] % 2:
                pair = _DD(
                    np.concatenate([pair.hi, x.hi[-1:]]), np.concatenate([pair.lo, x.lo[-1:]])
                )
            x = pair
        return x[0]

    def to_float(self) -> np.ndarray:
        return self.hi + self.lo


def _total(x: Any) -> Any:
    """Sum over the last axis (pairwise in both arithmetics)."""
    if isinstance(x, _DD):
        return x.total(-1)
    return np.sum(x, axis=-1)


def _as_float(x: Any) -> np.ndarray:
    return x.to_float() if isinstance(x, _DD) else np.asarray(x, dtype=np.float64)


@dataclass
class _Harmonics:
    """value, gradient sums (D, T) and Hessian sums (W, E, ZZ) of one field (see the kernel
    notes above), in the accurate arithmetic; floats where a sum has no element term."""

    value: Any
    D: Any
    T: Any
    W: Any = 0.0
    E: Any = 0.0
    ZZ: Any = 0.0


def _harmonics_accurate(
    coeffs: np.ndarray, Z: Any, S: Any, order: int, lift: Callable[[Any], Any]
) -> _Harmonics:
    """The recurrences of the kernel notes in the accurate arithmetic (integer factors exact:
    every ``(2k + 1) / (k + 1)`` is a multiplication and a division, not a rounded ratio)."""
    K = len(coeffs)
    f = [lift(0.0), *(lift(float(c)) for c in coeffs)]
    u: list[Any] = [1.0, Z]
    for k in range(1, K):
        u.append(((2 * k + 1) * (Z * u[k]) - k * (S * u[k - 1])) / float(k + 1))
    value: Any = 0.0
    D: Any = 0.0
    T: Any = 0.0
    v: list[Any] = [0.0, 1.0]
    for k in range(1, K - 1):
        v.append(S * v[k - 1] + (2 * k + 1) * u[k])
    for k in range(1, K + 1):
        if coeffs[k - 1] == 0.0:
            continue
        value = value + f[k] * u[k]
        D = D + (f[k] * k) * u[k - 1]
        T = T + f[k] * v[k - 1]
    out = _Harmonics(value, D, T)
    if order >= 2:
        t: list[Any] = [0.0, 0.0]
        for k in range(1, K - 1):
            t.append(S * t[k - 1] - (2 * k - 1) * v[k - 1])
        for k in range(1, K + 1):
            if coeffs[k - 1] == 0.0:
                continue
            out.W = out.W + f[k] * t[k - 1]
            if k >= 2:
                out.E = out.E + (f[k] * k) * v[k - 2]
                out.ZZ = out.ZZ + (f[k] * (k * (k - 1))) * u[k - 2]
    return out


@dataclass
class AccurateSums:
    """Per-orientation sums of :func:`evaluate_accurate` (body axes, SI units), each
    correctly rounded to double from the accurate arithmetic.

    ``energy_centered`` is the total energy minus its mean over the orientations, both
    formed in the accurate arithmetic (an orientation-independent part of the energy, however
    large, then costs no accuracy); ``energy_mean`` is that mean (J).
    """

    mu: np.ndarray
    gyro: np.ndarray
    energy: dict[str, np.ndarray]
    energy_centered: np.ndarray
    energy_mean: float
    torque: dict[str, np.ndarray]
    precision: str


def _cross_float(a: tuple[Any, Any, Any], b: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def evaluate_accurate(
    elements: Elements,
    fields: dict[str, tuple[float, ...]],
    gammas: np.ndarray,
    omegas: np.ndarray,
    *,
    precision: str = "double-double",
    block_pairs: int = BLOCK_PAIRS,
) -> AccurateSums:
    """mu, the Lorentz torque, the energies and the torques in extended precision.

    The same quantities as :func:`evaluate_rotated`, from the same recurrences, evaluated
    in body axes (``Z = gamma . r``, transverse part ``t = r - Z gamma``, ``grad Phi =
    -T t + D gamma``) in double-double arithmetic (about 32 digits) or ``np.longdouble``
    (``precision="longdouble"``; 19 digits on x86-64). The inputs (positions, weights, field
    coefficients, gamma, omega) are exact doubles; gamma is normalised in the accurate
    arithmetic, so the harmonics are harmonic to its precision (a double gamma is unit only
    to 1e-16, which a body whose contributions cancel would otherwise feel).

    Parameters
    ----------
    elements : Elements
    fields : dict[str, tuple of float]
    gammas : ndarray, shape (m, 3)
        Near-unit vectors (|gamma| = 1 to 1e-12).
    omegas : ndarray, shape (m, 3)
        Angular velocities in body axes, rad/s.
    precision : str
        ``double-double`` or ``longdouble``.
    block_pairs : int
        Element-orientation pairs per vectorised block.

    Returns
    -------
    AccurateSums
    """
    if precision == "double-double":

        def lift(x: Any) -> Any:
            return _DD(x)
    elif precision == "longdouble":

        def lift(x: Any) -> Any:
            return np.asarray(x, dtype=np.longdouble)
    else:
        raise input_error("precision", "'double-double' or 'longdouble'", precision)
    gammas = np.asarray(gammas, dtype=np.float64)
    if np.abs(np.einsum("ij,ij->i", gammas, gammas) - 1.0).max(initial=0.0) > 1e-12:
        raise input_error("gammas", "unit vectors (to 1e-12)", gammas)
    m = len(gammas)
    coeffs = {k: _trimmed(fields.get(k, ())) for k in FIELD_NAMES}
    mu = [lift(np.zeros(m)) for _ in range(3)]
    gyro = [lift(np.zeros(m)) for _ in range(3)]
    energy = {k: lift(np.zeros(m)) for k in POTENTIAL_EFFECTS}
    torque = {k: [lift(np.zeros(m)) for _ in range(3)] for k in POTENTIAL_EFFECTS}

    def unit_gammas(rows: slice) -> tuple[Any, Any, Any]:
        # 1 / |g| = 1 - delta / 2 + 3 delta^2 / 8 + O(delta^3), delta = |g|^2 - 1 ~ 1e-16
        g = [lift(gammas[rows, i]) for i in range(3)]
        delta = g[0] * gammas[rows, 0] + g[1] * gammas[rows, 1] + g[2] * gammas[rows, 2] - 1.0
        scale = 1.0 - delta * 0.5 + (delta * delta) * 0.375
        return g[0] * scale, g[1] * scale, g[2] * scale

    def add_rows(target: Any, rows: slice, value: Any) -> None:
        if isinstance(target, _DD):
            block = target[rows] + value
            target.hi[rows], target.lo[rows] = block.hi, block.lo
        else:
            target[rows] = target[rows] + value

    def geometry(r: np.ndarray, rows: slice) -> tuple[Any, ...]:
        g = unit_gammas(rows)
        gc = tuple(gi[:, None] for gi in g)
        x, y, z = r[:, 0], r[:, 1], r[:, 2]
        Z = gc[0] * x + gc[1] * y + gc[2] * z
        S = lift(x) * x + lift(y) * y + lift(z) * z
        t = (x - Z * gc[0], y - Z * gc[1], z - Z * gc[2])
        return gc, (x, y, z), Z, S, t

    def blocks(n: int) -> list[slice]:
        step = max(1, min(m, block_pairs // max(n, 1)))
        return [slice(s, min(m, s + step)) for s in range(0, m, step)]

    def potential_effect(name: str, r: np.ndarray, w: np.ndarray, c: np.ndarray) -> None:
        for rows in blocks(len(w)):
            gc, xyz, Z, S, _ = geometry(r, rows)
            h = _harmonics_accurate(c, Z, S, 1, lift)
            add_rows(energy[name], rows, _total(h.value * w))
            # X x (-w grad Phi) = -w (D + Z T) (r x gamma)
            lever = (h.D + Z * h.T) * (-w)
            for i, arm in enumerate(_cross_float(xyz, gc)):
                add_rows(torque[name][i], rows, _total(lever * arm))

    r, q = elements.charge_positions, elements.charge_values
    if len(q) and len(coeffs["magnetic"]):
        for rows in blocks(len(q)):
            gc, xyz, Z, S, t = geometry(r, rows)
            h = _harmonics_accurate(coeffs["magnetic"], Z, S, 1, lift)
            B = tuple(t[i] * h.T - h.D * gc[i] for i in range(3))
            qrB = (B[0] * xyz[0] + B[1] * xyz[1] + B[2] * xyz[2]) * q
            for i in range(3):
                add_rows(mu[i], rows, -_total(qrB * xyz[i]))
            om = tuple(lift(omegas[rows, i])[:, None] for i in range(3))
            v = _cross_float(om, xyz)  # omega x r
            force = tuple(fi * q for fi in _cross_float(v, B))  # q v x B
            for i, ti in enumerate(_cross_float(xyz, force)):
                add_rows(gyro[i], rows, _total(ti))
    if len(q) and len(coeffs["electric"]):
        potential_effect("electric", r, q, coeffs["electric"])
    r, w = elements.mass_positions, elements.mass_values
    if len(w) and len(coeffs["gravity"]):
        potential_effect("gravity", r, w, coeffs["gravity"])
    r, sigma = elements.dipole_positions, elements.dipole_moments
    if len(sigma) and len(coeffs["magnetic"]):
        s = (sigma[:, 0], sigma[:, 1], sigma[:, 2])
        for rows in blocks(len(sigma)):
            gc, xyz, Z, S, t = geometry(r, rows)
            h = _harmonics_accurate(coeffs["magnetic"], Z, S, 2, lift)
            B = tuple(t[i] * h.T - h.D * gc[i] for i in range(3))
            add_rows(
                energy["magnetization"], rows, -_total(B[0] * s[0] + B[1] * s[1] + B[2] * s[2])
            )
            sg = gc[0] * s[0] + gc[1] * s[1] + gc[2] * s[2]
            st = t[0] * s[0] + t[1] * s[1] + t[2] * s[2]
            # F = grad(sigma . B) = -H sigma,
            # H = -T (1 - g g^T) - W t t^T - E (t g^T + g t^T) + ZZ g g^T
            force = tuple(
                h.T * (s[i] - gc[i] * sg)
                + h.W * (t[i] * st)
                + h.E * (t[i] * sg + gc[i] * st)
                - h.ZZ * (gc[i] * sg)
                for i in range(3)
            )
            spin = _cross_float(s, B)
            lever = _cross_float(xyz, force)
            for i in range(3):
                add_rows(torque["magnetization"][i], rows, _total(spin[i] + lever[i]))
    total = energy["electric"] + energy["gravity"] + energy["magnetization"]
    mean = _total(total) / float(m) if isinstance(total, _DD) else np.mean(total)
    return AccurateSums(
        mu=np.stack([_as_float(c) for c in mu], axis=1),
        gyro=np.stack([_as_float(c) for c in gyro], axis=1),
        energy={k: _as_float(v) for k, v in energy.items()},
        energy_centered=_as_float(total - mean),
        energy_mean=float(_as_float(mean)),
        torque={k: np.stack([_as_float(c) for c in v], axis=1) for k, v in torque.items()},
        precision=precision,
    )


def _trimmed(legendre: tuple[float, ...]) -> np.ndarray:
    """Coefficients up to the last non-zero one (validated by AxisymmetricField)."""
    field_ = AxisymmetricField(legendre)
    return np.asarray(field_.legendre[: field_.degree], dtype=np.float64)


# ------------------------------------------------------------------------ comparisons
def _worst(gammas: np.ndarray, err: np.ndarray) -> tuple[float, float, float]:
    i = int(np.argmax(err))
    return (float(gammas[i, 0]), float(gammas[i, 1]), float(gammas[i, 2]))


def _norms(a: np.ndarray) -> np.ndarray:
    """|a| per orientation: absolute values (m,) or Euclidean norms of rows (m, 3)."""
    return np.abs(a) if a.ndim == 1 else np.linalg.norm(a, axis=1)


def _relative(
    x: np.ndarray, ref: np.ndarray, gross: float, gammas: np.ndarray
) -> tuple[float, float, float, str, tuple[float, float, float]]:
    """(rel_err, abs_err, scale, basis, worst gamma) of per-orientation vectors or scalars.

    The scale is ``max |ref|`` (basis ``reference``); for a reference that is zero at every
    orientation, the gross contributions (basis ``gross``: absolute error relative to the
    size of the terms that had to cancel to zero).
    """
    err = _norms(x - ref)
    abs_err = float(err.max(initial=0.0))
    scale = float(_norms(ref).max(initial=0.0))
    basis = "reference"
    if scale == 0.0:
        basis, scale = "gross", gross
    if scale > 0.0:
        rel = abs_err / scale
    else:  # no reference and no contributions: nothing to compare
        rel = 0.0 if abs_err == 0.0 else math.inf
    return rel, abs_err, scale, basis, _worst(gammas, err)


def _field_bounds(coeffs: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, ...]:
    """Bounds at distance r from O of |Phi|, |grad Phi| and |Hessian Phi| of a field.

    ``sum |f_k| r^k``, ``sum k |f_k| r^(k-1)``, ``sum k (k - 1) |f_k| r^(k-2)``: the sizes
    of the terms an element's evaluation adds up (the field may be far smaller there).

    Returns
    -------
    three ndarrays, shape (n,)
    """
    value, grad, hess = (np.zeros(len(radii)) for _ in range(3))
    for k, f in enumerate(np.abs(np.asarray(coeffs, dtype=float)), start=1):
        if f == 0.0:
            continue
        value += f * radii**k
        grad += k * f * radii ** (k - 1)
        if k >= 2:
            hess += k * (k - 1) * f * radii ** (k - 2)
    return value, grad, hess


def contribution_sizes(
    elements: Elements, fields: Mapping[str, Sequence[float]]
) -> dict[str, float]:
    """Sum over the elements of the size of their contributions to each compared quantity.

    The size of one contribution is its bound through every field term (:func:`_field_bounds`):
    ``|q| r^2 |grad Phi_m|`` for mu (and the Lorentz torque per unit |omega|), ``|q| |Phi_e| +
    m |Phi_g| + |sigma| |grad Phi_m|`` for V, ``|q| r |grad Phi_e| + m r |grad Phi_g| +
    |sigma| (|grad Phi_m| + r |Hess Phi_m|)`` for the potential torque. It is what a
    floating-point evaluation of each element rounds against, whatever the orientation, so
    ``size / max |x_ref|`` is the cancellation that sets the rounding floor.

    Returns
    -------
    dict with ``mu`` (kg m^2/s), ``gyroscopic_torque`` (per rad/s, N m s), ``V`` (J),
    ``potential_torque`` (N m).
    """
    coeffs = {k: _trimmed(tuple(fields.get(k, ()))) for k in FIELD_NAMES}
    rq = np.linalg.norm(elements.charge_positions, axis=1)
    rm = np.linalg.norm(elements.mass_positions, axis=1)
    rd = np.linalg.norm(elements.dipole_positions, axis=1)
    q = np.abs(elements.charge_values)
    m = np.abs(elements.mass_values)
    s = np.linalg.norm(elements.dipole_moments, axis=1)
    _, grad_mq, _ = _field_bounds(coeffs["magnetic"], rq)
    value_e, grad_e, _ = _field_bounds(coeffs["electric"], rq)
    value_g, grad_g, _ = _field_bounds(coeffs["gravity"], rm)
    _, grad_md, hess_md = _field_bounds(coeffs["magnetic"], rd)
    mu = float(q @ (rq**2 * grad_mq))
    return {
        "mu": mu,
        "gyroscopic_torque": mu,
        "V": float(q @ value_e + m @ value_g + s @ grad_md),
        "potential_torque": float(
            q @ (rq * grad_e) + m @ (rm * grad_g) + s @ (grad_md + rd * hess_md)
        ),
    }


def _cancellation(gross: float, ref_scale: float) -> float:
    """``gross / max |x_ref|``: inf for a zero reference, 0 without contributions."""
    if ref_scale > 0.0:
        return gross / ref_scale
    return math.inf if gross > 0.0 else 0.0


def rounding_floor(cancellation: float, unit: float, basis: str = "reference") -> float:
    """Attainable relative accuracy of a sum whose contributions cancel ``cancellation``-fold.

    ``ROUNDING_FACTOR * (unit * cancellation + EPS)``: each element's contribution is
    evaluated with a relative error of a few ``unit`` (the rotation, the recurrences, the
    products), so the sum is uncertain by a few ``unit * gross``; the result is finally
    rounded to double (``EPS``). With basis ``gross`` (a zero reference, rel_err measured
    against the gross) it is ``ROUNDING_FACTOR * unit``. ``unit``: :data:`EPS` for double,
    :data:`DD_UNIT` for double-double.
    """
    if basis == "gross":
        return ROUNDING_FACTOR * unit
    return ROUNDING_FACTOR * (unit * cancellation + EPS)


def _verdict(
    rel: float, floor: float, tol: float, cancellation: float, basis: str, precision: str
) -> tuple[str, str | None]:
    """(status, reason) of a claimed quantity.

    ``fail`` when the error is beyond the tolerance by more than the rounding floor (certainly
    wrong), ``unverifiable`` when the floor itself exceeds the tolerance (the evaluation cannot
    tell), ``pass`` when within the tolerance, ``fail`` otherwise.
    """
    if not rel <= tol + floor:  # also catches an infinite error
        return "fail", f"error {rel:.2e} exceeds tol {tol:g} (rounding floor {floor:.1e})"
    if floor > tol:
        if basis == "gross":
            size = "the reference is zero and the gross contributions round"
        else:
            size = f"contributions cancel to 1 part in {cancellation:.2g}"
        return "unverifiable", (
            f"cannot be verified at tol {tol:g}: {size} (rounding floor {floor:.1e} in "
            f"{precision}; error seen {rel:.1e})"
        )
    if rel <= tol:
        return "pass", None
    return "fail", f"error {rel:.2e} exceeds tol {tol:g} (rounding floor {floor:.1e})"


def _fitted_torque(gammas: np.ndarray, energy: np.ndarray, degree: int) -> np.ndarray | None:
    """``gamma x grad p`` of the least-squares polynomial p (degree <= ``degree``) of energy.

    The fit uses an evenly strided subset of the orientations (four per monomial: the
    polynomial is determined by any well-spread sample); the torque is evaluated at all.
    Returns None when there are too few orientations for a well-determined fit.
    """
    keys = [k for order in range(degree + 1) for k in moment_keys(order)]
    if len(gammas) < 2 * len(keys):
        return None
    subset = np.unique(np.linspace(0, len(gammas) - 1, 4 * len(keys)).astype(int))
    basis = monomial_matrix(gammas[subset], keys).T
    # the monomials are dependent on the sphere (|gamma| = 1): lstsq returns the minimum-norm
    # fit, whose tangential gradient (all the torque uses) is unique.
    coef, *_ = np.linalg.lstsq(basis, energy[subset], rcond=None)
    grad = np.zeros_like(gammas)
    for axis in range(3):
        lowered, factors = [], []
        for c, key in zip(coef, keys, strict=True):
            exps = list(parse_moment_key(key))
            if exps[axis]:
                factors.append(c * exps[axis])
                exps[axis] -= 1
                lowered.append("x" * exps[0] + "y" * exps[1] + "z" * exps[2])
        if lowered:
            grad[:, axis] = np.asarray(factors) @ monomial_matrix(gammas, lowered)
    return np.cross(gammas, grad)


def _theorem(params: Any, gammas: np.ndarray) -> dict[str, np.ndarray]:
    from chargedesign.model import evaluators

    ref = {
        "mu": np.asarray(evaluators.gyroscopic(gammas, params), dtype=float),
        "V": np.asarray(evaluators.potential(gammas, params), dtype=float),
        "dV": np.asarray(evaluators.potential_gradient(gammas, params), dtype=float),
    }
    for name, value in ref.items():
        if not np.all(np.isfinite(value)):
            raise SolverError(f"theorem: {name} is not finite at some sampled orientation")
    return ref


def check_design(
    design: Design,
    *,
    n_orientations: int = DEFAULT_ORIENTATIONS,
    tol: float = DEFAULT_TOL,
    seed: int = 0,
    quadrature_order: int | None = None,
    block_pairs: int = BLOCK_PAIRS,
    precision: str = "auto",
) -> CheckReport:
    """Recompute mu, V, the torques and the inertia of a design and compare with the theorem.

    Parameters
    ----------
    design : Design
        Point charges (C), masses (kg), dipoles (A m^2) and continuous bodies in body axes.
    n_orientations : int
        Orientations gamma sampled (half Fibonacci sphere, half random).
    tol : float
        Relative tolerance (> 0) for the quantities the design claims (``realises``).
    seed : int
        Seed of the random orientations, azimuths and angular velocities (rad/s, unit-normal
        components).
    quadrature_order : int, optional
        Degree of exactness of the continuous bodies' rules; default: exact for the check.
    block_pairs : int
        Element-orientation pairs per vectorised block (memory vs speed).
    precision : str
        ``auto`` (default): double precision, and double-double where a claimed quantity's
        contributions cancel so far that double rounding could decide it (its double
        rounding floor above ``ACCURATE_FRACTION * tol``); ``double`` or ``double-double``
        to force one.

    Returns
    -------
    CheckReport
        A claimed quantity passes when its error is within ``tol``; it is ``unverifiable``
        (and fails) when the rounding floor of the evaluation exceeds ``tol``.
    """
    if not isinstance(design, Design):
        raise input_error("design", "a Design", design)
    tol = as_finite_float(tol, "tol", positive=True)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise input_error("seed", "an integer >= 0", seed)
    if quadrature_order is not None and (
        isinstance(quadrature_order, bool)
        or not isinstance(quadrature_order, (int, np.integer))
        or quadrature_order < 0
    ):
        raise input_error("quadrature_order", "an integer >= 0 or None", quadrature_order)
    if isinstance(block_pairs, bool) or not isinstance(block_pairs, (int, np.integer)):
        raise input_error("block_pairs", "an integer >= 1", block_pairs)
    if block_pairs < 1:
        raise input_error("block_pairs", "an integer >= 1", block_pairs)
    if precision not in PRECISIONS:
        raise input_error("precision", "one of " + ", ".join(PRECISIONS), precision)
    gammas = sample_orientations(n_orientations, seed)
    rng = np.random.default_rng([int(seed), 1])
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((len(gammas), 3))
    elements, degrees = collect_elements(design, quadrature_order)
    fields = {k: design.field(k) for k in FIELD_NAMES}
    sums = evaluate_rotated(elements, fields, R, omegas, block_pairs=block_pairs)
    params = design.parameters
    ref = _theorem(params, gammas)
    claimed = set(design.realises)
    notes: list[str] = []

    for name, arr in [("mu", sums.mu), ("gyroscopic torque", sums.gyro)]:
        if not np.all(np.isfinite(arr)):
            raise SolverError(f"check: the design's {name} is not finite (overflow?)")
    omega_norm = np.linalg.norm(omegas, axis=1)
    refs = {
        "mu": ref["mu"],
        "gyroscopic_torque": np.cross(ref["mu"], omegas),
        "V": ref["V"] - ref["V"].mean(),  # V is defined up to a constant
        "potential_torque": np.cross(gammas, ref["dV"]),
    }
    sizes = contribution_sizes(elements, fields)
    gross = dict(sizes)
    gross["gyroscopic_torque"] = sizes["gyroscopic_torque"] * float(omega_norm.max(initial=0.0))
    ref_scale = {k: float(_norms(v).max(initial=0.0)) for k, v in refs.items()}
    cancellation = {k: _cancellation(gross[k], ref_scale[k]) for k in refs}
    basis = {k: "reference" if ref_scale[k] > 0.0 else "gross" for k in refs}
    double_floor = {k: rounding_floor(cancellation[k], EPS, basis[k]) for k in refs}
    if precision == "auto":
        # double-double only where double rounding could decide a claimed quantity
        accurate = any(
            QUANTITY_CLAIMS[k] in claimed and double_floor[k] > ACCURATE_FRACTION * tol
            for k in refs
        )
    else:
        accurate = precision == "double-double"
    used = sums
    if accurate:
        acc = evaluate_accurate(elements, fields, gammas, omegas, block_pairs=block_pairs)
        used = RotatedSums(
            mu=acc.mu,
            gyro=acc.gyro,
            mu_gross=sums.mu_gross,
            energy=acc.energy,
            energy_gross=sums.energy_gross,
            torque=acc.torque,
            torque_gross=sums.torque_gross,
        )
        energy_centered, energy_mean = acc.energy_centered, acc.energy_mean
    else:
        energy = np.sum(list(sums.energy.values()), axis=0)
        energy_mean = float(energy.mean())
        energy_centered = energy - energy_mean
    used_precision = "double-double" if accurate else "double"
    unit = DD_UNIT if accurate else EPS
    values = {
        "mu": used.mu,
        "gyroscopic_torque": used.gyro,
        "V": energy_centered,
        "potential_torque": np.sum(list(used.torque.values()), axis=0),
    }
    for name, value in values.items():
        if not np.all(np.isfinite(value)):
            raise SolverError(
                f"check: the design's {name} is not finite in {used_precision} (overflow?)"
            )

    quantities: dict[str, QuantityResult] = {}

    def record(
        name: str,
        compared: tuple[float, float, float, str, Any],
        gross_size: float,
        cancel: float,
        floors: tuple[float, float],
        arithmetic: str,
    ) -> None:
        rel, abs_err, scale, basis, worst = compared
        is_claimed = QUANTITY_CLAIMS[name] in claimed
        status, reason = (
            _verdict(rel, floors[0], tol, cancel, basis, arithmetic)
            if is_claimed
            else ("info", None)
        )
        quantities[name] = QuantityResult(
            name=name,
            rel_err=rel,
            abs_err=abs_err,
            scale=scale,
            worst_gamma=worst,
            claimed=is_claimed,
            passed=None if status == "info" else status == "pass",
            status=status,
            reason=reason,
            basis=basis,
            gross=gross_size,
            cancellation=cancel,
            rounding_floor=floors[0],
            double_rounding_floor=floors[1],
            precision=arithmetic,
        )

    for name in ("mu", "gyroscopic_torque", "V", "potential_torque"):
        compared = _relative(values[name], refs[name], gross[name], gammas)
        floors = (rounding_floor(cancellation[name], unit, basis[name]), double_floor[name])
        record(name, compared, gross[name], cancellation[name], floors, used_precision)
        if (
            accurate
            and quantities[name].claimed
            and floors[1] > tol
            and quantities[name].status == "pass"
        ):
            notes.append(
                f"{name}: verified in double-double; its contributions cancel to 1 part in "
                f"{cancellation[name]:.2g}, so any double-precision evaluation of this body "
                f"(e.g. chargedesign simulate) has a rounding floor of ~{floors[1]:.0e}"
            )

    inertia, inertia_gross = _inertia_accurate(elements.mass_positions, elements.mass_values)
    inertia_ref = np.diag([2.0 * params.C, 2.0 * params.C, params.C])
    inertia_abs = float(np.abs(inertia - inertia_ref).max())
    inertia_cancel = inertia_gross / (2.0 * params.C)
    record(
        "inertia",
        (inertia_abs / (2.0 * params.C), inertia_abs, 2.0 * params.C, "reference", None),
        inertia_gross,
        inertia_cancel,
        (rounding_floor(inertia_cancel, DD_UNIT), rounding_floor(inertia_cancel, EPS)),
        "double-double",
    )

    effects = _effects(elements, degrees, gammas, omegas, used, inertia, unit)
    if params.singular:
        notes.append(
            "lambda/rho terms of V are singular on gamma3 = 0: charges, masses and dipoles "
            "cannot realise them"
        )
    if not claimed:
        notes.append("the design claims nothing (realises is empty): all results informational")
    n_pairs = len(gammas) * (
        len(elements.charge_values) + len(elements.mass_values) + len(elements.dipole_moments)
    )
    return CheckReport(
        tol=tol,
        n_orientations=len(gammas),
        seed=int(seed),
        claimed=list(design.realises),
        quantities=quantities,
        effects=effects,
        V_offset=energy_mean - float(ref["V"].mean()),
        quadrature=elements.quadrature,
        n_pairs=n_pairs,
        notes=notes,
        precision=used_precision,
    )


def _inertia_accurate(positions: np.ndarray, masses: np.ndarray) -> tuple[np.ndarray, float]:
    """``sum m (|r|^2 1 - r r^T)`` summed in double-double, and ``sum m |r|^2`` (kg m^2)."""
    r = [positions[:, i] for i in range(3)]
    out = np.zeros((3, 3))
    for i in range(3):
        for j in range(i, 3):
            if i == j:
                a, b = r[(i + 1) % 3], r[(i + 2) % 3]
                entry = (_DD(masses) * a) * a + (_DD(masses) * b) * b
            else:
                entry = -((_DD(masses) * r[i]) * r[j])
            out[i, j] = out[j, i] = float(entry.total(-1).to_float())
    gross = float(np.abs(masses) @ np.einsum("ij,ij->i", positions, positions))
    return out, gross


def _effects(
    elements: Elements,
    degrees: dict[str, int],
    gammas: np.ndarray,
    omegas: np.ndarray,
    sums: RotatedSums,
    inertia: np.ndarray,
    unit: float,
) -> dict[str, EffectResult]:
    """Per-effect sizes and route agreement; ``unit``: unit roundoff of the sums (the route
    agreement is skipped where the effect cancels so far that rounding would dominate it)."""

    def resolved(size: float, gross: float) -> bool:
        return size > 0.0 and rounding_floor(gross / size, unit) <= NOISE_FLOOR

    counts = {
        "charges": len(elements.charge_values),
        "masses": len(elements.mass_values),
        "dipoles": len(elements.dipole_moments),
    }
    out: dict[str, EffectResult] = {}
    # Lorentz: the force route (sum r x q (v x B)) against the design's own mu x omega.
    active = counts["charges"] > 0 and degrees["magnetic"] > 0
    size = {
        "mu": float(np.linalg.norm(sums.mu, axis=1).max(initial=0.0)),
        "gyroscopic_torque": float(np.linalg.norm(sums.gyro, axis=1).max(initial=0.0)),
    }
    route: float | None = None
    worst = None
    gross = float((sums.mu_gross * np.linalg.norm(omegas, axis=1)).max(initial=0.0))
    if active and resolved(size["gyroscopic_torque"], gross):
        route, _, _, _, worst = _relative(sums.gyro, np.cross(sums.mu, omegas), gross, gammas)
    out["lorentz"] = EffectResult(
        "lorentz", "charges", counts["charges"], active, size, route, worst
    )
    for name in ("electric", "gravity", "magnetization"):
        source, field_name = EFFECTS[name]
        assert field_name is not None
        active = counts[source] > 0 and degrees[field_name] > 0
        e = sums.energy[name]
        t = sums.torque[name]
        size = {
            "V_spread": float(e.max(initial=0.0) - e.min(initial=0.0)) if len(e) else 0.0,
            "torque": float(np.linalg.norm(t, axis=1).max(initial=0.0)),
        }
        route, worst = None, None
        gross = float(sums.torque_gross[name].max(initial=0.0))
        # an effect that cancels to rounding (e.g. masses centred at O in uniform gravity)
        # has no torque to compare: its route agreement would only measure rounding
        if active and resolved(size["torque"], gross):
            fitted = _fitted_torque(gammas, e, degrees[field_name])
            if fitted is not None:
                route, _, _, _, worst = _relative(t, fitted, gross, gammas)
        out[name] = EffectResult(name, source, counts[source], active, size, route, worst)
    out["inertia"] = EffectResult(
        "inertia",
        "masses",
        counts["masses"],
        counts["masses"] > 0,
        {"total_mass": float(elements.mass_values.sum()), "trace": float(np.trace(inertia))},
    )
    return out


def summary_lines(report: CheckReport) -> list[str]:
    """Human-readable lines of a report (the CLI prints them)."""
    lines = [
        f"check: {report.n_orientations} orientations, {report.n_pairs} element-orientation "
        f"pairs, tol {report.tol:g}, evaluated in {report.precision}",
        f"{'quantity':<20} {'rel_err':>10} {'floor':>8} {'cancel':>8}  {'status':<10} worst gamma",
    ]
    status = {"info": "info", "pass": "PASS", "fail": "FAIL", "unverifiable": "UNVERIFIED"}
    for name, q in report.quantities.items():
        where = (
            "-"
            if q.worst_gamma is None
            else "(" + ", ".join(f"{g:+.4f}" for g in q.worst_gamma) + ")"
        )
        cancel = "zero ref" if q.basis == "gross" else f"{q.cancellation:.1e}"
        lines.append(
            f"{name:<20} {q.rel_err:>10.3e} {q.rounding_floor:>8.1e} {cancel:>8}  "
            f"{status[q.status]:<10} {where}"
        )
    lines.append(f"{'effect':<14} {'source':<8} {'elements':>8}  size; route agreement")
    for name, e in report.effects.items():
        size = ", ".join(f"{k} {v:.4g}" for k, v in e.size.items())
        route = "" if e.route_rel_err is None else f"; routes agree to {e.route_rel_err:.2e}"
        lines.append(f"{name:<14} {e.source:<8} {e.n_elements:>8}  {size}{route}")
    for body in report.quadrature:
        lines.append(
            f"continuous {body['kind']} {body['shape']}: {body['nodes']} nodes, "
            f"exact to degree {body['order']}"
        )
    lines += [f"note: {n}" for n in report.notes]
    lines += [f"{name}: {q.reason}" for name, q in report.quantities.items() if q.reason]
    lines.append("PASSED" if report.passed else "FAILED: " + ", ".join(report.failures))
    return lines


__all__ = [
    "ACCURATE_FRACTION",
    "DD_UNIT",
    "DEFAULT_ORIENTATIONS",
    "DEFAULT_TOL",
    "EPS",
    "NOISE_FLOOR",
    "PRECISIONS",
    "ROUNDING_FACTOR",
    "AccurateSums",
    "CheckReport",
    "EffectResult",
    "Elements",
    "QuantityResult",
    "RotatedSums",
    "check_design",
    "collect_elements",
    "contribution_sizes",
    "evaluate_accurate",
    "evaluate_rotated",
    "rotation_matrices",
    "rounding_floor",
    "sample_orientations",
    "summary_lines",
]

# `chargedesign.check(...)` calls chargedesign.api.check (the module stays a module)
from chargedesign.api import make_callable  # noqa: E402

make_callable(__name__)
