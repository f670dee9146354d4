"""The printed moment conditions (p6) of the paper against the derived ones, exactly."""

from __future__ import annotations

from chargedesign.model.audit_entry import AuditEntry
from chargedesign.moment_conditions.harmonics import field_symbols
from chargedesign.moment_conditions.mu import moment_symbol, symbolic_mu_solution


def audit_p6() -> AuditEntry:
    """Compare the printed moment conditions (p6) with the derived ones, exactly.

    The derived conditions come from :func:`symbolic_mu_solution` for the paper's field
    ``Phi = a1 Z + a2 (3 Z^2 - R^2)`` (legendre ``[a1, 2 a2]``, generic a1, a2 != 0); the
    printed (p6) are :func:`chargedesign.model.printed.printed_p6`, solved for the same 16
    moments. ``difference`` lists ``printed - derived`` for each moment that differs.
    """
    import sympy as sp

    from chargedesign.model.printed import a1, a2, printed_p6

    f1, f2 = field_symbols(2)
    derived = {
        key: sp.factor(value.subs({f1: a1, f2: 2 * a2}, simultaneous=True))
        for key, value in symbolic_mu_solution(2).items()
    }
    keys = list(derived)
    symbols = [moment_symbol(k) for k in keys]
    printed_solutions = sp.linsolve(list(printed_p6()), symbols)
    if not printed_solutions:
        return AuditEntry("p6", False, "printed (p6) is inconsistent", "")
    (printed_tuple,) = list(printed_solutions)
    differences = []
    undetermined = []
    for key, printed_value in zip(keys, printed_tuple, strict=True):
        if printed_value.free_symbols & set(symbols):
            undetermined.append(key)
        diff = sp.factor(sp.simplify(printed_value - derived[key]))
        if diff != 0:
            differences.append(f"I_{key}: {diff}")
    agrees = not differences
    note = (
        "printed (p6) solved for the 16 second and third charge moments, minus the moments "
        "derived by matching mu = -sum q (r . B) r with the theorem's mu on |gamma| = 1 "
        "(Phi = a1 Z + a2 (3 Z^2 - R^2), generic a1, a2 != 0)"
    )
    if undetermined:
        note += "; moments (p6) leaves free: " + ", ".join(undetermined)
    return AuditEntry("p6", agrees, "0" if agrees else "; ".join(differences), note)
