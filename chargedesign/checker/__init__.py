# ruff: noqa: F401  (this module re-exports the package's names)
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

The package's modules: :mod:`.constants`, :mod:`.results` (the report and its text),
:mod:`.kernel` (orientations, elements, the double kernel), :mod:`.double_double`,
:mod:`.accurate` (the kernel in double-double), :mod:`.verdict` (comparisons, floors,
:func:`check_design`). The names of ``__all__`` are importable from ``chargedesign.checker``
(and :func:`theorem_reference` and ``FIELD_NAMES``, which the design's acceptance and the check
benchmark read from here); the rest from their own module.
"""

from __future__ import annotations

from chargedesign.checker.accurate import (
    AccurateSums,
    evaluate_accurate,
)
from chargedesign.checker.constants import (
    ACCURATE_FRACTION,
    DEFAULT_ORIENTATIONS,
    DEFAULT_TOL,
    EPS,
    NOISE_FLOOR,
    ROUNDING_FACTOR,
)
from chargedesign.checker.double_double import DD_UNIT
from chargedesign.checker.kernel import (
    RotatedSums,
    collect_elements,
    evaluate_rotated,
    rotation_matrices,
    sample_orientations,
)
from chargedesign.checker.results import (
    CheckReport,
    EffectResult,
    QuantityResult,
    summary_lines,
)
from chargedesign.checker.verdict import (
    check_design,
    contribution_sizes,
    rounding_floor,
    theorem_reference,
)
from chargedesign.vocabulary import (
    FIELD_NAMES,
    PRECISIONS,
)

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
