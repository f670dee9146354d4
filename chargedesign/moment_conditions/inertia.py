"""The inertia: masses with ``A = B = 2C`` about O and no products of inertia."""

from __future__ import annotations

from fractions import Fraction

from chargedesign.moment_conditions.context import DerivationContext


def masses_for_inertia(ctx: DerivationContext) -> None:
    """Add the masses' second moments: ``M_xx = M_yy = C/2``, ``M_zz = 3C/2``, products 0."""
    C = ctx.P[0]
    system = ctx.systems["masses"]
    rows = [
        ("xx", C / 2, "inertia: C = M_xx + M_yy and A = B = 2C give M_xx = C/2"),
        ("yy", C / 2, "inertia: C = M_xx + M_yy and A = B = 2C give M_yy = C/2"),
        ("zz", 3 * C / 2, "inertia: A = M_yy + M_zz = 2C gives M_zz = 3C/2"),
        ("xy", Fraction(0), "inertia: product of inertia xy is zero (principal axes)"),
        ("xz", Fraction(0), "inertia: product of inertia xz is zero (principal axes)"),
        ("yz", Fraction(0), "inertia: product of inertia yz is zero (principal axes)"),
    ]
    for key, value, why in rows:
        system.add_display({key: Fraction(1)}, value, why)
    ctx.notes.append(
        "masses: nonnegative values are the design stage's job (not a linear condition)"
    )
