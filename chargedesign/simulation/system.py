"""The rigid body and the effects acting on it: torques, energies and momenta, by two routes.

State of one trajectory: ``y = (p, q, r, w, x, y, z)``: angular velocity in body axes (1/s)
and a quaternion ``(w, x, y, z)`` of the attitude (body to space). The rotation is
``R(q) / |q|^2`` with the homogeneous quadratic form of the quaternion, so it is orthonormal
for any non-zero quaternion and ``gamma = R^T e_Z`` (the third row) is a unit vector by
construction; the quaternion's norm, which the exact flow conserves, is monitored.

Equations (body axes, ``I = diag(2C, 2C, C)``, or any principal ``diag(A, B, C)`` of a case
of (ep))::

    I omega' = (I omega) x omega + N(omega, gamma, R)
    quaternion' = 1/2 quaternion * (0, omega)

``N`` is the sum of the torques of the effects a scene calls for. For the Euler-Poisson form
``omega' I + omega x (omega I + mu) = gamma x dV/dgamma`` the torque is
``N = gamma x dV/dgamma + mu x omega``; the Lorentz torque on a charge fixed in the body is
exactly ``q r x ((omega x r) x B) = (omega x r) q (r . B) = mu_q x omega`` with
``mu_q = -q (r . B) r``, so the contract's ``mu = -sum q (r . B) r`` enters with that sign.

Two routes compute ``N``:

- ``direct``: element by element at the rotated positions, from the fields (Lorentz force
  ``q v x B``, ``q E``, ``m g``, dipole torque ``sigma x B`` plus ``X x grad(sigma . B)``).
  Torques (and so the equations of motion) use the kernel of
  :mod:`chargedesign.simulation.direct` (body axes, ``Z = r . gamma`` per element);
  :func:`direct_terms` is the same physics term by term in space axes, used for the energy
  and the momentum and as the reference the kernel is tested against.
- ``reduced``: polynomials in gamma whose coefficients are moment contractions
  (:mod:`chargedesign.simulation.polynomials`); exact for the polynomial fields.

The ``theorem`` effect is the reduced model itself: ``V`` and ``mu`` of the theorem from
:mod:`chargedesign.model.evaluators` (lambda and rho allowed), or of a case of (ep) when the
system is given one (its polynomial V and mu, :mod:`chargedesign.model.case_numeric`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from chargedesign.constants import MU_0
from chargedesign.errors import InputError
from chargedesign.formatting import CELL, PLAIN, ROUGH, fmt
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.physical.parasitics import eddy_torque
from chargedesign.scene.simulation import check_effect_names
from chargedesign.simulation import polynomials as poly
from chargedesign.simulation.body import Body as Body  # the type lives below the kernel
from chargedesign.simulation.direct import DirectKernel, cross

#: every effect a scene may call for
from chargedesign.vocabulary import EFFECTS as EFFECTS

#: force routes for a designed body
from chargedesign.vocabulary import SIMULATION_ROUTES as ROUTES

#: which source and field each physical effect needs
EFFECT_SOURCES = {
    "lorentz": ("charges", "magnetic"),
    "electric": ("charges", "electric"),
    "magnetization": ("dipoles", "magnetic"),
    "gravity": ("masses", "gravity"),
    # the parts' own materials magnetised by the field (energy -chi v |B|^2 / (2 mu0))
    "induced": ("parts", "magnetic"),
    # the eddy currents of the conducting parts turning in the field (a damping torque)
    "eddy": ("conductors", "magnetic"),
}
#: effects computed only when a scene asks: for a real body they can be 1e11 times the
#: designed torques, and a run meant for the designed motion would take as many more steps
OPT_IN_EFFECTS = ("induced", "eddy")
#: effects whose torque depends on omega beyond the gyroscopic mu x omega (no potential,
#: no polynomial bank: added to the torque as they are)
DISSIPATIVE_EFFECTS = ("eddy",)
#: column layout of the reduced polynomial bank
_V, _DV, _MU, _L = 0, slice(1, 4), slice(4, 7), 7


def quaternion_rotation(quats: np.ndarray) -> np.ndarray:
    """Body-to-space rotation matrices of quaternions ``(w, x, y, z)``.

    Parameters
    ----------
    quats : ndarray, shape (m, 4)
        Non-zero quaternions (need not be normalised: ``R(q) / |q|^2`` is orthonormal).

    Returns
    -------
    ndarray, shape (m, 3, 3)
    """
    w, x, y, z = quats[:, 0], quats[:, 1], quats[:, 2], quats[:, 3]
    n = w * w + x * x + y * y + z * z
    R = np.empty((len(quats), 3, 3))
    R[:, 0, 0] = w * w + x * x - y * y - z * z
    R[:, 0, 1] = 2.0 * (x * y - w * z)
    R[:, 0, 2] = 2.0 * (x * z + w * y)
    R[:, 1, 0] = 2.0 * (x * y + w * z)
    R[:, 1, 1] = w * w - x * x + y * y - z * z
    R[:, 1, 2] = 2.0 * (y * z - w * x)
    R[:, 2, 0] = 2.0 * (x * z - w * y)
    R[:, 2, 1] = 2.0 * (y * z + w * x)
    R[:, 2, 2] = w * w - x * x - y * y + z * z
    R /= n[:, None, None]
    return R


def quaternion_gamma(quats: np.ndarray) -> np.ndarray:
    """``gamma = R^T e_Z`` (the third row of ``R``), ndarray shape (m, 3), unit by construction."""
    w, x, y, z = quats[:, 0], quats[:, 1], quats[:, 2], quats[:, 3]
    n = w * w + x * x + y * y + z * z
    out = np.empty((len(quats), 3))
    out[:, 0] = 2.0 * (x * z - w * y) / n
    out[:, 1] = 2.0 * (y * z + w * x) / n
    out[:, 2] = (w * w - x * x - y * y + z * z) / n
    return out


def rotation_quaternion(rotation: np.ndarray) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` of one rotation matrix (Shepperd's method), shape (4,)."""
    R = rotation
    trace = R[0, 0] + R[1, 1] + R[2, 2]
    diag = (trace, R[0, 0], R[1, 1], R[2, 2])
    k = int(np.argmax(diag))
    if k == 0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = (0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s)
    elif k == 1:
        s = 2.0 * np.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = ((R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s)
    elif k == 2:
        s = 2.0 * np.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = ((R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = ((R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s)
    out = np.array(q)
    return out / np.linalg.norm(out)


def attitude_from_gamma(gamma: np.ndarray, precession: float = 0.0) -> np.ndarray:
    """A body-to-space rotation whose third row is ``gamma``, turned by ``precession`` about Z.

    The dynamics depend on gamma only; the angle about the space Z axis (rad) fixes the rest
    of the attitude.

    Returns
    -------
    ndarray, shape (3, 3)
    """
    g = gamma / np.linalg.norm(gamma)
    helper = np.array([1.0, 0.0, 0.0]) if abs(g[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(helper, g)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(g, e1)
    R = np.array([e1, e2, g])
    c, s = np.cos(precession), np.sin(precession)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return Rz @ R


def state_derivatives(
    states: np.ndarray, torque: np.ndarray, C: float, inertia: np.ndarray | None = None
) -> np.ndarray:
    """``(p, q, r, w, x, y, z)'`` of states (m, 7) under torques (m, 3) (body axes, N m).

    Euler's equations ``I omega' = (I omega) x omega + N`` with ``I = diag(2C, 2C, C)``, or
    the principal moments ``inertia = (A, B, C)`` given (kg m^2), and the quaternion's
    ``1/2 quaternion * (0, omega)``: the numpy form of every batched right-hand side.
    """
    omega = states[:, :3]
    N = torque
    p, q, r = omega[:, 0], omega[:, 1], omega[:, 2]
    out = np.empty_like(states)
    if inertia is not None:
        # I omega' = (I omega) x omega + N with I = diag(A, B, C)
        out[:, :3] = (cross(omega * inertia, omega) + N) / inertia
    else:
        # I omega' = (I omega) x omega + N with I = diag(2C, 2C, C)
        out[:, 0] = 0.5 * q * r + N[:, 0] / (2.0 * C)
        out[:, 1] = -0.5 * p * r + N[:, 1] / (2.0 * C)
        out[:, 2] = N[:, 2] / C
    w, x, y, z = states[:, 3], states[:, 4], states[:, 5], states[:, 6]
    out[:, 3] = -0.5 * (x * p + y * q + z * r)
    out[:, 4] = 0.5 * (w * p + y * r - z * q)
    out[:, 5] = 0.5 * (w * q + z * p - x * r)
    out[:, 6] = 0.5 * (w * r + x * q - y * p)
    return out


def body_mass_points(body: Body) -> tuple[np.ndarray, np.ndarray]:
    """Every point mass of the body: positions (n, 3) in m and masses (n,) in kg.

    The one place the simulation reads the body's mass distribution (inertia, centre of mass,
    C from the masses): the ballast plus the carriers' and magnets' own masses.
    """
    return body.all_masses()


def mass_inertia(body: Body) -> tuple[np.ndarray, float, np.ndarray]:
    """Inertia tensor about O (kg m^2, (3, 3)), total mass (kg) and centre of mass (m, (3,)):
    the point masses' plus the parts' own and the holder's (``body.parts_inertia``)."""
    pts, m = body_mass_points(body)
    if len(m) == 0:
        return np.zeros((3, 3)), 0.0, np.zeros(3)
    r2 = np.einsum("ij,ij->i", pts, pts)
    inertia = np.eye(3) * float(m @ r2) - np.einsum("i,ij,ik->jk", m, pts, pts)
    inertia = inertia + body.parts_inertia
    total = float(np.sum(m))
    centre = (m @ pts) / total if total != 0.0 else np.zeros(3)
    return inertia, total, centre


#: relative tolerance of the inertia consistency check (designs polish to about 1e-9)
INERTIA_RTOL = 1e-6


def inertia_mismatch(
    body: Body, rtol: float = INERTIA_RTOL, target: Sequence[float] | None = None
) -> str | None:
    """Why the masses' inertia disagrees with ``diag(2C, 2C, C)``, or None when it agrees.

    Compares the given C with the masses' inertia about O (A = B = 2C, products zero). A
    body without masses has nothing to compare (its inertia is the given C).
    """
    _, m = body_mass_points(body)
    if len(m) == 0 or not np.any(m != 0.0):
        return None
    inertia, _, _ = mass_inertia(body)
    C = body.parameters.C
    wanted = np.diag([2.0 * C, 2.0 * C, C]) if target is None else np.diag(target)
    scale = float(np.max(np.abs(inertia))) or 1.0
    err = float(np.max(np.abs(inertia - wanted))) / scale
    if err <= rtol:
        return None
    A, B, Cm = np.diag(inertia)
    off = max(abs(inertia[0, 1]), abs(inertia[0, 2]), abs(inertia[1, 2]))
    if target is not None:
        return (
            f"the masses' inertia about O is diag({fmt(A, CELL)}, {fmt(B, CELL)}, {fmt(Cm, CELL)})"
            f" kg m^2 (largest product {fmt(off)}) but the case asks for diag("
            + ", ".join(fmt(float(m), CELL) for m in target)
            + f") (relative mismatch {fmt(err, ROUGH)} > {fmt(rtol, PLAIN)})"
        )
    return (
        f"the masses' inertia about O is diag({fmt(A, CELL)}, {fmt(B, CELL)}, {fmt(Cm, CELL)}) kg"
        " m^2 (largest "
        f"product {fmt(off)}) but C = {fmt(C, CELL)} asks for diag({fmt(2 * C, CELL)},"
        f" {fmt(2 * C, CELL)}, {fmt(C, CELL)}) "
        f"(relative mismatch {fmt(err, ROUGH)} > {fmt(rtol, PLAIN)})"
    )


def theorem_is_trivial(params: Parameters) -> bool:
    """True when the theorem's V and mu vanish (n = K = kappa = lambda = rho = 0)."""
    return all(v == 0.0 for v in (params.n, params.K, params.kappa, params.lam, params.rho))


def _requested_effects(
    body: Body, requested: Sequence[str] | None, notes: list[str]
) -> tuple[list[str], bool]:
    """The effects asked for (each once), and whether they were implicit (None: the default)."""
    if requested is None:
        names = [n for n in EFFECT_SOURCES if n not in OPT_IN_EFFECTS] if body.has_elements else []
        if body.source_count("parts"):
            notes.append(
                "induced: not computed unless simulation.effects asks for it (the parts' own "
                "magnetisation; the design's realism budget gives its size)"
            )
        return names or ["theorem"], True
    return check_effect_names(requested), False


def select_effects(body: Body, requested: Sequence[str] | None) -> tuple[list[str], list[str]]:
    """The effects to compute and notes on those skipped.

    Parameters
    ----------
    body : Body
    requested : sequence of str or None
        Effect names (see :data:`EFFECTS`); None: every physical effect that has a source
        and a non-zero field for a body with elements (but ``induced``, which is asked for
        by name), else ``theorem``.

    Returns
    -------
    effects : list of str
        In the order of :data:`EFFECTS`.
    notes : list of str
        One line per skipped effect, with the reason.
    """
    notes: list[str] = []
    names, implicit = _requested_effects(body, requested, notes)
    used: list[str] = []
    for name in EFFECTS:
        if name not in names:
            continue
        if name == "theorem":
            if theorem_is_trivial(body.parameters):
                notes.append("theorem: skipped, V and mu vanish (n = K = kappa = lambda = rho = 0)")
            else:
                used.append(name)
            continue
        source, kind = EFFECT_SOURCES[name]
        if body.source_count(source) == 0:
            if not implicit or body.has_elements:
                notes.append(f"{name}: skipped, the body has no {source}")
            continue
        if body.field(kind).is_zero:
            notes.append(f"{name}: skipped, the {kind} field is zero")
            continue
        used.append(name)
    return used, notes


class RigidBodySystem:
    """Torques, energy and momentum of a body under a set of effects, batched over states.

    Parameters
    ----------
    body : Body
        Elements, fields and parameters (``C`` sets the inertia).
    effects : sequence of str
        Effects to compute (already selected, see :func:`select_effects`).
    route : {"reduced", "direct"}
        Force route for the physical effects (the ``theorem`` effect has only one).
    inertia : sequence of 3 floats, optional
        The principal moments ``(A, B, C)`` about O, kg m^2 (default the theorem's
        ``(2C, 2C, C)`` of the body's C): a case of (ep) of any inertia.
    case : CaseFunctions, optional
        A case of (ep) (:mod:`chargedesign.model.case_numeric`): with the ``theorem`` effect
        the reduced model is the case's V and l instead of the theorem's.
    """

    def __init__(
        self,
        body: Body,
        effects: Sequence[str],
        route: str = "reduced",
        *,
        inertia: Sequence[float] | None = None,
        case: Any = None,
    ) -> None:
        # the route is the scene's checked [simulation] route, the effects select_effects'
        if route not in ROUTES or not set(effects) <= set(EFFECTS):
            raise ValueError(f"route {route!r} or effects {list(effects)} not known")
        self.body = body
        self.effects = list(effects)
        self.route = route
        self.C = body.parameters.C
        self.parameters = body.parameters
        self.physical = [e for e in self.effects if e != "theorem" and e not in DISSIPATIVE_EFFECTS]
        self.dissipative = [e for e in self.effects if e in DISSIPATIVE_EFFECTS]
        self.case = case
        C = self.C
        theorem_inertia = np.array([2.0 * C, 2.0 * C, C])
        self.inertia = theorem_inertia if inertia is None else np.asarray(inertia, dtype=float)
        if self.inertia.shape != (3,) or not np.all(self.inertia > 0.0):
            raise ValueError(f"inertia {inertia!r}: expected three principal moments > 0")
        #: True unless the inertia is the theorem's diag(2C, 2C, C) (its equations' own form)
        self.general_inertia = not np.array_equal(self.inertia, theorem_inertia)
        reduced_by_theorem = "theorem" in self.effects and case is None
        self.singular = reduced_by_theorem and body.parameters.singular
        self._banks: dict[str, poly.PolynomialBank] = {}
        for name in self.physical:
            self._banks[name] = poly.PolynomialBank(reduced_polynomials(body, name))
        self._bank = poly.PolynomialBank(
            reduced_polynomials(body, *self.physical) if self.physical else [{}] * 8
        )
        self._theorem: _TheoremTerms | _CaseTerms | None = None
        if "theorem" in self.effects:
            self._theorem = _CaseTerms(case) if case is not None else _TheoremTerms(body.parameters)
        self._kernels: dict[tuple[str, ...], DirectKernel] = {}

    @property
    def polynomial_bank(self) -> poly.PolynomialBank:
        """The reduced route's bank ``[V, dV/dgamma, mu, L]`` of all physical effects."""
        return self._bank

    def direct_kernel(self) -> DirectKernel:
        """The direct route's kernel of all physical effects (built once)."""
        return self._kernel(self.physical)

    def _kernel(self, physical: Sequence[str]) -> DirectKernel:
        """The direct route's kernel for a set of physical effects (built once, cached)."""
        key = tuple(physical)
        if key not in self._kernels:
            self._kernels[key] = DirectKernel(self.body, key)
        return self._kernels[key]

    # ------------------------------------------------------------------ torques
    def torque(
        self,
        omega: np.ndarray,
        gamma: np.ndarray,
        rotation: np.ndarray | None = None,
        effects: Sequence[str] | None = None,
        route: str | None = None,
    ) -> np.ndarray:
        """Total torque about O in body axes, N m.

        Parameters
        ----------
        omega : ndarray, shape (m, 3)
            Angular velocities in body axes, 1/s.
        gamma : ndarray, shape (m, 3)
            Unit vectors of space Z in body axes.
        rotation : ndarray, shape (m, 3, 3), optional
            Body-to-space rotations; no torque depends on them beyond gamma (the direct
            route places the elements by ``Z = r . gamma``), accepted for symmetry with
            :meth:`energy`.
        effects : sequence of str, optional
            A subset of this system's effects (default: all of them).
        route : str, optional
            Override the system's route.

        Returns
        -------
        ndarray, shape (m, 3)
        """
        names = self.effects if effects is None else list(effects)
        route = self.route if route is None else route
        out = np.zeros_like(gamma)
        physical = [e for e in names if e != "theorem" and e not in DISSIPATIVE_EFFECTS]
        if "eddy" in names:
            body = self.body
            out += eddy_torque(
                body.fields.get("magnetic", ()),
                body.conductor_positions,
                body.conductor_weights,
                omega,
                gamma,
            )
        if physical:
            if route == "reduced":
                bank = self._bank if physical == self.physical else None
                if bank is not None:
                    out += _reduced_torque(bank(gamma), omega, gamma)
                else:
                    for name in physical:
                        out += _reduced_torque(self._banks[name](gamma), omega, gamma)
            else:
                out += self._kernel(physical).torque(omega, gamma)
        if "theorem" in names and self._theorem is not None:
            out += self._theorem.torque(omega, gamma)
        return out

    def energy(
        self, gamma: np.ndarray, rotation: np.ndarray | None = None, route: str | None = None
    ) -> np.ndarray:
        """Potential energy ``V(gamma)`` of the effects (J), ndarray shape (m,)."""
        route = self.route if route is None else route
        out = np.zeros(len(gamma))
        if self.physical:
            if route == "reduced":
                out += self._bank(gamma)[:, _V]
            else:
                R = self._rotations(gamma, rotation)
                zero = np.zeros_like(gamma)
                for name in self.physical:
                    out += direct_terms(self.body, name, zero, R)[1]
        if self._theorem is not None:
            out += self._theorem.energy(gamma)
        return out

    def momentum_potential(
        self, gamma: np.ndarray, rotation: np.ndarray | None = None, route: str | None = None
    ) -> np.ndarray:
        """The gamma-dependent part ``L(gamma)`` of I3 (J s), ndarray shape (m,).

        Lorentz: ``sum q psi`` (flux function in the natural axisymmetric gauge); theorem:
        ``l . gamma``.
        """
        route = self.route if route is None else route
        out = np.zeros(len(gamma))
        if "lorentz" in self.physical:
            if route == "reduced":
                out += self._banks["lorentz"](gamma)[:, _L]
            else:
                R = self._rotations(gamma, rotation)
                out += direct_terms(self.body, "lorentz", np.zeros_like(gamma), R)[2]
        if self._theorem is not None:
            out += self._theorem.momentum(gamma)
        return out

    def gyroscopic(self, gamma: np.ndarray) -> np.ndarray:
        """``mu(gamma)`` of all effects (J s), ndarray shape (m, 3) (reduced route)."""
        out = self._bank(gamma)[:, _MU].copy() if self.physical else np.zeros_like(gamma)
        if self._theorem is not None:
            out += self._theorem.gyroscopic(gamma)
        return out

    def _rotations(self, gamma: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        if rotation is not None:
            return rotation
        return np.array([attitude_from_gamma(g) for g in gamma])

    # ----------------------------------------------------------------- dynamics
    def inertia_diagonal(self) -> np.ndarray:
        """``(A, B, C)``, kg m^2."""
        return self.inertia.copy()

    def derivatives(self, states: np.ndarray) -> np.ndarray:
        """Right-hand side for states ``(p, q, r, w, x, y, z)``, ndarray (m, 7) -> (m, 7)."""
        N = self.torque(states[:, :3], quaternion_gamma(states[:, 3:]))
        return state_derivatives(states, N, self.C, self.inertia if self.general_inertia else None)

    def rhs_function(self, batch: int = 1) -> Callable[[float, np.ndarray], np.ndarray]:
        """``fun(t, y)`` for solve_ivp: ``y`` of shape (7 batch,) laid out as (batch, 7).

        One trajectory takes a path in Python floats (numpy's overhead on 3-vectors dominates
        otherwise; the direct route evaluates its elements in one numpy pass); batches use
        :meth:`derivatives`.
        """
        if batch != 1 or self.dissipative or self.general_inertia:
            # a dissipative torque (eddy) is evaluated in numpy, one state at a time if need be
            derivatives = self.derivatives

            def fun_batch(t: float, y: np.ndarray) -> np.ndarray:
                return derivatives(y.reshape(-1, 7)).reshape(-1)

            return fun_batch
        return self._single_state_function()

    def _single_state_function(self) -> Callable[[float, np.ndarray], np.ndarray]:
        C = self.C
        half_inv_C = 0.5 / C
        inv_C = 1.0 / C
        direct = reduced = None
        if self.physical and self.route == "direct":
            direct = self._kernel(self.physical).scalar_function()
        elif self.physical:
            reduced = self._bank
        coef = np.ascontiguousarray(reduced.coefficients[:, 1:7]) if reduced is not None else None
        monomials = reduced.monomials if reduced is not None else None
        dot = np.dot
        theorem = self._theorem.scalar_functions() if self._theorem is not None else None
        array = np.array

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            p, q, r, w, x, yq, z = y.tolist()
            nq = w * w + x * x + yq * yq + z * z
            g1 = 2.0 * (x * z - w * yq) / nq
            g2 = 2.0 * (yq * z + w * x) / nq
            g3 = (w * w - x * x - yq * yq + z * z) / nq
            N1 = N2 = N3 = 0.0
            if coef is not None and monomials is not None:
                d1, d2, d3, m1, m2, m3 = dot(monomials(g1, g2, g3), coef).tolist()
            elif direct is not None:
                d1, d2, d3, m1, m2, m3 = direct(g1, g2, g3)
            if coef is not None or direct is not None:
                # gamma x dV/dgamma + mu x omega
                N1 = g2 * d3 - g3 * d2 + m2 * r - m3 * q
                N2 = g3 * d1 - g1 * d3 + m3 * p - m1 * r
                N3 = g1 * d2 - g2 * d1 + m1 * q - m2 * p
            if theorem is not None:
                try:
                    d1, d2, d3, m1, m2, m3 = theorem(g1, g2, g3)
                except (OverflowError, ZeroDivisionError):
                    # on the singular plane: an infinite derivative makes the solver reject
                    # the step (the gamma3 event stops the run before it gets there)
                    return np.full(7, np.inf)
                N1 += g2 * d3 - g3 * d2 + m2 * r - m3 * q
                N2 += g3 * d1 - g1 * d3 + m3 * p - m1 * r
                N3 += g1 * d2 - g2 * d1 + m1 * q - m2 * p
            return array(
                (
                    0.5 * q * r + N1 * half_inv_C,
                    -0.5 * p * r + N2 * half_inv_C,
                    N3 * inv_C,
                    -0.5 * (x * p + yq * q + z * r),
                    0.5 * (w * p + yq * r - z * q),
                    0.5 * (w * q + z * p - x * r),
                    0.5 * (w * r + x * q - yq * p),
                )
            )

        return fun

    def integrals(
        self, states: np.ndarray, route: str | None = None, rate: float = 0.0
    ) -> np.ndarray:
        """``I1, I2, I3, I4`` along states ``(m, 7)``, ndarray shape (m, 4).

        I1 = 1/2 omega . I omega + V (J); I2 = |gamma|^2; I3 = (I omega) . gamma + L(gamma)
        (J s; physical canonical momentum about Z); I4 = the theorem's quartic integral with
        this body's parameters (1/s^4), whatever effects act.

        With ``rate = n != 0`` the states are read in axes turning at n about Z (omega is the
        angular velocity relative to them, :func:`chargedesign.larmor.to_turning_axes`, and
        the quaternion the attitude relative to them) and the integrals are those of the
        turning axes, each evaluated at the turning-axes state (Larmor, the exact identities
        of :mod:`chargedesign.model.larmor`):

        - ``I1 = 1/2 omega . I omega + V - n L + n^2 (C |gamma|^2 - 1/2 gamma . I gamma)``
          (centrifugal and vector-potential terms of the turning axes, plus the constant
          ``C n^2 |gamma|^2`` that makes it the theorem's H with n for a body realising the
          theorem with n = 0); for any body it is ``H_0 - n I3_0 + C n^2 |gamma|^2``;
        - ``I3 = (I omega) . gamma + L + n gamma . I gamma``, equal to the inertial I3;
        - ``I4`` with the parameters' n replaced by the rate.
        """
        omega = states[:, :3]
        quats = states[:, 3:]
        gamma = quaternion_gamma(quats)
        rotation = quaternion_rotation(quats)
        Iw = omega * self.inertia_diagonal()
        out = np.empty((len(states), 4))
        energy = self.energy(gamma, rotation, route)
        momentum = self.momentum_potential(gamma, rotation, route)
        out[:, 0] = 0.5 * np.einsum("ij,ij->i", Iw, omega) + energy
        out[:, 1] = np.einsum("ij,ij->i", gamma, gamma)
        out[:, 2] = np.einsum("ij,ij->i", Iw, gamma) + momentum
        params = self.parameters
        if rate != 0.0:
            g_i_g = np.einsum("ij,ij->i", gamma * self.inertia_diagonal(), gamma)
            out[:, 0] += -rate * momentum + rate**2 * (self.C * out[:, 1] - 0.5 * g_i_g)
            out[:, 2] += rate * g_i_g
            params = replace(params, n=rate)
        out[:, 3] = theorem_i4(np.hstack([omega, gamma]), params)
        return out

    def solve_r(self, gamma: np.ndarray, p: float, q: float, level: float = 0.0) -> float:
        """The r that puts ``(p, q, r, gamma)`` on ``I3 = level`` (needs gamma3 != 0)."""
        g = gamma.reshape(1, 3)
        L = float(self.momentum_potential(g, np.array([attitude_from_gamma(gamma)]))[0])
        if abs(gamma[2]) < 1e-8:
            raise InputError("initial.gamma: gamma3 must be non-zero to solve r from the level")
        if self.general_inertia:
            A, B, C = self.inertia
            return (level - A * p * gamma[0] - B * q * gamma[1] - L) / (C * gamma[2])
        return (level - 2.0 * self.C * (p * gamma[0] + q * gamma[1]) - L) / (self.C * gamma[2])


def _reduced_torque(values: np.ndarray, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """``gamma x dV/dgamma + mu x omega`` from bank columns (m, 8)."""
    return cross(gamma, values[:, _DV]) + cross(values[:, _MU], omega)


def reduced_polynomials(body: Body, *effects: str) -> list[poly.GammaPoly]:
    """The polynomials ``[V, dV/dg1, dV/dg2, dV/dg3, mu1, mu2, mu3, L]`` of physical effects.

    Coefficients are moment contractions of the body's elements with the fields'
    coefficients (see :mod:`chargedesign.simulation.polynomials`).
    """
    V: poly.GammaPoly = {}
    mu: list[poly.GammaPoly] = [{}, {}, {}]
    L: poly.GammaPoly = {}
    shifts = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
    for name in effects:
        if name == "lorentz":
            phi = poly.field_polynomial(body.fields.get("magnetic", ()))
            # r . grad Phi = sum over homogeneous parts of degree a + 2j: (a + 2j) Phi
            euler = {(a, j): (a + 2 * j) * c for (a, j), c in phi.items()}
            for axis in range(3):
                poly.add_into(
                    mu[axis],
                    poly.contract(euler, body.charge_positions, body.charge_values, shifts[axis]),
                )
            flux = poly.flux_polynomial(body.fields.get("magnetic", ()))
            poly.add_into(L, poly.contract(flux, body.charge_positions, body.charge_values))
        elif name in ("electric", "gravity"):
            phi = poly.field_polynomial(body.fields.get(name, ()))
            pts, w = (
                (body.charge_positions, body.charge_values)
                if name == "electric"
                else (body.mass_positions, body.mass_values)
            )
            poly.add_into(V, poly.contract(phi, pts, w))
        elif name == "magnetization":
            # -sigma . B = sigma . grad_r Phi = Phi_Z (sigma . gamma) + 2 Phi_S (sigma . r)
            phi = poly.field_polynomial(body.fields.get("magnetic", ()))
            pts, sig = body.dipole_positions, body.dipole_moments
            phi_z, phi_s = poly.derivative_z(phi), poly.derivative_s(phi)
            for axis in range(3):
                part = poly.contract(phi_z, pts, sig[:, axis])
                poly.add_into(V, poly.times_gamma(part, axis))
            poly.add_into(V, poly.contract(phi_s, pts, np.einsum("ij,ij->i", sig, pts)), 2.0)
        elif name == "induced":
            # -sum chi v |B|^2 / (2 mu0)
            b2 = poly.gradient_squared(body.fields.get("magnetic", ()))
            pts, w = body.part_positions, body.part_susceptances
            poly.add_into(V, poly.contract(b2, pts, w), -1.0 / (2.0 * MU_0))
        else:
            raise ValueError(f"effects: {name!r} is not a physical effect")
    return [V, *poly.gamma_gradient(V), *mu, L]


def direct_terms(
    body: Body, effect: str, omega: np.ndarray, rotation: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One effect element by element, at the rotated positions ``X = R r``.

    Parameters
    ----------
    body : Body
    effect : str
        A physical effect.
    omega : ndarray, shape (m, 3)
        Angular velocities in body axes, 1/s.
    rotation : ndarray, shape (m, 3, 3)
        Body-to-space rotations.

    Returns
    -------
    torque : ndarray, shape (m, 3)
        Torque about O in body axes, N m.
    energy : ndarray, shape (m,)
        Potential energy, J (zero for ``lorentz``).
    momentum : ndarray, shape (m,)
        ``sum q psi`` (``lorentz``; zero otherwise), J s.
    """
    m = len(rotation)
    zeros = np.zeros(m)
    if effect in ("lorentz", "electric"):
        pts, w = body.charge_positions, body.charge_values
    elif effect == "gravity":
        pts, w = body.mass_positions, body.mass_values
    elif effect == "magnetization":
        pts, w = body.dipole_positions, np.zeros(len(body.dipole_positions))
    elif effect == "induced":
        pts, w = body.part_positions, body.part_susceptances
    else:
        raise ValueError(f"effect: {effect!r} is not a physical effect")
    n = len(pts)
    X = np.einsum("mij,nj->mni", rotation, pts)  # (m, n, 3) space positions
    flat = X.reshape(-1, 3)
    kind = {"lorentz": "magnetic", "magnetization": "magnetic", "induced": "magnetic"}.get(
        effect, effect
    )
    fld = body.field(kind)
    grad = fld.gradient(flat).reshape(m, n, 3)
    if effect == "lorentz":
        omega_space = np.einsum("mij,mj->mi", rotation, omega)
        velocity = cross(omega_space[:, None, :], X)
        force = w[None, :, None] * cross(velocity, -grad)
        momentum = fld.flux_function(flat).reshape(m, n) @ w
        energy = zeros
    elif effect == "magnetization":
        sigma = np.einsum("mij,kj->mki", rotation, body.dipole_moments)
        B = -grad
        hess = fld.hessian(flat).reshape(m, n, 3, 3)
        force = -np.einsum("mkij,mkj->mki", hess, sigma)  # grad(sigma . B) = -H sigma
        couple = cross(sigma, B).sum(axis=1)
        energy = -np.einsum("mki,mki->m", sigma, B)
        momentum = zeros
        torque_space = cross(X, force).sum(axis=1) + couple
        return np.einsum("mji,mj->mi", rotation, torque_space), energy, momentum
    elif effect == "induced":
        # U = -w |grad Phi|^2 / (2 mu0): F = -grad U = (w / mu0) H grad Phi
        hess = fld.hessian(flat).reshape(m, n, 3, 3)
        force = w[None, :, None] / MU_0 * np.einsum("mkij,mkj->mki", hess, grad)
        energy = -np.einsum("mki,mki->mk", grad, grad) @ w / (2.0 * MU_0)
        momentum = zeros
    else:
        force = -w[None, :, None] * grad
        energy = fld.potential(flat).reshape(m, n) @ w
        momentum = zeros
    torque_space = cross(X, force).sum(axis=1)
    return np.einsum("mji,mj->mi", rotation, torque_space), energy, momentum


class _TheoremTerms:
    """V, mu and l of the theorem from the compiled evaluators (lambda, rho allowed).

    The compiled functions are called directly (no validation) because the integrator may
    probe stages near the singular plane; non-finite values there make it reject the step.
    """

    def __init__(self, params: Parameters) -> None:
        self.params = params
        self._ev = evaluators
        self._pt = evaluators.parameter_tuple(params)

    def _batch(self, quantity: str, gamma: np.ndarray) -> np.ndarray:
        function = self._ev.compiled(quantity, self.params.singular, "numpy")
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            outputs = function(*gamma.T, *self._pt)
        out = np.empty((len(gamma), len(outputs)))
        for k, column in enumerate(outputs):
            out[:, k] = column  # broadcasts constant outputs
        return out

    def scalar_functions(self) -> Callable[[float, float, float], tuple[float, ...]]:
        """``(g1, g2, g3) -> (dV/dg1, dV/dg2, dV/dg3, mu1, mu2, mu3)`` in Python floats."""
        ev = self._ev
        pt = self._pt
        grad = ev.compiled("potential_gradient", self.params.singular, "math")
        gyro = ev.compiled("gyroscopic", self.params.singular, "math")

        def terms(g1: float, g2: float, g3: float) -> tuple[float, ...]:
            return (*grad(g1, g2, g3, *pt), *gyro(g1, g2, g3, *pt))

        return terms

    def torque(self, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        grad = self._batch("potential_gradient", gamma)
        mu = self._batch("gyroscopic", gamma)
        return cross(gamma, grad) + cross(mu, omega)

    def energy(self, gamma: np.ndarray) -> np.ndarray:
        return self._batch("potential", gamma)[:, 0]

    def gyroscopic(self, gamma: np.ndarray) -> np.ndarray:
        return self._batch("gyroscopic", gamma)

    def momentum(self, gamma: np.ndarray) -> np.ndarray:
        return np.einsum("ij,ij->i", self._batch("angular_potential", gamma), gamma)


class _CaseTerms:
    """V, mu and l of a case of (ep) from its numeric functions (polynomials in gamma:
    :func:`chargedesign.model.case_numeric.simulated_functions` refuses singular ones)."""

    def __init__(self, functions: Any) -> None:
        self.functions = functions

    def scalar_functions(self) -> Callable[[float, float, float], tuple[float, ...]]:
        """``(g1, g2, g3) -> (dV/dg1, dV/dg2, dV/dg3, mu1, mu2, mu3)`` in Python floats."""
        terms = self.functions.scalar_terms()

        def scalar(g1: float, g2: float, g3: float) -> tuple[float, ...]:
            return tuple(float(v) for v in terms(g1, g2, g3))

        return scalar

    def torque(self, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        grad = self.functions.potential_gradient(gamma)
        return cross(gamma, grad) + cross(self.functions.gyroscopic(gamma), omega)

    def energy(self, gamma: np.ndarray) -> np.ndarray:
        return np.asarray(self.functions.potential(gamma), dtype=float)

    def gyroscopic(self, gamma: np.ndarray) -> np.ndarray:
        return np.asarray(self.functions.gyroscopic(gamma), dtype=float)

    def momentum(self, gamma: np.ndarray) -> np.ndarray:
        return np.asarray(self.functions.momentum(gamma), dtype=float)


def theorem_i4(states: np.ndarray, params: Parameters) -> np.ndarray:
    """The theorem's quartic integral I4 at states ``(p, q, r, g1, g2, g3)`` (m, 6), shape (m,)."""

    return np.asarray(evaluators.integrals(states, params), dtype=float)[:, 3]
