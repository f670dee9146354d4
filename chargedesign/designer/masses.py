"""Physical design, the magnets' and masses' stage, jointly, on the sites not holding a carrier.

``A_d sigma = s^2 b_d``, ``A_m w = b_m - A_m(carriers) m_carrier`` (the inertia and centre of
mass of all mass), site mass ``w_i >= rho_magnet |sigma_i| / M`` (a magnet weighs at least its
volume), and ``|sigma_i| / M + w_i / rho_ballast <= V_cell`` (magnet plus ballast fit in the
cell). Solved by column generation over the sites (:mod:`chargedesign.designer.mass_columns`,
the whole program deciding when the columns cannot: a refusal Clarabel proves on it directly,
cvxpy otherwise) and polished to machine precision on its
support; :func:`mass_program` returns the stage as one program for a user to extend.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Hashable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import sparse

from chargedesign.designer.linear_program import linprog_highs
from chargedesign.designer.mass_columns import MassData, solve_by_columns, whole_infeasible
from chargedesign.designer.physical_setup import (
    DESIGN_MARGIN,
    Binding,
    PhysicalInfeasible,
    PhysicalSetup,
)
from chargedesign.designer.system import polish_equal, relative_residual, row_scaled
from chargedesign.designer.whole_inertia import CONVERGED, MAX_ROUNDS, Convergence, WholeTerms
from chargedesign.errors import InputError, SolverError
from chargedesign.formatting import PRECISE, fmt
from chargedesign.physical.induced import induced_rows
from chargedesign.scene.physical import PhysicalSpec


# ------------------------------------------------------------------- magnets and masses
@dataclass
class MassSolution:
    sites: np.ndarray  # candidate indices of the sites (no carrier)
    moments: np.ndarray  # (k, 3) A m^2
    site_masses: np.ndarray  # (k,) kg
    residual_dipoles: float
    residual_masses: float
    method: str
    #: with several ballast materials: each entry's material (index into ``spec.ballasts``;
    #: -1 for a magnet), and the induced-magnetisation rows' relative residual
    materials: np.ndarray | None = None
    residual_induced: float | None = None
    #: how the whole inertia's fixed point ended, and the holder's radius (None: no holder)
    convergence: Convergence | None = None
    holder_radius: float | None = None


@dataclass
class MassProgram:
    """The second stage as a cvxpy problem: variables and what they mean."""

    problem: Any
    sigma: Any  # (k, 3) in units of sigma_scale
    mass: Any  # (k,) in units of mass_scale
    sites: np.ndarray
    sigma_scale: float
    mass_scale: float
    rhs_masses: np.ndarray


def _unknown_scale(A: np.ndarray, b: np.ndarray) -> float:
    """The size of the unknowns ``A w = b`` asks for (0 when b = 0): max_i |b_i| / max_j |A_ij|."""
    if A.size == 0 or not np.any(b):
        return 0.0
    top = np.max(np.abs(A), axis=1)
    ok = top > 0
    return float(np.max(np.abs(b[ok]) / top[ok])) if np.any(ok) else 0.0


def mass_data(
    setup: PhysicalSetup,
    s: float,
    carrier_sites: np.ndarray,
    correction: np.ndarray | None = None,
    kappa: float = 1.0,
) -> MassData:
    """The magnets-and-masses program's data at rate ``s`` for these carriers, scaled (see
    :func:`mass_program`, which writes it as a cvxpy problem)."""
    spec = setup.spec
    n = len(setup.points)
    free = np.ones(n, dtype=bool)
    free[carrier_sites] = False
    sites = np.flatnonzero(free)
    Ad, bd = setup.systems["dipoles"]
    Am, bm = setup.systems["masses"]
    bd = s * s * bd
    bm = bm - Am[:, carrier_sites] @ np.full(len(carrier_sites), setup.carrier_mass)
    if correction is not None:
        bm = bm - correction
    Am = kappa * Am
    M, rho_m, rho_b = spec.magnet.magnetisation or 1.0, spec.magnet.density, spec.ballast.density
    v_cap = 4.0 / 3.0 * math.pi * setup.cell_radius[sites] ** 3 * (1 - DESIGN_MARGIN)
    mass_scale = _unknown_scale(Am[:, sites], bm) or float(np.max(v_cap)) * rho_b
    cols = (3 * sites[:, None] + np.arange(3)).reshape(-1)
    sigma_scale = _unknown_scale(Ad[:, cols], bd) or float(np.max(v_cap)) * M
    k = len(sites)
    Ads, bds = row_scaled(Ad[:, cols], bd, sigma_scale) if len(bd) else (np.zeros((0, 3 * k)), bd)
    Ams, bms = row_scaled(Am[:, sites], bm, mass_scale) if len(bm) else (np.zeros((0, k)), bm)
    return MassData(
        sites=sites,
        Ads=Ads,
        bds=bds,
        Ams=Ams,
        bms=bms,
        alpha=(1 + 1e-6) * rho_m * sigma_scale / M / mass_scale,
        beta=sigma_scale / M / v_cap,
        gamma=mass_scale / rho_b / v_cap,
        cm=setup.cost("masses")[sites],
        cd=setup.cost("dipoles")[sites],
        blocked=~setup.magnet_sites[sites],
        sigma_scale=sigma_scale,
        mass_scale=mass_scale,
        rhs_masses=bm,
    )


def mass_program(
    setup: PhysicalSetup,
    s: float,
    carrier_sites: np.ndarray,
    correction: np.ndarray | None = None,
    kappa: float = 1.0,
) -> MassProgram:
    """Build (not solve) the magnets-and-masses program at rate ``s`` for these carriers.

    ``correction`` (the mass rows' whole-inertia terms, :mod:`chargedesign.designer.
    whole_inertia`) is taken off the right-hand side and the free sites' columns are scaled by
    ``kappa`` (what a kilogram adds in the holder's bore); the default is the point masses.

    Returns a :class:`MassProgram`; ``program.problem`` is a ``cvxpy.Problem`` a user may add
    constraints to (``program.sigma`` and ``program.mass`` are the variables, scaled). The
    design solves the same program by columns (:mod:`chargedesign.designer.mass_columns`).
    """
    import cvxpy as cp

    data = mass_data(setup, s, carrier_sites, correction, kappa)
    k = len(data.sites)
    sigma = cp.Variable((k, 3))
    mass = cp.Variable(k, nonneg=True)
    constraints = []
    if len(data.bds):
        constraints.append(data.Ads @ cp.reshape(sigma, (3 * k,), order="C") == data.bds)
    if len(data.bms):
        constraints.append(data.Ams @ mass == data.bms)
    blocked = np.flatnonzero(data.blocked)
    if len(blocked):  # the field there would demagnetise a magnet
        constraints.append(sigma[blocked, :] == 0)
    norms = cp.norm(sigma, 2, axis=1)
    constraints.append(mass >= data.alpha * norms)
    constraints.append(cp.multiply(data.beta, norms) + cp.multiply(data.gamma, mass) <= 1.0)
    # both terms in their natural units: the l1 norm of the moments keeps the magnets few
    # (each weighted by its site's cost under the robust objective)
    objective = cp.Minimize(data.cm @ mass + data.cd @ norms)
    assert data.rhs_masses is not None
    return MassProgram(
        problem=cp.Problem(objective, constraints),
        sigma=sigma,
        mass=mass,
        sites=data.sites,
        sigma_scale=data.sigma_scale,
        mass_scale=data.mass_scale,
        rhs_masses=data.rhs_masses,
    )


@dataclass
class SolvedMasses:
    """The magnets-and-masses program solved: its data, the scaled moments (k, 3) and masses
    (k,) on ``data.sites``, and the route (``columns``, or ``whole`` through cvxpy)."""

    data: MassData
    sigma: np.ndarray
    mass: np.ndarray
    route: str

    @property
    def sites(self) -> np.ndarray:
        return self.data.sites

    @property
    def rhs_masses(self) -> np.ndarray:
        assert self.data.rhs_masses is not None
        return self.data.rhs_masses


#: the key of :attr:`PhysicalSetup.warm` that seeds the masses' working set
MASS_SEED = "masses: working set"


class MassesInfeasible(PhysicalInfeasible):
    """The magnets-and-masses program has no solution (its binding named by the feasibility
    programs of :func:`_mass_binding`, whose words hold the body's own figures)."""


def _solved_mass_program(
    setup: PhysicalSetup, s: float, carrier_sites: np.ndarray, terms: WholeTerms, correction
) -> SolvedMasses:
    """The magnets-and-masses program around the carriers, solved by columns (the whole
    program when they cannot decide; PhysicalInfeasible naming the binding limit when it
    has no solution)."""
    if len(np.unique(carrier_sites)) >= len(setup.points):
        # (the minmax's charges on every candidate, say): nothing left to solve for
        raise PhysicalInfeasible(
            Binding(
                "masses",
                f"the {len(setup.points)} carriers fill every candidate site: no cell is left "
                "for the magnets and the ballast",
                "ballast cells",
            )
        )
    kappa = terms.kappa(setup.spec.ballast.density)
    if kappa <= 0:
        raise PhysicalInfeasible(_holder_binding(setup, kappa))
    data = mass_data(setup, s, carrier_sites, correction, kappa)
    _, bd = setup.systems["dipoles"]
    if np.any(bd != 0) and not np.any(~data.blocked):
        # every free cell would demagnetise a magnet, and V needs magnets: no solver asked
        raise MassesInfeasible(_mass_binding(setup, s, carrier_sites, terms))
    by_columns = solve_by_columns(data, setup.warm.get(MASS_SEED))
    if by_columns is not None:
        setup.warm[MASS_SEED] = by_columns.working
        return SolvedMasses(data, by_columns.sigma, by_columns.mass, "columns")
    # a slack stayed or the rounds ran out: the whole program decides. Clarabel's proof of
    # infeasibility on it, built directly, refuses at once; otherwise cvxpy solves it
    if whole_infeasible(data):
        raise MassesInfeasible(_mass_binding(setup, s, carrier_sites, terms))
    import cvxpy as cp  # slow to import: only when the whole program must decide

    program = mass_program(setup, s, carrier_sites, correction, kappa)
    try:
        program.problem.solve(solver=cp.CLARABEL)
    except cp.SolverError as exc:
        raise SolverError(f"magnets and masses: Clarabel failed ({exc})") from exc
    if program.problem.status in ("infeasible", "infeasible_inaccurate"):
        raise MassesInfeasible(_mass_binding(setup, s, carrier_sites, terms))
    if program.sigma.value is None or program.mass.value is None:
        raise SolverError(f"magnets and masses: Clarabel returned {program.problem.status}")
    return SolvedMasses(
        data, np.asarray(program.sigma.value), np.asarray(program.mass.value), "whole"
    )


def _polish_moments(
    setup: PhysicalSetup, s: float, sites: np.ndarray, sigma: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The solver's moments on ``sites`` polished on their support: all moments (3 n,) and
    which sites keep a magnet."""
    Ad, bd = setup.systems["dipoles"]
    n = len(setup.points)
    # polish each system on its support
    sig_norm = np.linalg.norm(sigma, axis=1)
    top_sigma = max(float(np.max(sig_norm, initial=0.0)), 1e-300)
    sig_keep = sig_norm > 1e-6 * top_sigma
    full_sigma = np.zeros(3 * n)
    cols = (3 * sites[sig_keep][:, None] + np.arange(3)).reshape(-1)
    full_sigma[cols] = sigma[sig_keep].reshape(-1)
    big = sites[sig_norm > 1e-3 * top_sigma]
    if len(bd):
        # corrections on the strong magnets only (relative changes ~ the solver's residual)
        big_cols = (3 * big[:, None] + np.arange(3)).reshape(-1)
        full_sigma = polish_equal(Ad, s * s * bd, full_sigma, big_cols)
    return full_sigma, sig_keep


def _magnet_mass(setup: PhysicalSetup, moments: np.ndarray, factor: float = 1.0) -> np.ndarray:
    """``factor`` times the mass of each moment's magnet (density x |moment| / magnetisation)."""
    return (
        factor
        * setup.spec.magnet.density
        * np.linalg.norm(moments, axis=1)
        / (setup.spec.magnet.magnetisation or 1.0)
    )


def _program_masses(
    setup: PhysicalSetup, s: float, program: SolvedMasses
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The solved program's moments, polished on their support (3 n,), and its masses: per
    site (n,), as solved on the program's sites, and the largest."""
    sites = program.sites
    sigma = program.sigma * program.data.sigma_scale
    mass = np.maximum(program.mass, 0.0) * program.data.mass_scale
    n = len(setup.points)
    full_sigma, sig_keep = _polish_moments(setup, s, sites, sigma)
    # a magnet weighs at least its volume: lift the solver's slack on that bound (relative
    # changes at the solver's tolerance; the heavy sites absorb them in the polish below)
    sig_polished = full_sigma.reshape(n, 3)[sites]
    magnet_floor = _magnet_mass(setup, sig_polished, 1 + 1e-6)
    mass = np.maximum(mass, magnet_floor)
    top_mass = max(float(np.max(mass, initial=0.0)), 1e-300)
    mass_keep = (mass > 1e-9 * top_mass) | sig_keep
    full_mass = np.zeros(n)
    full_mass[sites[mass_keep]] = mass[mass_keep]
    return full_sigma, full_mass, mass, top_mass


#: the program is solved again while its parts change the correction by more than this
PROGRAM_SETTLED = 1e-8
#: solves of the program at most (the correction contracts by about 1e-2 a solve)
MAX_PROGRAMS = 6


def _fixed_point(
    terms: WholeTerms,
    kappa: float,
    Am: np.ndarray,
    rows: np.ndarray,
    full_mass: np.ndarray,
    sites: np.ndarray,
    chooser: np.ndarray,
    top_mass: float,
    correction: np.ndarray,
    n: int,
    full_sigma: np.ndarray,
) -> tuple[np.ndarray, Convergence, np.ndarray, Any]:
    """Rounds of the least-norm polish on the support (the sites ``chooser`` picks by size)
    with the correction of the last round's parts, until it settles; the masses, how it
    ended, the correction and the parts of the masses returned (built once: the caller's
    residual reads them)."""
    carriers_rows = terms.b - rows if len(rows) else rows
    convergence = Convergence()
    for rounds in range(1, MAX_ROUNDS + 1):
        # the correction goes to the heavy sites only, so that light ones (and magnets) keep
        # their sign and their bound: relative changes there are ~ the solver's residual. A
        # robust design spreads its masses, so the heaviest few may not span the mass rows:
        # lighter sites then join, as long as every mass stays nonnegative.
        full_mass = _polish_masses(
            kappa * Am, rows - correction, full_mass, sites, chooser, top_mass
        )
        parts = terms.parts(full_sigma.reshape(n, 3), full_mass)
        fresh = terms.correction(parts, kappa * Am @ full_mass + carriers_rows)
        convergence = Convergence(rounds, terms.change(fresh, correction))
        correction = fresh
        if convergence.change <= CONVERGED:
            break
    return full_mass, convergence, correction, parts


def design_masses(setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> MassSolution:
    """Magnets and ballast at rate ``s`` around the given carriers (see the module doc), with
    every part's own inertia and the holder's (:mod:`chargedesign.designer.whole_inertia`).

    Inside :func:`similar_bodies`, a body made a member of a class of similar bodies takes a
    design of the class made before, scaled, when it is the one it would make itself."""
    shared = _SIMILAR.get()
    if shared is not None:
        return shared.design(setup, s, carrier_sites)
    return _designed_masses(setup, s, carrier_sites)


def _designed_masses(setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> MassSolution:
    """The body's own design (:func:`design_masses`)."""
    terms = WholeTerms(setup, carrier_sites)
    kappa = terms.kappa(setup.spec.ballast.density)
    n = len(setup.points)
    correction = terms.initial()
    program = _solved_mass_program(setup, s, carrier_sites, terms, correction)
    full_sigma, full_mass, mass, top_mass = _program_masses(setup, s, program)
    # the program again with the correction of its own parts (the cells' room then holds
    # for the parts' true sizes) until it settles, then the fixed point on its support
    Am, bm = setup.systems["masses"]
    carriers_rows = bm - program.rhs_masses - correction
    for _ in range(MAX_PROGRAMS):
        fresh = terms.correction(
            terms.parts(full_sigma.reshape(n, 3), full_mass),
            kappa * Am @ full_mass + carriers_rows,
        )
        if terms.change(fresh, correction) <= PROGRAM_SETTLED:
            break
        correction = fresh
        terms.restart()
        program = _solved_mass_program(setup, s, carrier_sites, terms, correction)
        full_sigma, full_mass, mass, top_mass = _program_masses(setup, s, program)
    terms.restart()
    sites = program.sites
    # a magnet at its floor (no attached ballast to give) keeps its mass: the rounds' changes
    # go to the sites that can take them (every site when those alone cannot)
    floor = _magnet_mass(setup, full_sigma.reshape(n, 3)[sites])
    movable = np.where(mass > floor * (1 + 1e-4), mass, 0.0)
    start = full_mass
    for chooser in (movable, mass):
        full_mass, convergence, correction, parts = _fixed_point(
            terms,
            kappa,
            Am,
            bm - carriers_rows,
            start,
            sites,
            chooser,
            top_mass,
            correction,
            n,
            full_sigma,
        )
        if terms.residual(parts) <= 1e-13:
            break
    Ad, bd = setup.systems["dipoles"]
    sig = full_sigma.reshape(n, 3)[sites]
    m = full_mass[sites]
    magnet_mass = _magnet_mass(setup, sig)
    if np.any(m < magnet_mass * (1 - 1e-9)):
        raise SolverError("magnets: polishing left a magnet lighter than its volume")
    used = (np.linalg.norm(sig, axis=1) > 0) | (m > 0)
    residual_dipoles = relative_residual(Ad, full_sigma, s * s * bd) if len(bd) else 0.0
    if setup.spec.designs_induced:
        return induced_ballast(
            setup, carrier_sites, full_sigma.reshape(n, 3), residual_dipoles, terms, correction
        )
    return MassSolution(
        sites=sites[used],
        moments=sig[used],
        site_masses=m[used],
        residual_dipoles=residual_dipoles,
        residual_masses=terms.residual(parts) if len(bm) else 0.0,
        method="Clarabel (magnet-mass and cell-volume cones), least-norm polish on the supports"
        + ", every part's own inertia"
        + (f" and the {setup.spec.holder.name} holder's" if setup.spec.holder else "")
        + " by fixed point",
        convergence=convergence,
        holder_radius=terms.radius if setup.spec.holder is not None else None,
    )


# ---------------------------------------------------------------- similar bodies' designs
def _program_digest(
    setup: PhysicalSetup, s: float, carrier_sites: np.ndarray, ratio: float
) -> bytes | None:
    """The bytes of the first magnets-and-masses program a design at rate ``s`` solves (its
    scaled data, :func:`mass_data`), with the sites, cells and carriers in the units of a body
    ``ratio`` times smaller (None when the design refuses before any program)."""
    terms = WholeTerms(setup, carrier_sites)
    kappa = terms.kappa(setup.spec.ballast.density)
    if kappa <= 0 or len(np.unique(carrier_sites)) >= len(setup.points):
        return None
    data = mass_data(setup, s, carrier_sites, terms.initial(), kappa)
    digest = hashlib.sha256()
    shell = setup.spec.carrier.shell_thickness
    lengths = [setup.carrier_radius, setup.region_radius, -1.0 if shell is None else shell]
    for x in (setup.points, setup.cell_radius, np.asarray(lengths)):
        digest.update(np.ascontiguousarray(x / ratio, dtype=float).tobytes())
    magnet = setup.spec.magnet
    figures = [setup.carrier_mass / ratio**3, magnet.density, magnet.magnetisation or 0.0]
    figures.append(math.nan if magnet.susceptibility is None else magnet.susceptibility)
    digest.update(np.asarray(figures, dtype=float).tobytes())
    for x in (data.Ads, data.bds, data.Ams, data.bms, data.beta, data.gamma, data.cm, data.cd):
        digest.update(np.ascontiguousarray(x, dtype=float).tobytes())
    digest.update(np.asarray([data.alpha], dtype=float).tobytes())
    digest.update(np.asarray(data.blocked, dtype=bool).tobytes())
    return digest.digest()


def _scaled(solution: MassSolution, factor: float) -> MassSolution:
    """The design of the body ``factor`` times the size: masses and moments x factor^3, the
    holder's radius x factor (exact when ``factor`` is a power of 2)."""
    cube = factor**3
    return replace(
        solution,
        moments=solution.moments * cube,
        site_masses=solution.site_masses * cube,
        convergence=replace(solution.convergence) if solution.convergence else None,
        holder_radius=None if solution.holder_radius is None else solution.holder_radius * factor,
    )


@dataclass
class _Shared:
    """One design of a class, in the units of the class's body of ratio 1 (or its refusal),
    the bytes of its first program, and the working set it left (the next design's seed)."""

    digest: bytes
    solution: MassSolution | None
    error: Exception | None
    seed_after: np.ndarray | None


class SimilarBodies:
    """Magnets-and-masses designs shared between similar bodies.

    A body ``r`` times the size of another (its radius, spacing and carriers x r, C x r^5) of
    the same materials in the same field has, at rate ``s / sqrt(r)``, the other's program at
    rate ``s``: the dipole rows grow like r (the field's gradient at r times the distance), their
    right-hand side like ``s^2 C``, the mass rows like r^2 (inertia) and r (centre of mass)
    against C, the cells' volumes like r^3, and every part's own inertia like the body's. For
    ``r = 4^k`` every figure of the design is the other's times a power of 2, so the scaled
    design is the one the body makes itself, to the bit. Members of a class (``add``: a key
    and the ratio ``r`` to the class's body) then share their designs: a design at the class
    rate ``s sqrt(r)``, with the same carriers and the same working set to start from, whose
    first program has the same bytes and whose sites, cells and carriers over ``r`` and
    magnet material's figures too (checked on every use), is the design made before,
    scaled (a refusal refuses again, in the body's own words). ``shared`` and ``designed``
    count the designs taken and made.
    """

    def __init__(self) -> None:
        self._members: dict[int, tuple[PhysicalSetup, Hashable, float]] = {}
        self._designs: dict[Hashable, _Shared] = {}
        self.shared = 0
        self.designed = 0

    def add(self, setup: PhysicalSetup, key: Hashable, ratio: float) -> None:
        """Make ``setup`` a member of the class ``key``, ``ratio`` (a power of 4) times the size
        of the class's body."""
        k = round(math.log(ratio, 4)) if ratio > 0 else 0
        if ratio != 4.0**k:
            raise ValueError(f"similar bodies: the size ratio {ratio!r} is not a power of 4")
        self._members[id(setup)] = (setup, key, ratio)

    def design(self, setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> MassSolution:
        """:func:`design_masses` of a member, shared within its class (others: their own)."""
        member = self._members.get(id(setup))
        if member is None or member[0] is not setup:
            return _designed_masses(setup, s, carrier_sites)
        _, key, ratio = member
        digest = _program_digest(setup, s, carrier_sites, ratio)
        if digest is None:
            return _designed_masses(setup, s, carrier_sites)
        seed = setup.warm.get(MASS_SEED)
        where = (
            key,
            s * math.sqrt(ratio),
            np.asarray(carrier_sites).tobytes(),
            None if seed is None else np.asarray(seed).tobytes(),
        )
        known = self._designs.get(where)
        if known is not None and known.digest == digest:
            self.shared += 1
            return self._replay(setup, s, carrier_sites, known, ratio)
        self.designed += 1
        try:
            solution = _designed_masses(setup, s, carrier_sites)
        except (PhysicalInfeasible, SolverError) as exc:
            self._designs[where] = _Shared(digest, None, exc, setup.warm.get(MASS_SEED))
            raise
        self._designs[where] = _Shared(
            digest, _scaled(solution, 1.0 / ratio), None, setup.warm.get(MASS_SEED)
        )
        return solution

    @staticmethod
    def _replay(
        setup: PhysicalSetup, s: float, carrier_sites: np.ndarray, known: _Shared, ratio: float
    ) -> MassSolution:
        if known.seed_after is not None:
            setup.warm[MASS_SEED] = known.seed_after
        if isinstance(known.error, MassesInfeasible):
            terms = WholeTerms(setup, carrier_sites)
            raise MassesInfeasible(_mass_binding(setup, s, carrier_sites, terms))
        if isinstance(known.error, PhysicalInfeasible):
            raise PhysicalInfeasible(known.error.binding)
        if known.error is not None:
            raise type(known.error)(*known.error.args)
        assert known.solution is not None
        return _scaled(known.solution, ratio)


_SIMILAR: ContextVar[SimilarBodies | None] = ContextVar("similar_bodies", default=None)


@contextmanager
def similar_bodies() -> Iterator[SimilarBodies]:
    """Within the block, :func:`design_masses` shares designs between the members of the
    :class:`SimilarBodies` it yields (:func:`~chargedesign.designer.recommend.recommend`)."""
    shared = SimilarBodies()
    token = _SIMILAR.set(shared)
    try:
        yield shared
    finally:
        _SIMILAR.reset(token)


def _check_susceptibility(susceptibility: Any, role: str, name: str) -> None:
    """A part material's susceptibility, which cancelling the induced magnetisation needs."""
    if susceptibility is None:
        table = "carriers" if role == "carrier" else f"{role}s"
        raise InputError(
            f"{table}.susceptibility: cancelling the induced magnetisation needs the "
            f"{role} material's susceptibility ({name} has none)"
        )


def _susceptibilities(spec: PhysicalSpec) -> dict[tuple[str, str], float]:
    """Each part material's susceptibility by (name, role); one line naming the table whose
    material has none."""
    chi = {}
    for part in (spec.carrier, spec.magnet, *spec.ballasts):
        _check_susceptibility(part.susceptibility, part.role, part.name)
        assert part.susceptibility is not None
        chi[part.name, part.role] = part.susceptibility
    return chi


def _one_material_per_cell(
    cost: np.ndarray, room: np.ndarray, As: np.ndarray, bs: np.ndarray, mats: Any
) -> np.ndarray:
    """The ballast LP (masses per material and cell, scaled; shape (materials, cells)) with
    one material per cell: cells given two are fixed to the one filling more of the cell
    and the LP solved again."""
    J, k = len(mats), room.shape[0]
    allowed = np.ones(J * k, dtype=bool)
    for _ in range(6):
        res = linprog_highs(
            cost,
            A_ub=room,
            b_ub=np.ones(k),
            A_eq=As,
            b_eq=bs,
            bounds=[(0.0, None if ok else 0.0) for ok in allowed],
        )
        if res.status == 2:
            raise PhysicalInfeasible(
                Binding(
                    "masses",
                    "no ballast of " + ", ".join(m.name for m in mats) + " in the free cells "
                    "makes A = B = 2C, the centre of mass at O and the induced magnetisation "
                    "independent of the orientation",
                    "ballast.material",
                )
            )
        if res.status != 0 or res.x is None:
            raise SolverError(
                f"ballast: HiGHS failed on the induced-magnetisation LP ({res.message})"
            )
        x = res.x.reshape(J, k)
        top = max(float(np.max(x)), 1e-300)
        used = x > 1e-12 * top
        split = np.flatnonzero(used.sum(axis=0) > 1)
        if not len(split):
            return x
        keep = np.argmax(x[:, split] / np.array([m.density for m in mats])[:, None], axis=0)
        mask = allowed.reshape(J, k)
        mask[:, split] = False
        mask[keep, split] = True
    raise SolverError("ballast: cells kept two materials after 6 rounds of the LP")


@dataclass
class FixedParts:
    """What the carriers and magnets already put in the mass and induced rows: the mass and
    ``chi v`` (contrast to the holder) of every site, and the magnets' sites and masses."""

    mass: np.ndarray  # (n,) kg
    chi_v: np.ndarray  # (n,) m^3
    magnet_sites: np.ndarray
    magnet_mass: np.ndarray


@dataclass
class BallastRows:
    """The ballast's equality rows on the free cells, one column block per material: the
    first ``n_mass`` rows are the mass rows, the rest the induced-magnetisation rows."""

    A: np.ndarray
    b: np.ndarray
    free: np.ndarray
    n_mass: int
    correction: np.ndarray


def _holder_chi(spec: PhysicalSpec) -> float:
    """The holder's susceptibility (0 without a holder)."""
    return (spec.holder.susceptibility or 0.0) if spec.holder is not None else 0.0


def _fixed_parts(setup: PhysicalSetup, carrier_sites: np.ndarray, sigma: np.ndarray) -> FixedParts:
    """The carriers' and magnets' masses and ``chi v`` (constants of both row sets)."""
    spec = setup.spec
    chi, chi_h = _susceptibilities(spec), _holder_chi(spec)
    n = len(setup.points)
    norms = np.linalg.norm(sigma, axis=1)
    magnet_sites = np.flatnonzero(norms > 0)
    volumes = norms[magnet_sites] / (spec.magnet.magnetisation or 1.0)
    magnet_mass = spec.magnet.density * volumes
    carrier_volume = setup.carrier_mass / spec.carrier.density
    fixed_mass = np.zeros(n)
    fixed_mass[carrier_sites] = setup.carrier_mass
    fixed_mass[magnet_sites] = magnet_mass
    chi_v = np.zeros(n)
    outer_volume = 4.0 / 3.0 * math.pi * setup.carrier_radius**3
    chi_v[carrier_sites] = chi[spec.carrier.name, "carrier"] * carrier_volume - chi_h * outer_volume
    chi_v[magnet_sites] = (chi[spec.magnet.name, "magnet"] - chi_h) * volumes
    return FixedParts(fixed_mass, chi_v, magnet_sites, magnet_mass)


def _ballast_rows(
    setup: PhysicalSetup,
    carrier_sites: np.ndarray,
    fixed: FixedParts,
    terms: WholeTerms,
    correction: np.ndarray | None,
) -> BallastRows:
    """The mass rows (each material's columns scaled by its ``kappa``) and the induced rows
    (``chi v = (chi / rho) m`` in the holder's bore) on the free cells."""
    spec = setup.spec
    chi, chi_h = _susceptibilities(spec), _holder_chi(spec)
    mats = spec.ballasts
    n = len(setup.points)
    legendre = tuple(setup.conditions.fields.get("magnetic", ()))
    Am, bm = setup.systems["masses"]
    rows_all = induced_rows(legendre, setup.points)
    free = np.setdiff1d(np.arange(n), np.concatenate([carrier_sites, fixed.magnet_sites]))
    # chi v per kg, in the holder's bore
    per_kg = np.array([(chi[m.name, "ballast"] - chi_h) / m.density for m in mats])
    kappas = [terms.kappa(m.density) for m in mats]
    if min(kappas) <= 0:
        raise PhysicalInfeasible(_holder_binding(setup, min(kappas)))
    A = np.vstack(
        [
            np.hstack([Am[:, free] * kj for kj in kappas]),
            np.hstack([rows_all[:, free] * c for c in per_kg]),
        ]
    )
    correction = terms.initial() if correction is None else correction
    b = np.concatenate([bm - Am @ fixed.mass - correction, -rows_all @ fixed.chi_v])
    return BallastRows(A, b, free, len(bm), correction)


def _ballast_lp(setup: PhysicalSetup, rows: BallastRows) -> tuple[np.ndarray, np.ndarray]:
    """The ballast LP's masses (per material and free cell, flat, kg; the solver's crumbs
    off the support dropped) and their support."""
    mats = setup.spec.ballasts
    free = rows.free
    v_cap = 4.0 / 3.0 * math.pi * setup.cell_radius[free] ** 3 * (1 - DESIGN_MARGIN)
    scale = _unknown_scale(rows.A, rows.b) or float(np.max(v_cap)) * mats[0].density
    As, bs = row_scaled(rows.A, rows.b, scale)
    # one material per cell: sum_j m_j / (rho_j v_cap) <= 1 (sparse: one entry per column)
    room = sparse.hstack([sparse.diags(scale / (m.density * v_cap)) for m in mats], format="csr")
    cost = np.tile(setup.cost("masses")[free], len(mats))
    x = _one_material_per_cell(cost, room, As, bs, mats)
    flat = x.reshape(-1) * scale
    support = np.flatnonzero(flat > 1e-12 * float(np.max(flat)))
    # the solver's crumbs off the support are dropped before the polish, so that the parts
    # written are exactly the ones the rows were polished with
    kept = np.zeros_like(flat)
    kept[support] = flat[support]
    return kept, support


def _ballast_parts(
    setup: PhysicalSetup,
    carrier_sites: np.ndarray,
    sigma: np.ndarray,
    fixed: FixedParts,
    free: np.ndarray,
    terms: WholeTerms,
    values: np.ndarray,
) -> Any:
    """The whole-inertia parts of the body with these ballast masses (flat, per material
    and free cell), each cell of its material's density."""
    mats = setup.spec.ballasts
    per = values.reshape(len(mats), len(free))
    site_mass = fixed.mass.copy()
    site_mass[carrier_sites] = 0.0
    site_mass[free] += per.sum(axis=0)
    densities = np.full(len(setup.points), setup.spec.ballast.density)
    for j, m in enumerate(mats):
        densities[free[per[j] > 0]] = m.density
    return terms.parts(sigma, site_mass, densities)


def _polished_ballast(
    setup: PhysicalSetup,
    carrier_sites: np.ndarray,
    sigma: np.ndarray,
    fixed: FixedParts,
    rows: BallastRows,
    terms: WholeTerms,
    flat: np.ndarray,
    support: np.ndarray,
) -> tuple[np.ndarray, Convergence]:
    """The LP's masses polished on their support to rounding, the whole inertia's
    correction by fixed point (``rows.b`` and ``rows.correction`` follow it)."""
    Am, _ = setup.systems["masses"]
    convergence = Convergence()
    polished = flat
    terms.restart()
    for rounds in range(1, MAX_ROUNDS + 1):
        polished = polish_equal(rows.A, rows.b, polished, support)
        lhs = rows.A[: rows.n_mass] @ polished + Am @ fixed.mass
        parts = _ballast_parts(setup, carrier_sites, sigma, fixed, rows.free, terms, polished)
        fresh = terms.correction(parts, lhs)
        convergence = Convergence(rounds, terms.change(fresh, rows.correction))
        rows.b[: rows.n_mass] += rows.correction - fresh
        rows.correction = fresh
        if convergence.change <= CONVERGED:
            break
    if np.any(polished < 0):
        raise SolverError("ballast: polishing made a ballast mass negative")
    return polished, convergence


def induced_ballast(
    setup: PhysicalSetup,
    carrier_sites: np.ndarray,
    sigma: np.ndarray,
    residual_dipoles: float,
    terms: WholeTerms | None = None,
    correction: np.ndarray | None = None,
) -> MassSolution:
    """Ballast of several materials that cancels the parts' induced magnetisation.

    The carriers and the magnets ``sigma`` (n, 3), A m^2, are kept; the ballast is designed
    anew, one material per free cell: its masses (per cell and material, kg) meet the mass
    rows (inertia, centre of mass) and the induced-magnetisation rows (:func:`induced_rows`,
    linear in the masses through ``chi v = (chi / rho) m``), within the cells' room. A linear
    program (HiGHS, least total mass); cells given two materials are fixed to the larger and
    the program solved again; then a least-norm polish on the support to rounding. With
    ``terms`` the mass rows hold the whole inertia (each material's columns scaled by its
    ``kappa``, the correction by fixed point on the support) and the induced rows the
    contrast ``chi_part - chi_holder`` of each bore.
    """
    spec = setup.spec
    terms = WholeTerms(setup, carrier_sites) if terms is None else terms
    fixed = _fixed_parts(setup, carrier_sites, sigma)
    rows = _ballast_rows(setup, carrier_sites, fixed, terms, correction)
    flat, support = _ballast_lp(setup, rows)
    polished, convergence = _polished_ballast(
        setup, carrier_sites, sigma, fixed, rows, terms, flat, support
    )
    mats, free, n_mass = spec.ballasts, rows.free, rows.n_mass
    per = polished.reshape(len(mats), len(free))
    material_of, cell = np.nonzero(per > 0)  # material-major, as the entries were listed
    nm = len(fixed.magnet_sites)
    parts = _ballast_parts(setup, carrier_sites, sigma, fixed, free, terms, polished)
    return MassSolution(
        sites=np.concatenate([fixed.magnet_sites, free[cell]]).astype(int),
        moments=np.vstack([sigma[fixed.magnet_sites], np.zeros((len(cell), 3))]),
        site_masses=np.concatenate([fixed.magnet_mass, per[material_of, cell]]),
        residual_dipoles=residual_dipoles,
        residual_masses=terms.residual(parts) if n_mass else 0.0,
        method="Clarabel for the magnets; HiGHS for the ballast of "
        + ", ".join(m.name for m in mats)
        + " (induced magnetisation cancelled), least-norm polish on the supports, every "
        "part's own inertia"
        + (f" and the {spec.holder.name} holder's" if spec.holder else "")
        + " by fixed point",
        convergence=convergence,
        holder_radius=terms.radius if spec.holder is not None else None,
        materials=np.concatenate([np.full(nm, -1), material_of]).astype(int),
        residual_induced=relative_residual(rows.A[n_mass:], polished, rows.b[n_mass:])
        if len(rows.b) > n_mass
        else 0.0,
    )


def _polish_masses(
    Am: np.ndarray,
    rhs: np.ndarray,
    full_mass: np.ndarray,
    sites: np.ndarray,
    mass: np.ndarray,
    top_mass: float,
) -> np.ndarray:
    """Masses meeting ``Am m = rhs`` to rounding, corrected on the heaviest sites that do it.

    Heavy sets from the heaviest (above 1e-3 of the largest mass) to every site are tried;
    the best nonnegative result wins (the first at rounding level ends the search).
    """
    best: tuple[float, np.ndarray] | None = None
    for level in (1e-3, 1e-6, 1e-9, 0.0):
        polished = polish_equal(Am, rhs, full_mass, sites[mass > level * top_mass])
        if np.any(polished < 0):
            continue
        residual = relative_residual(Am, polished, rhs) if len(rhs) else 0.0
        if best is None or residual < best[0]:
            best = (residual, polished)
        if residual < 1e-15:
            break
    if best is None:
        raise SolverError("masses: polishing made a site mass negative")
    return best[1]


def _holder_binding(setup: PhysicalSetup, kappa: float) -> Binding:
    """A holder at least as dense as the ballast: a part in its bore adds nothing (or less
    than nothing) to the inertia."""
    holder, ballast = setup.spec.holder, setup.spec.ballast
    assert holder is not None
    return Binding(
        "masses",
        f"a {holder.name} holder ({fmt(holder.density)} kg/m^3) is at least as dense as the "
        f"{ballast.name} ballast ({fmt(ballast.density)} kg/m^3): a part in its bore adds "
        f"{fmt(kappa, PRECISE)} of its mass to the inertia; a lighter holder (pmi-foam, peek) "
        "or a denser ballast",
        "holder.material",
    )


def _holder_text(setup: PhysicalSetup, terms: WholeTerms) -> str:
    """The holder's share of the inertia, for a refusal (empty without a holder)."""
    holder = setup.spec.holder
    if holder is None:
        return ""
    sphere = 0.4 * holder.density * 4.0 / 3.0 * math.pi * terms.largest**5
    return (
        f"; the {holder.name} holder (radius up to {fmt(terms.largest)} m) adds up to "
        f"{fmt(sphere)} kg m^2 to each moment against C = {fmt(setup.params.C, PRECISE)} "
        "kg m^2: a lighter holder (pmi-foam) or a smaller body reaches further"
    )


def _mass_binding(
    setup: PhysicalSetup, s: float, carrier_sites: np.ndarray, terms: WholeTerms
) -> Binding:
    """Why the second stage is infeasible: the carriers' mass, the ballast's room, or the
    magnets' volume (each tried without the later ones; feasibility LPs, HiGHS)."""
    Am, bm = setup.systems["masses"]
    free = np.setdiff1d(np.arange(len(setup.points)), carrier_sites)
    rhs = (
        bm
        - terms.initial()
        - Am[:, carrier_sites] @ np.full(len(carrier_sites), setup.carrier_mass)
    )
    Am = terms.kappa(setup.spec.ballast.density) * Am
    scale = _unknown_scale(Am[:, free], rhs) or 1.0
    Ams, bms = row_scaled(Am[:, free], rhs, scale)
    v_cap = 4.0 / 3.0 * math.pi * setup.cell_radius[free] ** 3 * (1 - DESIGN_MARGIN)

    def feasible(room: bool) -> bool:
        # w >= 0 (scaled ballast masses), Ams w = bms, and with room each mass within its cell
        bounds: Any = (0, None)
        if room:
            upper = v_cap * setup.spec.ballast.density / scale
            bounds = np.column_stack([np.zeros(len(free)), upper])
        res = linprog_highs(np.zeros(len(free)), A_eq=Ams, b_eq=bms, bounds=bounds)
        return res.status != 2  # 2: HiGHS proved the program infeasible

    carriers_c = float(
        setup.carrier_mass * np.sum(np.sum(setup.points[carrier_sites, :2] ** 2, axis=1))
    )
    if not feasible(room=False):
        return Binding(
            "masses",
            f"the {len(carrier_sites)} carriers ({fmt(setup.carrier_mass)} kg each, their own "
            f"C = {fmt(carriers_c)} kg m^2) leave no nonnegative ballast that makes A = B = 2C "
            f"with C = {fmt(setup.params.C, PRECISE)} kg m^2 and the centre of mass at O"
            + _holder_text(setup, terms),
            "holder" if setup.spec.holder is not None else "inertia",
        )
    if not feasible(room=True):
        return Binding(
            "masses",
            f"the {setup.spec.ballast.name} ballast that makes A = B = 2C (C = "
            f"{fmt(setup.params.C, PRECISE)} kg m^2) does not fit in the cells the "
            f"{len(carrier_sites)} carriers leave free",
            "ballast cells",
        )
    return _magnet_binding(setup, free)


def _magnet_binding(setup: PhysicalSetup, free: np.ndarray) -> Binding:
    """Why the magnets do not fit: the field demagnetises some cells, or no room at all."""
    magnet = setup.spec.magnet
    allowed = setup.magnet_sites[free]
    if not np.all(allowed):
        withstood = magnet.field_withstood() or 0.0
        where = (
            f"{int(np.sum(allowed))} of the {len(free)} free cells"
            if np.any(allowed)
            else "none of the free cells"
        )
        return Binding(
            "magnets",
            f"the magnets need more volume of {magnet.name} (M = {fmt(magnet.magnetisation)} A/m) "
            f"than {where} hold beside the ballast where the field stays below the "
            f"{fmt(withstood)} T a {magnet.name} magnet withstands (intrinsic coercivity less its "
            "own demagnetising field); a higher-coercivity grade (ndfeb-eh, smco) or a weaker "
            "field reaches further",
            "magnets.material",
        )
    return Binding(
        "magnets",
        f"the magnets need more volume of {magnet.name} (M = "
        f"{fmt(magnet.magnetisation)} A/m) than the free cells hold beside the ballast",
        "magnet cells",
    )
