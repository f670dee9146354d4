"""Design problems: weights on candidate points that meet the linear moment conditions.

For each source (charges, dipoles, masses) the conditions engine gives ``A w = b``
(:meth:`chargedesign.moment_conditions.LinearConditions.system`); this package chooses ``w`` on the
candidate points by a convex objective, then polishes it to machine precision:

- charges (free sign, optional ``|q| <= max_charge``, optional total charge, optional number
  of charges): ``l1`` (minimum ``sum |q|``, sparse layouts), ``l2`` (minimum ``sum q^2``,
  smooth), ``linf`` (minimum ``max |q|``);
- dipoles (free vectors): ``l1`` is the group-sparse ``sum |sigma_j|`` (second-order cone),
  ``l2`` the minimum ``sum |sigma_j|^2``, ``linf`` the minimum ``max |sigma_j|``;
- masses (``m >= 0``, optional total mass): ``l1`` minimum total mass (or, with the total
  given, a sparse vertex of the feasible set), ``l2`` minimum ``sum m^2``, ``linf`` minimum
  ``max m``.

The conditions never couple two sources, so the joint problem is the sum of independent
per-source problems and is solved source by source (exactly the same optimum).

Numerics (see docs/design.md):

- every problem is nondimensionalised: each row of ``A`` is divided by its largest entry
  (row equilibration: a row scaled by ``a2 = 1e-9`` or by ``L^4`` for a 5 cm body is as
  accurate as a unit one) and the unknowns by the scale of the scaled right-hand side;
- linear programs (l1, linf, masses) go to HiGHS; on large candidate sets the l1 and mass
  problems (and the group-sparse dipole problem) are solved by column generation: a small
  problem on a working set, all columns priced with its duals, violators added, until none
  is left, which proves optimality for the full set;
- cones and quadratics go to Clarabel through cvxpy with tolerances tightened to 1e-12;
  unconstrained least-norm problems have a closed form (``lstsq``);
- every solver status is checked; residuals are computed here, never taken on trust;
- polishing fixes the support (non-zero weights) and applies the least-norm correction on
  it (``lstsq``, with one refinement step; masses that would turn negative are re-solved by
  NNLS on the support), so the relative residual (defined in :func:`relative_residual`)
  reaches ~1e-16.

Modules (each imports only those above it):

- :mod:`~chargedesign.designer.options`: :class:`DesignOptions` (the ``[design]`` table),
  validated; default tolerances;
- :mod:`~chargedesign.designer.system`: one source's nondimensionalised system ``A w = b``
  and :func:`relative_residual`;
- :mod:`~chargedesign.designer.solvers`: HiGHS, cvxpy and least-norm back ends, status checks;
- :mod:`~chargedesign.designer.problems`: the l1 / linf / l2 / cone problems per source;
- :mod:`~chargedesign.designer.column_generation`: the same problems on large candidate sets;
- :mod:`~chargedesign.designer.solve`: which problem answers a source, and the ``n_charges``
  sparsity search (reweighted l1, mixed integer);
- :mod:`~chargedesign.designer.polish`: support-fixed least-norm correction, NNLS for masses;
- :mod:`~chargedesign.designer.diagnostics`: planar or degenerate candidates, infeasible
  bounds and totals, named;
- :mod:`~chargedesign.designer.accuracy`: forward accuracy (:func:`forward_accuracy`,
  conditions met only by cancellation);
- :mod:`~chargedesign.designer.result`: :class:`SourceResult`, :class:`DesignResult`, the
  provenance written into design.json;
- :mod:`~chargedesign.designer.pipeline`: :func:`design_source`, :func:`design_body`,
  :func:`design_from_scene`.
"""

from chargedesign.designer.accuracy import (
    FORWARD_LIMIT,
    FORWARD_NOTE,
    Cancellation,
    forward_accuracy,
    quantity_scales,
    source_cancellations,
)
from chargedesign.designer.column_generation import CG_MIN_CANDIDATES
from chargedesign.designer.diagnostics import (
    AMPLIFICATION_LIMIT,
    AMPLIFICATION_NOTE,
    RANK_RTOL,
    diagnose,
)
from chargedesign.designer.pipeline import design_body, design_from_scene, design_source
from chargedesign.designer.polish import POLISH_THRESHOLDS
from chargedesign.designer.result import DesignResult, SourceResult, design_extras
from chargedesign.designer.solve import MIP_MAX_CANDIDATES
from chargedesign.designer.solvers import CLARABEL_SETTINGS, HIGHS_OPTIONS
from chargedesign.designer.system import UNITS, condition_label, relative_residual
from chargedesign.scene.design import (
    OBJECTIVES,
    POLISHED_TOL,
    RAW_TOL,
    SPARSITY_METHODS,
    DesignOptions,
    Progress,
)

__all__ = [
    "AMPLIFICATION_LIMIT",
    "AMPLIFICATION_NOTE",
    "CG_MIN_CANDIDATES",
    "CLARABEL_SETTINGS",
    "FORWARD_LIMIT",
    "FORWARD_NOTE",
    "HIGHS_OPTIONS",
    "MIP_MAX_CANDIDATES",
    "OBJECTIVES",
    "POLISHED_TOL",
    "POLISH_THRESHOLDS",
    "RANK_RTOL",
    "RAW_TOL",
    "SPARSITY_METHODS",
    "UNITS",
    "Cancellation",
    "DesignOptions",
    "DesignResult",
    "Progress",
    "SourceResult",
    "condition_label",
    "design_body",
    "design_extras",
    "design_from_scene",
    "design_source",
    "diagnose",
    "forward_accuracy",
    "quantity_scales",
    "relative_residual",
    "source_cancellations",
]
