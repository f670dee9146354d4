"""A case of (ep) made into the testbed's :class:`~chargedesign.airbearing.dynamics.CaseModel`.

The case's expressions are the sympy objects the whitelisted parser built
(:mod:`chargedesign.model.case_file`); they are differentiated here (dV/dgamma, the
right-hand sides of (ep), I1, I3) and turned into NumPy functions by
:func:`chargedesign.model.case_numeric.lambdified` (``sympy.lambdify``: the printed code is
sympy's own, of trees whose leaves are the state's names and rationals: no text from a file
reaches ``eval``).

A case the testbed cannot fly is refused by the testbed's options
(:meth:`chargedesign.scene.testbed.TestbedOptions.check_case`, on the singular factors found
here), in one line naming why, before any work: an inertia the platform's ballast cannot
give, or a V or mu singular somewhere on the sphere (the wheels' torque would be unbounded
there).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from chargedesign.airbearing.dynamics import CaseModel
from chargedesign.model.case_file import STATE, case_equations
from chargedesign.model.case_numeric import case_functions, lambdified
from chargedesign.model.case_numeric import singular_factors as case_singular_factors
from chargedesign.scene.case_file import Case
from chargedesign.scene.testbed import case_refusal


def singular_factors(case: Case) -> list[str]:
    """The factors (``"<factor> = 0"``) on which the case's V or mu is singular, sorted
    (:func:`chargedesign.model.case_numeric.singular_factors`)."""
    return case_singular_factors([case.V, *case.mu])


def refusal(case: Case) -> str | None:
    """Why the testbed cannot fly ``case`` (one line, :func:`~chargedesign.scene.testbed.
    case_refusal`), or None."""
    return case_refusal(case.name, case.inertia, singular_factors(case))


def case_model(case: Case) -> CaseModel:
    """The testbed's numeric model of ``case`` (refused first by :func:`refusal`).

    The level is the case's I3 value for a conditional claim; a general case is flown on
    I3 = 0 (the area-zero level, as the theorem's motions are)."""
    reason = refusal(case)
    if reason is not None:  # the testbed refuses it first (TestbedOptions.check_case)
        raise ValueError(reason)
    equations = case_equations(case)
    return CaseModel(
        name=case.name,
        inertia=np.array([float(m) for m in case.inertia]),
        level=0.0 if case.level is None else float(case.level),
        conditional=case.level is not None,
        functions=case_functions(case),
        cyclic=lambdified(case.I3, STATE),
        energy=lambdified(case.I1, STATE),
        equations=tuple(lambdified(e, STATE) for e in equations),
        record={
            "name": case.name,
            "source": case.source,
            "inertia_kg_m2": [float(m) for m in case.inertia],
            "V": sp.sstr(case.V),
            "l_dot_gamma": sp.sstr(case.l_dot_gamma),
            "integral": sp.sstr(case.integral),
            "level": "general" if case.level is None else str(case.level),
            "flown_on_I3": 0.0 if case.level is None else float(case.level),
            "monitored_integral": "F",
            "note": "the I4_* figures of results, requirements, tolerances and the verdict hold "
            "the relative drift of the case's F; the wheels apply the case's torque "
            "gamma x dV/dgamma - omega x mu (model/case_file.py's (ep))",
        },
    )


__all__ = ["case_model", "refusal", "singular_factors"]
