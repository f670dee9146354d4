"""The charges' second-order cone programs: a dense interior point first, Clarabel as the judge.

The charges' stage (:mod:`chargedesign.designer.charges`) solves programs with few unknowns
(the candidate carriers' charges, a few hundred) and many 4-dimensional cones, one per surface
point, each dense in every charge (the Coulomb field). Clarabel's sparse factorisation of the
augmented system costs ~130 ms per iteration on the default body's largest; the normal
matrix ``G^T W^2 G`` of the same program is one BLAS product of a few ms
(:func:`~chargedesign.designer.dense_socp.solve_dense_socp`). So:

- the dense interior point solves it first; its answer is taken only when it reports the
  residuals and gap within :data:`CONE_TOL`;
- anything else (a stall, an infeasible or unbounded program, rank trouble) goes to Clarabel
  on the same data, which alone decides infeasibility (a refusal the frontier may treat as
  proved must come from a solver with infeasibility certificates).

Measured on the default body's frontier (docs/benchmarks.md): the charges' minmax and the
design's cone rounds, ~11 s in Clarabel, take a fraction of that.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse
from threadpoolctl import ThreadpoolController

from chargedesign.designer.dense_socp import solve_dense_socp
from chargedesign.errors import SolverError

#: relative residuals and gap at which a cone program counts as solved (both solvers)
CONE_TOL = 1e-8
#: BLAS threads of the dense interior point
DENSE_BLAS_THREADS = 1
#: Clarabel's factorisation (its cones are dense in the charges)
CLARABEL_LDL = "faer"


@functools.lru_cache(maxsize=1)
def _blas_threads() -> ThreadpoolController:
    """The process's thread pools, found once (``threadpool_limits`` looks for them again on
    every call: about 1 ms, against 0.02 ms for the limit itself)."""
    return ThreadpoolController()


@dataclass
class ConeProgram:
    """``min c x`` subject to ``A x = b``, ``G_lin x <= h_lin`` and, for every cone ``i``,
    ``h_soc[i] - G_soc[i] x`` in the 4-dimensional Lorentz cone ``{s0 >= |s[1:]|}``.

    Shapes: ``c`` (n,), ``A`` (p, n), ``G_lin`` (l, n; sparse or dense), ``G_soc`` (m, 4, n).
    ``what`` names the program in errors.
    """

    c: np.ndarray
    A: np.ndarray
    b: np.ndarray
    G_lin: Any
    h_lin: np.ndarray
    G_soc: np.ndarray
    h_soc: np.ndarray
    what: str

    def solve(self, tol: float = CONE_TOL) -> np.ndarray | None:
        """The minimiser ``x`` (None: the program is infeasible, by Clarabel's certificate).

        Raises
        ------
        SolverError
            Clarabel fails too.
        """
        # its BLAS products are small (a few hundred columns): one thread is faster than
        # several here, where they spin and wait on each other (docs/benchmarks.md)
        with _blas_threads().limit(limits=DENSE_BLAS_THREADS, user_api="blas"):
            dense = solve_dense_socp(
                self.c, self.A, self.b, self.G_lin, self.h_lin, self.G_soc, self.h_soc, tol=tol
            )
        if dense.status == "solved":
            return np.asarray(dense.x)
        return self.solve_clarabel(tol)

    def solve_clarabel(self, tol: float = CONE_TOL) -> np.ndarray | None:
        """The same program by Clarabel (None: primal infeasible)."""
        import clarabel

        n, m = len(self.c), len(self.G_soc)
        blocks = [sparse.csc_matrix(self.A.reshape(-1, n)), sparse.csc_matrix(self.G_lin)]
        rhs = [self.b, self.h_lin]
        cones: list[Any] = [
            clarabel.ZeroConeT(len(self.b)),
            clarabel.NonnegativeConeT(len(self.h_lin)),
        ]
        if m:
            blocks.append(sparse.csc_matrix(self.G_soc.reshape(4 * m, n)))
            rhs.append(self.h_soc.reshape(-1))
            cones += [clarabel.SecondOrderConeT(4)] * m
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.direct_solve_method = CLARABEL_LDL
        settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tol
        solution = clarabel.DefaultSolver(
            sparse.csc_matrix((n, n)),
            self.c,
            sparse.vstack(blocks, format="csc"),
            np.concatenate(rhs),
            cones,
            settings,
        ).solve()
        status = solution.status
        if status in (
            clarabel.SolverStatus.PrimalInfeasible,
            clarabel.SolverStatus.AlmostPrimalInfeasible,
        ):
            return None
        if status not in (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved):
            raise SolverError(f"{self.what}: Clarabel returned {status}")
        return np.asarray(solution.x)
