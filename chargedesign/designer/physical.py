"""Transitional: the names that frontier.py and pipeline.py still import from here.

The physical design now lives by concern in :mod:`chargedesign.designer.physical_setup`,
:mod:`~chargedesign.designer.charges`, :mod:`~chargedesign.designer.masses`,
:mod:`~chargedesign.designer.assembly` and :mod:`~chargedesign.designer.frontier_probes`; this
module goes once those two import from there.
"""

from chargedesign.designer.assembly import build_design, design_at_rate, design_physical
from chargedesign.designer.charges import charge_support, lp_charges
from chargedesign.designer.frontier_probes import ChargesLimit, charges_rate_limit
from chargedesign.designer.masses import design_masses
from chargedesign.designer.physical_setup import (
    Binding,
    PhysicalInfeasible,
    PhysicalSetup,
    setup_physical,
)

__all__ = [
    "Binding",
    "ChargesLimit",
    "PhysicalInfeasible",
    "PhysicalSetup",
    "build_design",
    "charge_support",
    "charges_rate_limit",
    "design_at_rate",
    "design_masses",
    "design_physical",
    "lp_charges",
    "setup_physical",
]
