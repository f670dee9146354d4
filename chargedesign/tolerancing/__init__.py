"""Manufacturing tolerances: exact first-order sensitivity and a Monte Carlo of perturbed bodies.

The errors the forward check measures (:mod:`chargedesign.checker`) are, per orientation gamma,

- ``e_mu(g) = mu_body(g) - mu_theorem(g)`` with ``mu_body = sum q (r . G_m) r``
  (``G_m = R^T grad Phi_m(R r)``, so ``-q (r . B) r`` with ``B_body = -G_m``),
- ``e_V(g)``: ``V_body - V_theorem``, each minus its mean over the orientations, with
  ``V_body = sum q Phi_e + sum m Phi_g + sum sigma . G_m``,
- ``e_I = sum m (|r|^2 1 - r r^T) - diag(2C, 2C, C)`` (no orientation),

and their relative errors are ``max_g |e(g)| / scale`` (scale ``max_g |x_theorem(g)|``; the
inertia's ``2C``; the largest absolute entry for the inertia, as in the check). Every ``e`` is
linear in the charges, dipole moments and masses and polynomial in the positions, so its
derivatives are exact and closed-form (:func:`jacobians`):

- ``d mu / d q = s r`` and ``d mu / d r = q (r (G_m + H_m r)^T + s 1)``, ``s = r . G_m``
  (``H_m = R^T Hess Phi_m R``),
- ``d V / d q = Phi_e``, ``d V / d r = q G_e``; ``d V / d m = Phi_g``, ``d V / d r = m G_g``;
  ``d V / d sigma = G_m``, ``d V / d r = H_m sigma`` (all centred over the orientations),
- ``d I / d m = |r|^2 1 - r r^T``, ``d I / d r_a = m (2 r_a 1 - e_a r^T - r e_a^T)``.

The tolerance of one element for a target relative error ``eps`` of quantity Q is the largest
displacement (or relative change of its value) whose first-order effect keeps Q's error below
``eps`` in the worst direction: ``eps * scale_Q / max_g ||dQ/dr||_2``.

The Monte Carlo (:func:`monte_carlo`) draws perturbed bodies (Gaussian errors, one standard
deviation = the given tolerance), measures their errors exactly and to first order, and
integrates them all at once (:func:`simulate_ensemble`) to measure the drift of I4; the
linear-response prediction of that drift integrates ``dI4/domega . I^-1 (N_b - N_0)`` along
the nominal trajectory. See docs/tolerance.md.

The package's modules: :mod:`.common` (defaults, shared helpers), :mod:`.error_model`
(:class:`Spread`, :class:`ErrorModel`, the draws), :mod:`.element_tolerances` (the report:
:func:`tolerance_report`, :func:`with_tolerance`), :mod:`.ensemble` (:func:`simulate_ensemble`,
the linear drift), :mod:`.perturbed_bodies` (the Monte Carlo: :func:`monte_carlo`,
:func:`error_distribution`, :func:`plot_drift`) and :mod:`.material_properties`
(:func:`material_uncertainty`). Every name stays importable from ``chargedesign.tolerancing``.
"""

from __future__ import annotations

from chargedesign.limits import MAX_TOLERANCE_LEVELS as MAX_LEVELS
from chargedesign.limits import MAX_TOLERANCE_SAMPLES as MAX_SAMPLES
from chargedesign.scene.spreads import LENGTH_UNITS, Spread, parse_spread
from chargedesign.sensitivity import DEFAULT_ORIENTATIONS
from chargedesign.tolerancing.common import (
    DEFAULT_LEVELS,
    DEFAULT_MATERIAL_SAMPLES,
    DEFAULT_RTOL,
    DEFAULT_T_END,
    DEFAULT_TARGET,
    KINDS,
)
from chargedesign.tolerancing.element_tolerances import (
    ToleranceReport,
    tolerance_report,
    with_tolerance,
)
from chargedesign.tolerancing.ensemble import EnsembleRun, simulate_ensemble
from chargedesign.tolerancing.error_model import ErrorModel
from chargedesign.tolerancing.material_properties import (
    MaterialErrors,
    MaterialUncertainty,
    material_errors_with,
    material_uncertainty,
    recorded_material_errors,
)
from chargedesign.tolerancing.perturbed_bodies import (
    MonteCarloResult,
    error_distribution,
    monte_carlo,
    plot_drift,
)

__all__ = [
    "DEFAULT_LEVELS",
    "DEFAULT_MATERIAL_SAMPLES",
    "DEFAULT_ORIENTATIONS",
    "DEFAULT_RTOL",
    "DEFAULT_TARGET",
    "DEFAULT_T_END",
    "KINDS",
    "LENGTH_UNITS",
    "MAX_LEVELS",
    "MAX_SAMPLES",
    "EnsembleRun",
    "ErrorModel",
    "MaterialErrors",
    "MaterialUncertainty",
    "MonteCarloResult",
    "Spread",
    "ToleranceReport",
    "error_distribution",
    "material_errors_with",
    "material_uncertainty",
    "monte_carlo",
    "parse_spread",
    "plot_drift",
    "recorded_material_errors",
    "simulate_ensemble",
    "tolerance_report",
    "with_tolerance",
]
