"""Why a source's conditions cannot be met on the candidates, named.

:func:`diagnose` checks the equality system before any solve (absent directions: candidates
in or near a plane; weights amplified beyond :data:`AMPLIFICATION_LIMIT`);
:func:`infeasible_inequalities` names the bound or total that makes a solvable system
infeasible once a solver has proved it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from chargedesign.candidates import Geometry
from chargedesign.designer.problems import l1_lp_full, solve_linf_scalar
from chargedesign.designer.solvers import InfeasibleProblem, solve_linprog
from chargedesign.designer.system import DesignProblem, drop_last_row, natural_row_size
from chargedesign.errors import InfeasibleError, SolverError
from chargedesign.formatting import CELL, PLAIN, ROUGH, fmt
from chargedesign.scene.design import DesignOptions

#: a direction of the nondimensional condition matrix with singular value below this
#: fraction of the largest is treated as absent (exact degeneracy up to rounding)
RANK_RTOL = 1e-10
#: weights amplified beyond this factor (relative to a round body) are refused as infeasible
AMPLIFICATION_LIMIT = 1e8
#: ... and beyond this one reported in the notes
AMPLIFICATION_NOTE = 1e3


def _short(text: str, limit: int = 160) -> str:
    first = text.split("; ")[0]
    return first if len(first) <= limit else first[: limit - 3] + "..."


def diagnose(problem: DesignProblem, geometry: Geometry) -> tuple[int, list[str]]:
    """Check that ``A w = b`` can be met on the candidates; name what cannot.

    The system is nondimensionalised by what each row gives for unit weight at the body's
    size; directions with singular value below ``RANK_RTOL`` of the largest are absent. A
    right-hand side with a component along an absent direction is infeasible; one that
    needs weights amplified by more than ``AMPLIFICATION_LIMIT`` (a nearly planar or
    degenerate set) is refused as well.

    Returns
    -------
    rank : int
    notes : list of str
        Warnings (ill-conditioning).

    Raises
    ------
    InfeasibleError
        Naming the conditions that cannot be produced, and why.
    """
    source = problem.source
    notes: list[str] = []
    m = len(problem.b)
    if m == 0:
        return 0, notes
    # conditions whose coefficients vanish (e.g. a1 = 0 in a mu condition) but ask for a value
    for i, row in enumerate(problem.rows):
        if all(c == 0 for c in row.coefficients.values()) and row.value != 0:
            raise InfeasibleError(
                f"{source}: condition '{problem.labels[i]}' ({_short(row.provenance)}) asks "
                f"for {fmt(row.value, CELL)} but all its coefficients are zero: no body meets it"
            )
    size = geometry.size if geometry.size > 0 else 1.0
    natural = np.array([natural_row_size(r, size) for r in problem.rows])
    natural = np.where(natural > 0, natural, 1.0)
    A_nd = problem.A / natural[:, None]
    b_nd = problem.b / natural
    # SVD through a QR of the tall transpose: A_nd^T = Q R, so A_nd = R^T Q^T and the left
    # singular vectors and values are those of the small (m, m) matrix R^T (several times
    # faster than a direct SVD of a wide matrix with 10^5 columns)
    if A_nd.shape[1] > A_nd.shape[0]:
        R = np.asarray(np.linalg.qr(A_nd.T, mode="r"))
        U, s, _ = np.linalg.svd(R.T)
    else:
        U, s, _ = np.linalg.svd(A_nd, full_matrices=False)
    top = float(s[0]) if len(s) and s[0] > 0 else 0.0
    rank = int(np.sum(s > RANK_RTOL * top)) if top > 0 else 0
    coeffs = U.T @ b_nd
    b_norm = float(np.linalg.norm(b_nd))
    if b_norm == 0.0:
        return rank, notes
    # the left null space: every direction of R^m not spanned by the retained ones
    null_part = b_nd - U[:, :rank] @ coeffs[:rank]
    if float(np.linalg.norm(null_part)) > 1e-8 * b_norm:
        raise InfeasibleError(_cannot_produce(problem, null_part, geometry, exact=True))
    natural_weight = b_norm / top
    worst = 0.0
    worst_dir = None
    for i in range(rank):
        amp = abs(coeffs[i]) / s[i] / natural_weight
        if amp > worst:
            worst, worst_dir = amp, U[:, i]
    if worst > AMPLIFICATION_LIMIT and worst_dir is not None:
        raise InfeasibleError(
            _cannot_produce(problem, worst_dir, geometry, exact=False, amplification=worst)
        )
    if worst > AMPLIFICATION_NOTE and worst_dir is not None:
        involved = _involved(worst_dir)
        names = ", ".join(f"'{problem.labels[i]}'" for i in involved)
        verb = f"conditions {names} are" if len(involved) > 1 else f"condition {names} is"
        notes.append(
            f"{source}: {verb} weakly produced by these candidates: weights "
            f"about {fmt(worst, ROUGH)} times larger than a round body of this size needs"
            + (
                f" ({geometry.plane_text()} is nearly all of it)"
                if geometry.thickness_ratio < 1e-2
                else ""
            )
        )
    return rank, notes


def _involved(direction: np.ndarray, limit: int = 4) -> list[int]:
    mags = np.abs(direction)
    order = np.argsort(-mags)
    return [int(i) for i in order[:limit] if mags[i] >= 0.25 * mags[order[0]]]


def _cannot_produce(
    problem: DesignProblem,
    direction: np.ndarray,
    geometry: Geometry,
    *,
    exact: bool,
    amplification: float = 0.0,
) -> str:
    idx = _involved(direction)
    labels = ", ".join(f"'{problem.labels[i]}'" for i in idx)
    provenance = "; ".join(_short(problem.rows[i].provenance, 120) for i in idx)
    plural = "s" if len(idx) > 1 else ""
    what = f"condition{plural} {labels} of {problem.source} ({provenance})"
    if geometry.dimension < 3:
        where = f"candidates all lie in {geometry.plane_text()}"
    elif geometry.thickness_ratio < 1e-2:
        where = (
            "candidates are nearly planar (thickness / width"
            f" {fmt(geometry.thickness_ratio, ROUGH)}, "
            f"close to {geometry.plane_text()})"
        )
    else:
        where = "the candidates"
    if exact:
        return f"{where}: they cannot produce the moment{plural} of {what}"
    return (
        f"{where}: they produce the moment{plural} of {what} only with weights "
        f"{fmt(amplification, ROUGH)} times larger than a round body of this size needs; "
        "use a thicker candidate region"
    )


def infeasible_inequalities(p: DesignProblem, options: DesignOptions) -> InfeasibleError:
    """Name the inequality that makes a (range-feasible) problem infeasible."""
    if p.source == "charges" and p.upper is not None:
        try:
            free = replace(p, upper=None)
            need = float(np.max(np.abs(solve_linf_scalar(free, replace(options, solver="auto")).u)))
            return InfeasibleError(
                f"charges: design.max_charge = {fmt(options.max_charge, PLAIN)} C is too small:"
                " these "
                f"conditions on these candidates need a largest |q| of at least "
                f"{fmt(need * p.scale, CELL)} C"
            )
        except InfeasibleProblem:
            pass
    if p.source == "masses":
        if options.total_mass is not None:
            free = drop_last_row(p)
            try:
                least = l1_lp_full(free, None, None).u.sum() * free.scale
            except InfeasibleProblem:
                least = None
            if least is not None:
                if options.total_mass < least:
                    return InfeasibleError(
                        f"masses: design.total_mass = {fmt(options.total_mass, PLAIN)} kg is below"
                        " the "
                        f"least total mass that meets the conditions on these candidates, "
                        f"{fmt(least, CELL)} kg"
                    )
                return InfeasibleError(
                    f"masses: design.total_mass = {fmt(options.total_mass, PLAIN)} kg is above the"
                    " largest "
                    "total mass that meets the conditions on these candidates (the least is "
                    f"{fmt(least, CELL)} kg; add candidates nearer O)"
                )
        idx = _irreducible_rows(p)
        names = ", ".join(f"'{p.labels[i]}' ({_short(p.rows[i].provenance, 100)})" for i in idx)
        return InfeasibleError(
            f"masses: no nonnegative masses on these candidates meet conditions {names} together"
        )
    return InfeasibleError(f"{p.source}: the conditions and bounds cannot be met together")


def _irreducible_rows(p: DesignProblem) -> list[int]:
    """A smallest-by-deletion set of rows with no nonnegative solution (for the message).

    Deletion filter: a row is dropped for good when the others are still infeasible; what
    is left is an irreducible infeasible subsystem (every proper subset is feasible).
    """
    keep = list(range(len(p.b_s)))
    for i in range(len(p.b_s)):
        trial = [j for j in keep if j != i]
        if not trial:
            break
        try:
            solve_linprog(
                np.zeros(p.A_s.shape[1]), p.A_s[trial], p.b_s[trial], (0, None),
                "masses: infeasibility diagnosis",
            )  # fmt: skip
        except InfeasibleProblem:
            keep = trial
        except SolverError:
            break
    return keep
