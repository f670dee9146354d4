"""What an infeasible design says, and the change that fixes each case.

Every failure is a ChargeDesignError (here InfeasibleError) with a one-line message naming
the condition, parameter or bound at fault; the CLI prints the same line and exits 2. Run::

    .venv/bin/python examples/infeasible_design.py
"""

from __future__ import annotations

import sys
from typing import Any

from chargedesign.designer import design_from_scene
from chargedesign.errors import InfeasibleError
from chargedesign.scene import scene_from_dict

BASE: dict[str, Any] = {
    "parameters": {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9},
    "fields": {"magnetic": {"a1": 1.0, "a2": 0.5}},
    "body": {"shape": "ball", "radius": 1.0, "spacing": 0.25},
}

#: (what goes wrong, the scene tables that cause it, the tables that fix it)
CASES: list[tuple[str, dict[str, Any], dict[str, Any]]] = [
    (
        "no field gradient, but K != 0",
        {"fields": {"magnetic": {"a1": 1.0, "a2": 0.0}}},
        {"fields": {"magnetic": {"a1": 1.0, "a2": 0.5}}},
    ),
    (
        "flat candidate region",
        {"body": {"shape": "box", "half_size": [1.0, 1.0, 0.1], "spacing": 0.25}},
        {"body": {"shape": "box", "half_size": [1.0, 1.0, 0.5], "spacing": 0.25}},
    ),
    (
        "charges bounded too tightly",
        {"design": {"max_charge": 0.05}},
        {"design": {"max_charge": 0.5}},
    ),
]


def attempt(tables: dict[str, Any]) -> str:
    try:
        result = design_from_scene(scene_from_dict({**BASE, **tables}))
    except InfeasibleError as exc:
        return f"infeasible: {exc}"
    d = result.design
    return (
        f"designed: {len(d.charge_values)} charges, {len(d.dipole_moments)} dipoles, "
        f"{len(d.mass_values)} masses, residual {result.residual_after:.1e}"
    )


def main() -> int:
    for what, broken, fixed in CASES:
        print(f"{what}:")
        print(f"  {attempt(broken)}")
        print(f"  fixed with {fixed}: {attempt(fixed)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
