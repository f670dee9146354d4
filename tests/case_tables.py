"""Case tables the case tests share: one Kowalevski top, its name and parameters chosen by
each test (the catalogue's own files are in chargedesign/data/cases)."""

from __future__ import annotations


def kowalevski_table(name: str, C: float, a: float) -> str:
    """The ``[case]`` table of a Kowalevski top: inertia diag(2C, 2C, C) kg m^2,
    V = C a gamma1 J, and its quartic integral, claimed for every level."""
    return f"""
[case]
name = "{name}"
inertia = ["2*C", "2*C", "C"]
V = "C*a*gamma1"
l = ["0", "0", "0"]
integral = "(p**2 - q**2 - a*gamma1)**2 + (2*p*q - a*gamma2)**2"
level = "general"
[case.parameters]
C = {C}
a = {a}
"""
