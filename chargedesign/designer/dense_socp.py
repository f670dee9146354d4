"""A dense primal-dual interior-point solver for second-order-cone programs with 4-dim cones.

The problem (all cones of the second-order part have dimension 4)::

    minimise    c^T x
    subject to  A x = b
                G_lin x + s_lin = h_lin,         s_lin >= 0
                G_soc[i] x + s_soc[i] = h_soc[i], s_soc[i] in Q4 = {s : s0 >= ||s[1:]||}

Its dual: maximise ``-b^T y - h_lin^T z_lin - sum_i h_soc[i]^T z_soc[i]`` subject to
``c + A^T y + G_lin^T z_lin + sum_i G_soc[i]^T z_soc[i] = 0``, ``z_lin >= 0``, ``z_soc[i]`` in Q4.

Why a solver of its own: the problems of the charge design have few variables (hundreds) but
thousands of dense cone rows (every field row depends on every charge). A sparse solver
factors the large augmented system; here every iteration forms the small normal matrix
``G^T W^-2 G`` (one dense gram product over the columns shared by several cones, over 3 rows
a cone where their first rows vanish, 4-vector products for a column private to one cone;
the linear rows' part from their listed pairs of entries) and factors it by Cholesky (the
unknowns with a diagonal block, the charges' cost variables, eliminated first), all cone
operations vectorised over the cones (arrays of shape ``(m, 4)``). Meant for a few hundred
variables: the factorisation is dense, ``O(n^3)`` per iteration.

The method is the infeasible-start path-following method of CVXOPT's ``coneqp`` (L.
Vandenberghe, *The CVXOPT linear and quadratic cone program solvers*, 2010): Nesterov-Todd
scaling, Mehrotra predictor-corrector, starting point of ``conelp`` (least-squares ``x`` and
``z`` shifted into the cones). It proves nothing about infeasibility: anything other than
convergence (stall, iteration limit, numerical breakdown, diverging iterates) returns status
``"not_solved"`` quickly, and the caller falls back to a solver that decides infeasibility.

Conventions (checked by the tests): the scaling ``W`` is symmetric and satisfies
``W z = W^-1 s = lambda``, hence ``W^2 z = s``; the Jordan product of the Lorentz cone is
``u o v = (u . v, u0 v1 + v0 u1)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.linalg import lapack

#: fraction of the step to the boundary of the cones that an iteration takes
STEP_FRACTION = 0.99
#: the Mehrotra centring exponent (sigma = (gap after the affine step / gap)^3)
CENTRING_EXPONENT = 3
#: iterations without an improvement of the merit that count as a stall
STALL_ITERATIONS = 5
#: factor by which the merit must fall to count as an improvement
STALL_FACTOR = 0.9
#: a residual this many times the relative gap (after a few iterations) means infeasibility
RESIDUAL_OVER_GAP = 1e4
#: iterates beyond this norm mean an unbounded or infeasible problem
DIVERGENCE_NORM = 1e13
#: static regularisations of the normal matrix tried in turn (relative to its largest diagonal
#: entry): a larger one costs accuracy that the refinement must win back
REGULARISATIONS = (1e-16, 1e-12, 1e-8)
#: refinement steps of each Newton direction against the whole Newton system
NEWTON_REFINEMENTS = 1
#: refinement steps of each solve of the reduced (normal) system
NORMAL_REFINEMENTS = 1
#: relative threshold on the pivots of the rank-revealing QR of A
RANK_TOLERANCE = 1e-10


@dataclass
class DenseSocpSolution:
    """Result of :func:`solve_dense_socp`.

    Attributes
    ----------
    status : str
        ``"solved"`` (every relative residual below ``tol``) or ``"not_solved"``.
    x, y, z_lin, z_soc : numpy.ndarray
        Primal point, equality duals (one per row of ``A``; zero on dropped dependent rows),
        duals of the linear inequalities and of the cones (shape ``(m, 4)``).
    primal_objective, dual_objective : float
        ``c^T x`` and ``-b^T y - h^T z`` (a lower bound when the dual residual is small).
    iterations : int
        Interior-point iterations taken.
    residuals : dict[str, float]
        The relative ``primal``, ``dual`` and ``gap`` residuals of the returned point (see
        :func:`solve_dense_socp`).
    """

    status: str
    x: np.ndarray
    y: np.ndarray
    z_lin: np.ndarray
    z_soc: np.ndarray
    primal_objective: float
    dual_objective: float
    iterations: int
    residuals: dict[str, float]


# ---------------------------------------------------------------- cone algebra (vectorised)


def row_norms(v: np.ndarray) -> np.ndarray:
    """The Euclidean norm of each row of ``v`` (shape ``(m, k)``): ``np.linalg.norm(v,
    axis=1)``'s own formula for real rows, to the bit, without its argument handling (it
    runs some 1,500 times in one frontier point's cone programs)."""
    return np.sqrt(np.add.reduce(v * v, axis=1))


def lorentz_det(u: np.ndarray) -> np.ndarray:
    """``u0^2 - ||u[1:]||^2`` of each row of ``u`` (shape ``(m, 4)``), without cancellation."""
    norm1 = row_norms(u[:, 1:])
    return (u[:, 0] - norm1) * (u[:, 0] + norm1)


def jordan_product(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The Jordan product ``u o v = (u . v, u0 v1 + v0 u1)`` of each pair of rows."""
    out = np.empty_like(u)
    out[:, 0] = np.einsum("ij,ij->i", u, v)
    out[:, 1:] = u[:, :1] * v[:, 1:] + v[:, :1] * u[:, 1:]
    return out


def jordan_divide(lam: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The ``x`` with ``lam o x = v`` for each pair of rows (``lam`` inside the cone)."""
    out = np.empty_like(v)
    dot1 = np.einsum("ij,ij->i", lam[:, 1:], v[:, 1:])
    out[:, 0] = (lam[:, 0] * v[:, 0] - dot1) / lorentz_det(lam)
    out[:, 1:] = (v[:, 1:] - out[:, :1] * lam[:, 1:]) / lam[:, :1]
    return out


@dataclass
class NtScaling:
    """Nesterov-Todd scaling of the linear part (diagonal ``d``) and of the cones.

    The cone part is ``W_i = eta_i * Wbar_i`` with ``Wbar_i`` the Lorentz boost of ``wbar_i``
    (``wbar_i^T J wbar_i = 1``); ``W z = W^-1 s = lam`` on every cone.
    """

    d: np.ndarray
    eta: np.ndarray
    wbar: np.ndarray
    lam_lin: np.ndarray
    lam_soc: np.ndarray
    #: ``1 + wbar_0`` and ``1 / eta`` of every cone, formed once: :meth:`apply` runs some 20
    #: times per iteration on the same scaling
    one_plus_w0: np.ndarray = field(init=False)
    inverse_eta: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.one_plus_w0 = 1.0 + self.wbar[:, 0]
        self.inverse_eta = 1.0 / self.eta

    def apply(self, v: np.ndarray, inverse: bool = False) -> np.ndarray:
        """``W v`` (or ``W^-1 v``) for cone vectors ``v`` of shape ``(m, 4)`` or ``(m, 4, n)``.

        ``W^-1`` flips the sign of ``w1``'s terms: written as subtractions, which are the
        additions of the negated terms to the bit."""
        if v.ndim == 3:
            return np.matmul(self.matrices(inverse), v)
        w0, w1 = self.wbar[:, 0], self.wbar[:, 1:]
        v0 = v[:, 0]
        t = np.einsum("ij,ij->i", w1, v[:, 1:])
        out = np.empty_like(v)
        if inverse:
            np.subtract(w0 * v0, t, out=out[:, 0])
            out[:, 1:] = v[:, 1:] + (t / self.one_plus_w0 - v0)[:, None] * w1
            out *= self.inverse_eta[:, None]
        else:
            np.add(w0 * v0, t, out=out[:, 0])
            out[:, 1:] = v[:, 1:] + (v0 + t / self.one_plus_w0)[:, None] * w1
            out *= self.eta[:, None]
        return out

    def matrices(self, inverse: bool = False) -> np.ndarray:
        """The ``(m, 4, 4)`` matrices ``W_i`` (or their inverses ``J W_i J / eta_i^2``)."""
        w0, w1 = self.wbar[:, 0], self.wbar[:, 1:]
        sign = -1.0 if inverse else 1.0
        out = np.empty((w0.size, 4, 4))
        out[:, 0, 0] = w0
        out[:, 0, 1:] = sign * w1
        out[:, 1:, 0] = sign * w1
        out[:, 1:, 1:] = w1[:, :, None] * (w1 / self.one_plus_w0[:, None])[:, None, :]
        out[:, 1:, 1:] += np.eye(3)
        scale = self.inverse_eta if inverse else self.eta
        out *= scale[:, None, None]
        return out


def nt_scaling(
    s_lin: np.ndarray, z_lin: np.ndarray, s_soc: np.ndarray, z_soc: np.ndarray
) -> NtScaling:
    """The Nesterov-Todd scaling of the interior pair ``(s, z)`` (Vandenberghe 2010, 4.3)."""
    d = np.sqrt(s_lin / z_lin)
    det_s, det_z = lorentz_det(s_soc), lorentz_det(z_soc)
    s_bar = s_soc / np.sqrt(det_s)[:, None]
    z_bar = z_soc / np.sqrt(det_z)[:, None]
    gamma = np.sqrt(0.5 * (1.0 + np.einsum("ij,ij->i", s_bar, z_bar)))
    wbar = np.empty_like(s_soc)
    wbar[:, 0] = s_bar[:, 0] + z_bar[:, 0]
    wbar[:, 1:] = s_bar[:, 1:] - z_bar[:, 1:]
    wbar /= 2.0 * gamma[:, None]
    eta = (det_s / det_z) ** 0.25
    scaling = NtScaling(d, eta, wbar, np.sqrt(s_lin * z_lin), np.empty_like(s_soc))
    scaling.lam_soc = scaling.apply(z_soc)
    return scaling


def max_step_lin(x: np.ndarray, dx: np.ndarray) -> float:
    """Largest ``a >= 0`` with ``x + a dx >= 0`` (``inf`` when unbounded)."""
    neg = dx < 0
    if not np.any(neg):
        return np.inf
    return float(np.min(-x[neg] / dx[neg]))


def max_step_soc(x: np.ndarray, dx: np.ndarray) -> float:
    """Largest ``a >= 0`` with every ``x[i] + a dx[i]`` in the cone (``x`` interior).

    The boundary is the smallest positive root of the quadratic ``det(x + a dx) = 0``,
    computed in the cancellation-free form on every cone at once.
    """
    if x.shape[0] == 0:
        return np.inf
    a = lorentz_det(dx)
    b = 2.0 * (x[:, 0] * dx[:, 0] - np.einsum("ij,ij->i", x[:, 1:], dx[:, 1:]))
    c = np.maximum(lorentz_det(x), 0.0)
    disc = b * b - 4.0 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -b - np.copysign(np.sqrt(np.maximum(disc, 0.0)), b)
        roots = np.stack([2.0 * c / t, t / (2.0 * a)])
    roots[~np.isfinite(roots) | (roots < 0)] = np.inf
    step = roots.min(axis=0)
    # no boundary crossing: the direction keeps the point in the cone for every a >= 0
    step[((a > 0) & (b > 0)) | (disc < 0)] = np.inf
    # a point already on the boundary (c = 0) moving outwards cannot move at all
    step[(c == 0) & (b < 0)] = 0.0
    return float(step.min())


def shift_into_cones(s_lin: np.ndarray, s_soc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``s + (1 + t) e`` with ``t`` the largest violation (CVXOPT's ``conelp`` start).

    Unchanged when ``s`` is well inside every cone.
    """
    lowest = [np.inf]
    if s_lin.size:
        lowest.append(float(s_lin.min()))
    if s_soc.size:
        lowest.append(float(np.min(s_soc[:, 0] - row_norms(s_soc[:, 1:]))))
    t = -min(lowest)
    norm = float(np.sqrt(np.sum(s_lin**2) + np.sum(s_soc**2)))
    if t < -1e-8 * max(norm, 1.0):
        return s_lin, s_soc
    s_soc = s_soc.copy()
    s_soc[:, 0] += 1.0 + t
    return s_lin + (1.0 + t), s_soc


# ---------------------------------------------------------------- problem data


def index_block(index: np.ndarray) -> slice | np.ndarray:
    """``index`` as a slice when it is a contiguous run (a view instead of a gather)."""
    if index.size and index[-1] - index[0] + 1 == index.size:
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


def block(rows: np.ndarray, cols: np.ndarray) -> tuple:
    """The index of the block ``M[rows][:, cols]`` (slices where the indices are runs)."""
    r, c = index_block(rows), index_block(cols)
    if isinstance(r, slice) and isinstance(c, slice):
        return r, c
    return np.ix_(rows, cols)


def gram(Y: np.ndarray) -> np.ndarray:
    """``Y^T Y`` of the rows of ``Y`` of shape ``(m, r, s)`` (all ``m r`` rows)."""
    rows = Y.reshape(-1, Y.shape[-1])
    return rows.T @ rows


class ConeColumns:
    """Where the variables enter the cones, to form ``G_soc^T W^-2 G_soc`` cheaply.

    A column of ``G_soc`` is *shared* (nonzero in two or more cones), *private* (nonzero in
    exactly one cone, as an epigraph variable of that cone) or absent. Only the shared
    columns need the dense gram product; a private column's products are 4-vectors.

    Most shared columns (the charges) are zero in the first row of every cone: on those,
    ``W_i^-2`` enters only through its lower ``3 x 3`` block ``(I + 2 w w^T) / eta^2``
    (``w`` the spatial part of the scaling point), whose square root ``R_i = (I + c w w^T) /
    eta`` gives a gram product over ``3 m`` rows instead of ``4 m``. The products ``G_soc x``
    and ``G_soc^T z`` use the same blocks (the absent columns, the charges' cost variables,
    and the zero first rows skipped).
    """

    def __init__(self, G_soc: np.ndarray):
        m = G_soc.shape[0]
        nonzero = G_soc != 0.0
        in_cone = np.any(nonzero, axis=1)
        count = in_cone.sum(axis=0)
        self.n = G_soc.shape[2]
        self.m = m
        self.shared = np.flatnonzero(count >= 2)
        self.private = np.flatnonzero(count == 1)
        self.owner = np.argmax(in_cone[:, self.private], axis=0) if in_cone.size else self.private
        self.g_private = G_soc[self.owner, :, self.private]
        self.G_owner_shared = G_soc[self.owner][:, :, self.shared]
        # the shared columns without (zero) and with (full) a first row
        first_row = np.any(nonzero[:, 0, self.shared], axis=0)
        self.zero, self.full = self.shared[~first_row], self.shared[first_row]
        # a slice where the columns are a run: a copy without the gather
        self.G_zero = np.ascontiguousarray(G_soc[:, 1:, index_block(self.zero)])
        self.G_full = np.ascontiguousarray(G_soc[:, :, index_block(self.full)])
        self.zero_block = block(self.zero, self.zero)
        self.cross_block = block(self.zero, self.full)
        self.cross_block_T = block(self.full, self.zero)
        self.full_block = block(self.full, self.full)
        self.absent = np.flatnonzero(count == 0)
        self.zero_index = index_block(self.zero)
        self.full_index = index_block(self.full)
        self.G_zero_rows = self.G_zero.reshape(3 * m, self.zero.size)
        self.G_full_rows = self.G_full.reshape(4 * m, self.full.size)

    def times(self, x: np.ndarray) -> np.ndarray:
        """``G_soc x`` as ``(m, 4)`` (the absent columns and the zero first rows skipped)."""
        out = np.zeros((self.m, 4))
        if self.zero.size:
            out[:, 1:] = (self.G_zero_rows @ x[self.zero_index]).reshape(self.m, 3)
        if self.full.size:
            out += (self.G_full_rows @ x[self.full_index]).reshape(self.m, 4)
        if self.private.size:
            np.add.at(out, self.owner, self.g_private * x[self.private][:, None])
        return out

    def transposed_times(self, z_soc: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``out + G_soc^T z`` (``out`` updated in place)."""
        if self.zero.size:
            out[self.zero_index] += self.G_zero_rows.T @ z_soc[:, 1:].ravel()
        if self.full.size:
            out[self.full_index] += self.G_full_rows.T @ z_soc.ravel()
        if self.private.size:
            out[self.private] += np.einsum("pk,pk->p", self.g_private, z_soc[self.owner])
        return out

    def transposed_times_pair(
        self, z_soc: np.ndarray, other: np.ndarray, out: np.ndarray
    ) -> np.ndarray:
        """``out + G_soc^T [z, other]`` (``out`` of shape ``(n, 2)``, updated in place): two
        products in one pass over the cone rows."""
        if self.zero.size:
            pair = np.stack([z_soc[:, 1:].ravel(), other[:, 1:].ravel()], axis=1)
            out[self.zero_index] += self.G_zero_rows.T @ pair
        if self.full.size:
            out[self.full_index] += self.G_full_rows.T @ np.stack(
                [z_soc.ravel(), other.ravel()], axis=1
            )
        if self.private.size:
            out[self.private, 0] += np.einsum("pk,pk->p", self.g_private, z_soc[self.owner])
            out[self.private, 1] += np.einsum("pk,pk->p", self.g_private, other[self.owner])
        return out

    def add_normal_matrix(self, M: np.ndarray, scaling: NtScaling | None) -> np.ndarray:
        """``M + G_soc^T W^-2 G_soc`` (``M`` updated in place; ``scaling`` None: W = I).

        The charge columns' block is ``(R G')^T (R G')`` with ``R_i^2`` the lower block of
        ``W_i^-2``; their cross block with the full columns, ``G'^T (W^-2 G_full)[1:]``, is
        ``(R G')^T (R^-1 (W^-2 G_full)[1:])``: both come from one gram product of the
        columns ``[R G', R^-1 (W^-2 G_full)[1:]]``, one pass over the cone rows.
        """
        nz, nf = self.zero.size, self.full.size
        square = None
        # the charge columns' rows (R G'), stacked with R^-1 (W^-2 G_full)[1:] when there are
        # full columns
        stacked = self.G_zero
        if scaling is None:
            Y_full = self.G_full
            if nf:
                stacked = np.concatenate([self.G_zero, self.G_full[:, 1:]], axis=2)
        else:
            w1 = scaling.wbar[:, 1:]
            norm_sq = np.einsum("ij,ij->i", w1, w1)
            c = 2.0 / (np.sqrt(1.0 + 2.0 * norm_sq) + 1.0)
            outer = w1[:, :, None] * w1[:, None, :]
            root = (c / scaling.eta)[:, None, None] * outer
            root += np.eye(3) / scaling.eta[:, None, None]
            if nf or self.private.size:  # the whole W^-2 (only the charge columns: none)
                inverse = scaling.matrices(inverse=True)
                square = np.matmul(inverse, inverse)
                Y_full = np.matmul(inverse, self.G_full)
            if nf:
                stacked = np.empty((self.m, 3, nz + nf))
                np.matmul(root, self.G_zero, out=stacked[:, :, :nz])
                root_inverse = (-c / (1.0 + c * norm_sq) * scaling.eta)[:, None, None] * outer
                root_inverse += np.eye(3) * scaling.eta[:, None, None]
                assert square is not None  # formed above: there are full columns
                P = np.matmul(square[:, 1:], self.G_full)
                np.matmul(root_inverse, P, out=stacked[:, :, nz:])
            else:
                stacked = np.matmul(root, self.G_zero)
        if nf:
            M[self.full_block] += gram(Y_full)
        if nz and nf:
            both = gram(stacked)
            M[self.zero_block] += both[:nz, :nz]
            M[self.cross_block] += both[:nz, nz:]
            M[self.cross_block_T] += both[nz:, :nz]
        elif nz:
            M[self.zero_block] += gram(stacked)
        if self.private.size:
            h = (
                self.g_private
                if square is None
                else np.einsum("pij,pj->pi", square[self.owner], self.g_private)
            )
            cross = np.einsum("pk,pks->ps", h, self.G_owner_shared)
            M[np.ix_(self.private, self.shared)] += cross
            M[np.ix_(self.shared, self.private)] += cross.T
            same_cone = self.owner[:, None] == self.owner[None, :]
            M[np.ix_(self.private, self.private)] += (h @ self.g_private.T) * same_cone
        return M


class LinearGram:
    """``G_lin^T D^-2 G_lin`` for a sparse ``G_lin`` whose rows have few entries (the
    charges' bounds: one or two per row), without sparse products.

    Each pair of entries ``(r, a)``, ``(r, b)`` of a row ``r`` adds ``G_ra G_rb / d_r^2`` to
    ``M[a, b]``: the pairs and their products are listed once per program and each iteration
    sums the weighted products into place. Rows with many entries (a dense ``G_lin``) use
    one BLAS product instead.
    """

    #: pairs per unknown squared beyond which the dense product is cheaper
    DENSE_PAIRS = 0.25

    def __init__(self, G_lin: sp.csr_matrix):
        self.n = G_lin.shape[1]
        per_row = np.diff(G_lin.indptr)
        pairs = int(np.sum(per_row.astype(np.int64) ** 2))
        self.dense = pairs > self.DENSE_PAIRS * self.n * self.n
        if self.dense:
            self.G = G_lin.toarray()
            return
        rows = np.repeat(np.arange(G_lin.shape[0]), per_row)  # the row of each entry
        partners = per_row[rows]  # the entries of its row, itself included
        # every entry (first) against every entry of its row (second)
        first = np.repeat(np.arange(G_lin.nnz), partners)
        offset = np.arange(first.size) - np.repeat(np.cumsum(partners) - partners, partners)
        second = G_lin.indptr[rows[first]] + offset
        self.row = rows[first]
        self.first = G_lin.indices[first]
        self.second = G_lin.indices[second]
        self.flat = self.first * self.n + self.second
        self.product = G_lin.data[first] * G_lin.data[second]

    def matrix(self, d: np.ndarray) -> np.ndarray:
        """``G_lin^T diag(d)^-2 G_lin`` as a dense ``n x n`` array."""
        if self.dense:
            scaled = self.G / d[:, None]
            return scaled.T @ scaled
        weights = self.product / (d * d)[self.row]
        M = np.bincount(self.flat, weights, minlength=self.n * self.n)
        return M.reshape(self.n, self.n).astype(float, copy=False)


@dataclass
class ShapedProgram:
    """The data of the problem, checked and shaped (``A`` with independent rows only)."""

    c: np.ndarray
    A: np.ndarray
    b: np.ndarray
    G_lin: sp.csr_matrix
    h_lin: np.ndarray
    G_soc: np.ndarray
    h_soc: np.ndarray
    columns: ConeColumns = field(init=False)
    lin_gram: LinearGram = field(init=False)
    G_lin_T: sp.csr_matrix = field(init=False)
    AtA: np.ndarray = field(init=False)
    split: tuple[np.ndarray, np.ndarray] | None = field(init=False)

    def __post_init__(self) -> None:
        with np.errstate(all="ignore"):  # data that is not finite is refused on its own
            self.columns = ConeColumns(self.G_soc)
            self.lin_gram = LinearGram(self.G_lin)
            self.G_lin_T = self.G_lin.T.tocsr()
            self.keep_rows(np.arange(self.b.size))
            self.split = diagonal_split(self)

    def keep_rows(self, keep: np.ndarray) -> None:
        """Keep only the rows ``keep`` of ``A x = b``."""
        self.A, self.b = self.A[keep], self.b[keep]
        self.AtA = self.A.T @ self.A

    def G_times(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``G x``, split into the linear rows and the cones ``(m, 4)``."""
        return self.G_lin @ x, self.columns.times(x)

    def GT_times(self, z_lin: np.ndarray, z_soc: np.ndarray) -> np.ndarray:
        """``G^T z``."""
        return self.columns.transposed_times(z_soc, self.G_lin_T @ z_lin)

    def GT_times_pair(
        self, z: tuple[np.ndarray, np.ndarray], other: tuple[np.ndarray, np.ndarray]
    ) -> tuple[np.ndarray, np.ndarray]:
        """``G^T z`` and ``G^T other`` (each a pair of linear and cone parts) in one pass."""
        out = np.asarray(self.G_lin_T @ np.stack([z[0], other[0]], axis=1), dtype=float)
        out = self.columns.transposed_times_pair(z[1], other[1], out)
        return out[:, 0], out[:, 1]


def diagonal_split(program: ShapedProgram) -> tuple[np.ndarray, np.ndarray] | None:
    """``(rest, diagonal)``: the unknowns whose block of the normal matrix is diagonal at every
    scaling (in no cone, no equality, and no linear row with another of them: the charges'
    cost variables ``w >= |u|``) and the others; None when either is empty.

    The factorisation eliminates the diagonal block first: a Cholesky of the rest's Schur
    complement (half the charges' unknowns) instead of the whole normal matrix.
    """
    gram = program.lin_gram
    if gram.dense:
        return None
    n = program.c.size
    candidate = np.zeros(n, dtype=bool)
    candidate[program.columns.absent] = True
    candidate &= ~np.any(program.A != 0.0, axis=0)
    coupled = (gram.first != gram.second) & candidate[gram.first] & candidate[gram.second]
    candidate[gram.first[coupled]] = False
    if candidate.all() or not candidate.any():
        return None
    return np.flatnonzero(~candidate), np.flatnonzero(candidate)


def independent_rows(A: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, bool]:
    """Indices of a maximal independent set of rows of ``A`` and whether ``A x = b`` is
    consistent (rank-revealing QR of ``A^T`` with column pivoting)."""
    if A.shape[0] == 0:
        return np.arange(0), True
    _, r, perm = la.qr(A.T, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > RANK_TOLERANCE * max(diag[0], 1e-300))) if diag.size else 0
    keep = np.sort(perm[:rank])
    if rank == A.shape[0]:
        return keep, True
    x0 = np.linalg.lstsq(A[keep], b[keep], rcond=None)[0]
    scale = max(1.0, float(np.abs(b).max()), float(np.abs(A).max() * np.abs(x0).max()))
    return keep, bool(np.abs(A @ x0 - b).max() <= 1e3 * RANK_TOLERANCE * scale)


def as_cone_program(c, A, b, G_lin, h_lin, G_soc, h_soc) -> ShapedProgram:
    """The data as a :class:`ShapedProgram` of floats in the shapes the solver uses."""
    c = np.asarray(c, dtype=float).ravel()
    n = c.size
    return ShapedProgram(
        c,
        np.asarray(A.toarray() if sp.issparse(A) else A, dtype=float).reshape(-1, n),
        np.asarray(b, dtype=float).ravel(),
        sp.csr_matrix(sp.csr_matrix(G_lin, dtype=float).reshape(-1, n)),
        np.asarray(h_lin, dtype=float).ravel(),
        np.ascontiguousarray(np.asarray(G_soc, dtype=float).reshape(-1, 4, n)),
        np.asarray(h_soc, dtype=float).reshape(-1, 4),
    )


def is_finite(program: ShapedProgram) -> bool:
    """Whether every number of the data is finite."""
    arrays = (program.c, program.A, program.b, program.G_lin.data, program.h_lin)
    return all(np.all(np.isfinite(a)) for a in (*arrays, program.G_soc, program.h_soc))


# ---------------------------------------------------------------- the Newton systems


def cholesky(K: np.ndarray) -> tuple[np.ndarray, bool]:
    """Cholesky factor of ``K`` in the ``(factor, lower)`` form of ``scipy.linalg.cho_factor``
    (LAPACK directly: the wrappers' checks cost more than the factorisation here)."""
    factor, info = lapack.dpotrf(K, lower=False, clean=False, overwrite_a=False)
    if info != 0:
        raise np.linalg.LinAlgError("the matrix is not positive definite")
    return factor, False


def regularised_cholesky(K: np.ndarray) -> tuple[np.ndarray, bool]:
    """Cholesky factor of ``K + delta I`` with the smallest ``delta`` of
    :data:`REGULARISATIONS` (times the largest diagonal entry) that works (``K`` is
    overwritten), in the ``(factor, lower)`` form of ``scipy.linalg.cho_factor``."""
    diagonal = K.reshape(-1)[:: K.shape[0] + 1] if K.size else np.zeros(0)
    original = diagonal.copy()
    top = max(float(np.max(original)), 1.0) if K.size else 1.0
    for delta in REGULARISATIONS:
        diagonal[:] = original + delta * top
        try:
            return cholesky(K)
        except np.linalg.LinAlgError:
            continue
    raise np.linalg.LinAlgError("the normal matrix is not positive definite")


def cholesky_solve(factor: tuple[np.ndarray, bool], rhs: np.ndarray) -> np.ndarray:
    """``K^-1 rhs`` from :func:`cholesky`'s factor (``rhs`` a vector or columns)."""
    x, info = lapack.dpotrs(factor[0], rhs, lower=factor[1])
    if info != 0:
        raise np.linalg.LinAlgError("the normal matrix cannot be solved")
    return x


class NormalFactor:
    """``K + delta I`` factored, ``delta`` the smallest of :data:`REGULARISATIONS` (times the
    largest diagonal entry) that works; with a ``split`` (:func:`diagonal_split`), by
    eliminating the diagonal block ``D`` first::

        S = K_RR - K_RD K_DD^-1 K_DR  (Cholesky),   x_R = S^-1 (r_R - K_RD K_DD^-1 r_D),
        x_D = K_DD^-1 (r_D - K_DR x_R).
    """

    def __init__(self, K: np.ndarray, split: tuple[np.ndarray, np.ndarray] | None):
        self.split = split
        if split is None:
            self.factor = regularised_cholesky(K)
            return
        rest, diagonal = split
        self.rest, self.diagonal = index_block(rest), index_block(diagonal)
        k_dd = np.diag(K)[diagonal]
        self.K_RD = K[block(rest, diagonal)]
        K_RR = K[block(rest, rest)]
        top = max(float(np.max(np.diag(K))), 1.0)
        for delta in REGULARISATIONS:
            self.k_dd = k_dd + delta * top
            if not np.all(self.k_dd > 0):
                continue
            schur = K_RR - (self.K_RD / self.k_dd) @ self.K_RD.T
            schur.reshape(-1)[:: schur.shape[0] + 1] += delta * top
            try:
                self.factor = cholesky(schur)
                return
            except np.linalg.LinAlgError:
                continue
        raise np.linalg.LinAlgError("the normal matrix is not positive definite")

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """``(K + delta I)^-1 rhs`` (``rhs`` a vector or columns)."""
        if self.split is None:
            return cholesky_solve(self.factor, rhs)
        k_dd = self.k_dd if rhs.ndim == 1 else self.k_dd[:, None]
        scaled = rhs[self.diagonal] / k_dd
        x = np.empty_like(rhs, dtype=float)
        x[self.rest] = cholesky_solve(self.factor, rhs[self.rest] - self.K_RD @ scaled)
        x[self.diagonal] = scaled - (self.K_RD.T @ x[self.rest]) / k_dd
        return x


class NormalSystem:
    """The reduced KKT system ``[M A^T; A 0]`` with ``M = G^T W^-2 G``, factored once.

    ``M + A^T A`` (positive definite when ``[G; A]`` has full column rank) is factored by
    Cholesky with a tiny static regularisation, ``A`` enters through its Schur complement,
    and each solve is refined against the unregularised system.
    """

    def __init__(self, program: ShapedProgram, d: np.ndarray, scaling: NtScaling | None):
        self.M = program.lin_gram.matrix(d)
        if program.G_soc.shape[0]:
            program.columns.add_normal_matrix(self.M, scaling)
        self.A = program.A
        self.K = NormalFactor(self.M + program.AtA, program.split)
        if self.A.shape[0]:
            self.KA = self.K.solve(self.A.T)
            self.S = cholesky(self.A @ self.KA)

    def solve_once(self, r1: np.ndarray, r2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One solve with the regularised factors."""
        rhs = r1 + self.A.T @ r2
        x = self.K.solve(rhs)
        if not self.A.shape[0]:
            return x, np.zeros(0)
        y = cholesky_solve(self.S, self.A @ x - r2)
        return x - self.KA @ y, y

    def solve(
        self, r1: np.ndarray, r2: np.ndarray, refinements: int = NORMAL_REFINEMENTS
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(x, y)`` with ``M x + A^T y = r1`` and ``A x = r2``."""
        x, y = self.solve_once(r1, r2)
        for _ in range(refinements):
            e1 = r1 - self.M @ x - self.A.T @ y
            e2 = r2 - self.A @ x
            dx, dy = self.solve_once(e1, e2)
            x, y = x + dx, y + dy
        return x, y


@dataclass
class Point:
    """A primal-dual point, or a direction: ``x, y`` and the slacks and duals of the cones."""

    x: np.ndarray
    y: np.ndarray
    s_lin: np.ndarray
    z_lin: np.ndarray
    s_soc: np.ndarray
    z_soc: np.ndarray

    def moved(self, step: float, d: Point) -> Point:
        """``self + step * d``."""
        return Point(
            self.x + step * d.x,
            self.y + step * d.y,
            self.s_lin + step * d.s_lin,
            self.z_lin + step * d.z_lin,
            self.s_soc + step * d.s_soc,
            self.z_soc + step * d.z_soc,
        )

    def gap(self) -> float:
        """``s^T z``."""
        return float(self.s_lin @ self.z_lin + np.sum(self.s_soc * self.z_soc))

    def max_step(self, d: Point) -> float:
        """Largest step along ``d`` keeping ``s`` and ``z`` in their cones."""
        # s and z at once: the same elementwise roots, half the calls
        return min(
            max_step_lin(
                np.concatenate([self.s_lin, self.z_lin]), np.concatenate([d.s_lin, d.z_lin])
            ),
            max_step_soc(
                np.concatenate([self.s_soc, self.z_soc]), np.concatenate([d.s_soc, d.z_soc])
            ),
        )


@dataclass
class Residuals:
    """The residuals of a point: vectors, objectives and the relative measures."""

    rx: np.ndarray
    ry: np.ndarray
    rz_lin: np.ndarray
    rz_soc: np.ndarray
    primal_objective: float
    dual_objective: float
    relative: dict[str, float]
    #: ``G^T u`` of the affine direction's elimination (:func:`residuals` with a scaling)
    affine_product: np.ndarray | None = None

    def merit(self) -> float:
        """The largest relative residual (``nan`` propagates as ``inf``)."""
        worst = max(self.relative.values())
        return worst if np.isfinite(worst) else np.inf


def inf_norm(*arrays: np.ndarray) -> float:
    """The largest absolute entry of the arrays (0 when all are empty)."""
    return max([float(np.abs(a).max()) for a in arrays if a.size] + [0.0])


def residuals(program: ShapedProgram, p: Point, scaling: NtScaling | None = None) -> Residuals:
    """Residuals and relative measures of ``p`` (defined in :func:`solve_dense_socp`).

    With the ``scaling`` at ``p``, the product ``G^T u`` that the affine direction's
    elimination needs (:func:`affine_rhs`, :func:`eliminated`) is formed in the same pass
    over the cone rows as ``G^T z``.
    """
    Gx_lin, Gx_soc = program.G_times(p.x)
    ry = program.A @ p.x - program.b
    rz_lin = Gx_lin + p.s_lin - program.h_lin
    rz_soc = Gx_soc + p.s_soc - program.h_soc
    affine_product = None
    if scaling is None:
        GTz = program.GT_times(p.z_lin, p.z_soc)
    else:
        rhs = affine_rhs(scaling, np.zeros_like(p.x), ry, rz_lin, rz_soc)
        _, _, u_lin, u_soc = eliminated(scaling, rhs)
        GTz, affine_product = program.GT_times_pair((p.z_lin, p.z_soc), (u_lin, u_soc))
    rx = program.c + program.A.T @ p.y + GTz
    pobj = float(program.c @ p.x)
    dobj = -float(program.b @ p.y + program.h_lin @ p.z_lin + np.sum(program.h_soc * p.z_soc))
    data = inf_norm(program.b, program.h_lin, program.h_soc)
    primal_scale = max(1.0, data + inf_norm(p.x) + inf_norm(p.s_lin, p.s_soc))
    dual_scale = max(1.0, inf_norm(program.c) + inf_norm(p.y, p.z_lin, p.z_soc))
    gap = max(abs(pobj - dobj), p.gap())
    relative = {
        "primal": inf_norm(ry, rz_lin, rz_soc) / primal_scale,
        "dual": inf_norm(rx) / dual_scale,
        "gap": gap / max(1.0, min(abs(pobj), abs(dobj))),
    }
    return Residuals(rx, ry, rz_lin, rz_soc, pobj, dobj, relative, affine_product)


@dataclass
class NewtonRhs:
    """Right-hand side of the Newton system (see :func:`newton_direction`)."""

    rx: np.ndarray
    ry: np.ndarray
    rz_lin: np.ndarray
    rz_soc: np.ndarray
    rs_lin: np.ndarray
    rs_soc: np.ndarray


def newton_direction(
    program: ShapedProgram,
    system: NormalSystem,
    scaling: NtScaling,
    rhs: NewtonRhs,
    dual_part: tuple[np.ndarray, np.ndarray] | None = None,
    product: np.ndarray | None = None,
) -> Point:
    """The solution ``d`` of the Newton system, eliminating ``ds`` and ``dz``::

    A^T dy + G^T dz = rx,   A dx = ry,   G dx + ds = rz,   lam o (W dz + W^-1 ds) = rs.

    With ``dual_part`` ``(z_lin, z_soc)`` the first block's right-hand side is
    ``rx - G^T dual_part``, its product folded into the elimination's own ``G^T`` product;
    ``product`` is that product formed already (:func:`residuals`).
    """
    d = scaling.d
    v_lin, v_soc, u_lin, u_soc = eliminated(scaling, rhs)
    if product is None:
        if dual_part is not None:
            u_lin, u_soc = u_lin + dual_part[0], u_soc + dual_part[1]
        product = program.GT_times(u_lin, u_soc)
    r1 = rhs.rx - product
    dx, dy = system.solve(r1, rhs.ry)
    Gdx_lin, Gdx_soc = program.G_times(dx)
    dz_lin = (Gdx_lin / d + v_lin) / d
    dz_soc = scaling.apply(scaling.apply(Gdx_soc, True) + v_soc, True)
    return Point(dx, dy, rhs.rz_lin - Gdx_lin, dz_lin, rhs.rz_soc - Gdx_soc, dz_soc)


def eliminated(
    scaling: NtScaling, rhs: NewtonRhs
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``v`` (the eliminated ``W dz`` less ``W^-1 G dx``) and ``u = W^-1 v`` of both parts,
    whose ``G^T u`` enters the reduced system's right-hand side."""
    v_lin = rhs.rs_lin / scaling.lam_lin - rhs.rz_lin / scaling.d
    v_soc = jordan_divide(scaling.lam_soc, rhs.rs_soc) - scaling.apply(rhs.rz_soc, True)
    return v_lin, v_soc, v_lin / scaling.d, scaling.apply(v_soc, True)


def affine_rhs(
    scaling: NtScaling, rx: np.ndarray, ry: np.ndarray, rz_lin: np.ndarray, rz_soc: np.ndarray
) -> NewtonRhs:
    """The affine (predictor) right-hand side at residuals ``r`` and scaling ``lam``."""
    lam_sq_lin = scaling.lam_lin**2
    lam_sq_soc = jordan_product(scaling.lam_soc, scaling.lam_soc)
    return NewtonRhs(-rx, -ry, -rz_lin, -rz_soc, -lam_sq_lin, -lam_sq_soc)


def newton_residual(
    program: ShapedProgram,
    scaling: NtScaling,
    rhs: NewtonRhs,
    d: Point,
    dual_product: bool = True,
) -> NewtonRhs:
    """What ``d`` misses of each block of the Newton system, for a ``d`` built by
    :func:`newton_direction` (which meets ``G dx + ds = rz`` by construction); without
    ``dual_product`` the first block leaves out ``- G^T dz`` (for ``dual_part``)."""
    scaled_soc = scaling.apply(d.z_soc) + scaling.apply(d.s_soc, True)
    scaled_lin = d.z_lin * scaling.d + d.s_lin / scaling.d
    rx = rhs.rx - program.A.T @ d.y
    if dual_product:
        rx = rx - program.GT_times(d.z_lin, d.z_soc)
    return NewtonRhs(
        rx,
        rhs.ry - program.A @ d.x,
        np.zeros_like(rhs.rz_lin),
        np.zeros_like(rhs.rz_soc),
        rhs.rs_lin - scaling.lam_lin * scaled_lin,
        rhs.rs_soc - jordan_product(scaling.lam_soc, scaled_soc),
    )


def refined_newton_direction(
    program: ShapedProgram,
    system: NormalSystem,
    scaling: NtScaling,
    rhs: NewtonRhs,
    refinements: int = NEWTON_REFINEMENTS,
) -> Point:
    """:func:`newton_direction` with iterative refinement on the whole Newton system (the
    elimination loses the dual residual's accuracy as ``W`` grows ill-conditioned). The
    residual's ``G^T dz`` and the correction's own ``G^T`` product are one product."""
    d = newton_direction(program, system, scaling, rhs)
    for _ in range(refinements):
        residual = newton_residual(program, scaling, rhs, d, dual_product=False)
        correction = newton_direction(
            program, system, scaling, residual, dual_part=(d.z_lin, d.z_soc)
        )
        d = d.moved(1.0, correction)
    return d


def predictor_corrector_step(
    program: ShapedProgram, p: Point, res: Residuals, scaling: NtScaling | None = None
) -> Point:
    """One Mehrotra predictor-corrector iteration from the interior point ``p`` (``res``
    and ``scaling`` at ``p``; the scaling computed here when not given)."""
    if scaling is None:
        scaling = nt_scaling(p.s_lin, p.z_lin, p.s_soc, p.z_soc)
    system = NormalSystem(program, scaling.d, scaling)
    rhs = affine_rhs(scaling, res.rx, res.ry, res.rz_lin, res.rz_soc)
    lam_sq_lin, lam_sq_soc = -rhs.rs_lin, -rhs.rs_soc
    # the affine direction only sets the centring and the second-order term: no refinement
    affine = newton_direction(program, system, scaling, rhs, product=res.affine_product)
    step = min(1.0, p.max_step(affine))
    gap = p.gap()
    sigma = min(1.0, max(0.0, p.moved(step, affine).gap() / gap)) ** CENTRING_EXPONENT
    mu = gap / (p.s_lin.size + p.s_soc.shape[0])
    # second-order term (W^-1 ds_a) o (W dz_a) of the complementarity
    cross_lin = (affine.s_lin / scaling.d) * (affine.z_lin * scaling.d)
    cross_soc = jordan_product(scaling.apply(affine.s_soc, True), scaling.apply(affine.z_soc))
    rhs.rs_lin = -lam_sq_lin - cross_lin + sigma * mu
    rhs.rs_soc = -lam_sq_soc - cross_soc
    rhs.rs_soc[:, 0] += sigma * mu
    direction = refined_newton_direction(program, system, scaling, rhs)
    step = min(1.0, STEP_FRACTION * p.max_step(direction))
    return p.moved(step, direction)


def starting_point(program: ShapedProgram) -> Point:
    """CVXOPT's ``conelp`` start: ``x`` minimising ``||G x - h||`` on ``A x = b``, ``z``
    of least norm with ``G^T z + A^T y + c = 0``, both shifted into the cones."""
    system = NormalSystem(program, np.ones(program.h_lin.size), None)
    x, _ = system.solve(program.GT_times(program.h_lin, program.h_soc), program.b)
    u, y = system.solve(-program.c, np.zeros(program.b.size))
    Gx_lin, Gx_soc = program.G_times(x)
    s_lin, s_soc = shift_into_cones(program.h_lin - Gx_lin, program.h_soc - Gx_soc)
    z_lin, z_soc = shift_into_cones(*program.G_times(u))
    return Point(x, y, s_lin, z_lin, s_soc, z_soc)


def is_interior(p: Point) -> bool:
    """Whether every slack and dual is finite and strictly inside its cone."""
    finite = all(np.all(np.isfinite(v)) for v in (p.x, p.y, p.s_lin, p.z_lin, p.s_soc, p.z_soc))
    return (
        finite
        and bool(np.all(p.s_lin > 0) and np.all(p.z_lin > 0))
        and bool(np.all(lorentz_det(p.s_soc) > 0) and np.all(p.s_soc[:, 0] > 0))
        and bool(np.all(lorentz_det(p.z_soc) > 0) and np.all(p.z_soc[:, 0] > 0))
    )


def hopeless(res: Residuals, p: Point, iteration: int) -> bool:
    """Signs of an infeasible or unbounded problem: diverging iterates, or residuals that
    stay large while the gap closes."""
    if inf_norm(p.x, p.y, p.z_lin, p.z_soc, p.s_lin, p.s_soc) > DIVERGENCE_NORM:
        return True
    rel = res.relative
    residual = max(rel["primal"], rel["dual"])
    return iteration >= 5 and residual > 1e-6 and residual > RESIDUAL_OVER_GAP * rel["gap"]


def solution(
    status: str, p: Point, res: Residuals | None, iterations: int, keep: np.ndarray, rows: int
) -> DenseSocpSolution:
    """The result record (equality duals scattered back to every row of ``A``)."""
    y = np.zeros(rows)
    y[keep] = p.y
    nan = float("nan")
    relative = res.relative if res is not None else {"primal": nan, "dual": nan, "gap": nan}
    return DenseSocpSolution(
        status=status,
        x=p.x,
        y=y,
        z_lin=p.z_lin,
        z_soc=p.z_soc,
        primal_objective=res.primal_objective if res is not None else nan,
        dual_objective=res.dual_objective if res is not None else nan,
        iterations=iterations,
        residuals=dict(relative),
    )


def empty_point(program: ShapedProgram) -> Point:
    """The zero point (returned with ``not_solved`` before any iteration)."""
    n, p, l, m = program.c.size, program.b.size, program.h_lin.size, program.h_soc.shape[0]
    zeros_soc = np.zeros((m, 4))
    return Point(np.zeros(n), np.zeros(p), np.zeros(l), np.zeros(l), zeros_soc, zeros_soc)


def interior_point_loop(
    program: ShapedProgram, tol: float, max_iter: int
) -> tuple[str, Point, Residuals | None, int]:
    """Iterate from the starting point until converged, stalled or hopeless."""
    try:
        p = starting_point(program)
    except (np.linalg.LinAlgError, ValueError):
        return "not_solved", empty_point(program), None, 0
    best, best_iteration = np.inf, 0
    res, previous = None, empty_point(program)
    for iteration in range(max_iter + 1):
        if not is_interior(p):
            # the last point that was interior, with its residuals
            return "not_solved", previous, res, iteration
        previous = p
        scaling = nt_scaling(p.s_lin, p.z_lin, p.s_soc, p.z_soc)
        res = residuals(program, p, scaling)
        merit = res.merit()
        if merit <= tol:
            return "solved", p, res, iteration
        if merit < STALL_FACTOR * best:
            best, best_iteration = merit, iteration
        stalled = iteration - best_iteration >= STALL_ITERATIONS
        if stalled or iteration == max_iter or hopeless(res, p, iteration):
            return "not_solved", p, res, iteration
        try:
            p = predictor_corrector_step(program, p, res, scaling)
        except (np.linalg.LinAlgError, ValueError):
            return "not_solved", p, res, iteration
    return "not_solved", p, res, max_iter


def solve_dense_socp(
    c: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    G_lin: np.ndarray | sp.spmatrix,
    h_lin: np.ndarray,
    G_soc: np.ndarray,
    h_soc: np.ndarray,
    *,
    tol: float = 1e-8,
    max_iter: int = 60,
) -> DenseSocpSolution:
    """Minimise ``c^T x`` subject to ``A x = b``, ``G_lin x <= h_lin`` and
    ``h_soc[i] - G_soc[i] x`` in the 4-dimensional Lorentz cone for every ``i``.

    Parameters
    ----------
    c : numpy.ndarray
        Objective, shape ``(n,)``.
    A, b : numpy.ndarray
        Equality constraints, shapes ``(p, n)`` and ``(p,)``; ``p`` may be 0. Dependent rows
        are dropped (rank-revealing QR); an inconsistent system gives ``"not_solved"``.
    G_lin, h_lin : scipy.sparse matrix or numpy.ndarray, numpy.ndarray
        Linear inequalities ``G_lin x + s_lin = h_lin``, ``s_lin >= 0``; shapes ``(l, n)``
        and ``(l,)``.
    G_soc, h_soc : numpy.ndarray
        Cone constraints ``G_soc[i] x + s_i = h_soc[i]``, ``s_i0 >= ||s_i[1:]||``; shapes
        ``(m, 4, n)`` and ``(m, 4)``; ``m`` may be 0.
    tol : float
        Bound on the three relative residuals below.
    max_iter : int
        Iteration limit.

    Returns
    -------
    DenseSocpSolution
        ``status`` is ``"solved"`` only when, at the returned point (infinity norms,
        as Clarabel defines them),

        - primal: ``max(|A x - b|, |G x + s - h|) / max(1, |(b, h)| + |x| + |s|) <= tol``,
        - dual: ``|c + A^T y + G^T z| / max(1, |c| + |(y, z)|) <= tol``,
        - gap: ``max(|c^T x - d|, s^T z) / max(1, min(|c^T x|, |d|)) <= tol`` with the dual
          objective ``d = -b^T y - h^T z``,

        and every value is finite with ``s`` and ``z`` strictly inside their cones. Anything
        else (stall, iteration limit, numerical breakdown, diverging iterates, residuals that
        stay while the gap closes as on infeasible problems, inconsistent equalities, no
        inequality at all) returns ``"not_solved"``; this function never raises on numerical
        trouble and never decides infeasibility.

    Notes
    -----
    ``tol = 1e-8`` is reached on every problem tried; below about ``1e-10`` the dual
    residual often stalls (the normal equations lose its accuracy as cones become active)
    and the result is ``"not_solved"`` after about as many iterations as a success.
    """
    program = as_cone_program(c, A, b, G_lin, h_lin, G_soc, h_soc)
    rows = program.b.size
    if not is_finite(program):
        return solution("not_solved", empty_point(program), None, 0, np.arange(rows), rows)
    keep, consistent = independent_rows(program.A, program.b)
    program.keep_rows(keep)
    if not consistent or program.h_lin.size + program.h_soc.shape[0] == 0:
        return solution("not_solved", empty_point(program), None, 0, keep, rows)
    with np.errstate(all="ignore"):
        status, p, res, iterations = interior_point_loop(program, tol, max_iter)
    return solution(status, p, res, iterations, keep, rows)
