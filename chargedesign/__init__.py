"""chargedesign: bodies that realise the Yehia-Elmandouh integrable case of rigid-body dynamics.

The package turns the theorem (A = B = 2C; potential V and gyroscopic vector mu with
parameters c, d, n, K, kappa, lambda, rho) into point charges, magnetic dipoles and masses,
checks them forward and simulates them.

>>> import chargedesign as cd
>>> result = cd.design()                 # doctest: +SKIP  (the embedded default scene)
>>> report = cd.check(result.design)     # doctest: +SKIP
>>> motion = cd.simulate(result, t_end=10.0)   # doctest: +SKIP

Every name below is imported lazily (PEP 562), so ``import chargedesign`` loads neither
sympy, cvxpy, scipy's optimisers nor PyVista; they load when a stage first needs them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from chargedesign.errors import ChargeDesignError, InfeasibleError, InputError, SolverError
from chargedesign.version import __version__ as __version__

#: public name -> (module, attribute), resolved on first use so that ``import chargedesign``
#: loads none of the heavy packages (sympy, cvxpy, PyVista, heyoka, dask). The stages are
#: plain functions of :mod:`chargedesign.api`; no subpackage shares their names (a submodule
#: import would rebind the package attribute of the same name).
_LAZY: dict[str, tuple[str, str]] = {
    # the parameters (lazy too: the command line sets its BLAS threads before numpy loads,
    # chargedesign/commands/__init__.py)
    "Parameters": ("chargedesign.params", "Parameters"),
    # stages
    "design": ("chargedesign.api", "design"),
    "check": ("chargedesign.api", "check"),
    "simulate": ("chargedesign.api", "simulate"),
    "frontier": ("chargedesign.api", "frontier"),
    "tolerance": ("chargedesign.api", "tolerance"),
    "sweep": ("chargedesign.api", "sweep"),
    "testbed": ("chargedesign.api", "testbed"),
    "bifurcation": ("chargedesign.api", "bifurcation"),
    "verify": ("chargedesign.verification", "verify"),
    "verify_case": ("chargedesign.api", "verify_case"),
    "catalogue": ("chargedesign.api", "catalogue"),
    "conditions": ("chargedesign.moment_conditions", "conditions_for_scene"),
    # elements and files
    "Design": ("chargedesign.body", "Design"),
    "ElementSet": ("chargedesign.elements", "ElementSet"),
    "read_design": ("chargedesign.body", "read_design"),
    "write_design": ("chargedesign.body", "write_design"),
    "load_scene": ("chargedesign.scene", "load_scene"),
    "Scene": ("chargedesign.scene", "Scene"),
    "export_design": ("chargedesign.export", "export_design"),
    "schema": ("chargedesign.schemas", "schema"),
    # results
    "DesignResult": ("chargedesign.designer", "DesignResult"),
    "CheckReport": ("chargedesign.checker", "CheckReport"),
    "SimulationResult": ("chargedesign.simulation", "SimulationResult"),
    "LinearConditions": ("chargedesign.moment_conditions", "LinearConditions"),
    "VerificationReport": ("chargedesign.verification", "VerificationReport"),
    "BifurcationDiagram": ("chargedesign.topology.diagram", "BifurcationDiagram"),
    "CaseDiagram": ("chargedesign.topology.diagram", "CaseDiagram"),
    "CaseCertificate": ("chargedesign.model.case_file", "CaseCertificate"),
    "CatalogueReport": ("chargedesign.model.catalogue", "CatalogueReport"),
    "CaseDesignResult": ("chargedesign.designer.case_design", "CaseDesignResult"),
}

__all__ = [
    "BifurcationDiagram",
    "CaseCertificate",
    "CaseDesignResult",
    "CaseDiagram",
    "CatalogueReport",
    "ChargeDesignError",
    "CheckReport",
    "Design",
    "DesignResult",
    "ElementSet",
    "InfeasibleError",
    "InputError",
    "LinearConditions",
    "Parameters",
    "Scene",
    "SimulationResult",
    "SolverError",
    "VerificationReport",
    "__version__",
    "bifurcation",
    "catalogue",
    "check",
    "conditions",
    "design",
    "export_design",
    "frontier",
    "load_scene",
    "read_design",
    "schema",
    "simulate",
    "sweep",
    "testbed",
    "tolerance",
    "verify",
    "verify_case",
    "write_design",
]


def __getattr__(name: str) -> Any:
    try:
        module_name, attribute = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'chargedesign' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module_name), attribute)
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__() -> list[str]:
    """The public names only (``__all__``): not the module's own imports (``Any``,
    ``TYPE_CHECKING``, ``annotations``, ``importlib``) nor the submodules loaded so far."""
    return sorted(__all__)


if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs
    from chargedesign.api import (
        bifurcation,
        catalogue,
        check,
        design,
        frontier,
        simulate,
        sweep,
        testbed,
        tolerance,
        verify_case,
    )
    from chargedesign.body import Design, read_design, write_design
    from chargedesign.checker import CheckReport
    from chargedesign.designer import DesignResult
    from chargedesign.designer.case_design import CaseDesignResult
    from chargedesign.elements import ElementSet
    from chargedesign.export import export_design
    from chargedesign.model.case_file import CaseCertificate
    from chargedesign.model.catalogue import CatalogueReport
    from chargedesign.moment_conditions import LinearConditions
    from chargedesign.moment_conditions import conditions_for_scene as conditions
    from chargedesign.params import Parameters
    from chargedesign.scene import Scene, load_scene
    from chargedesign.schemas import schema
    from chargedesign.simulation import SimulationResult
    from chargedesign.topology.diagram import BifurcationDiagram, CaseDiagram
    from chargedesign.verification import VerificationReport, verify
