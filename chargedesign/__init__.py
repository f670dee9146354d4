"""chargedesign: bodies that realise the Yehia-Elmandouh integrable case of rigid-body dynamics.

The package turns the theorem (A = B = 2C; potential V and gyroscopic vector mu with
parameters c, d, n, K, kappa, lambda, rho) into point charges, magnetic dipoles and masses,
checks them forward and simulates them. Heavy dependencies are imported lazily.
"""

from chargedesign.errors import ChargeDesignError, InfeasibleError, InputError, SolverError
from chargedesign.params import Parameters

__all__ = [
    "ChargeDesignError",
    "InfeasibleError",
    "InputError",
    "Parameters",
    "SolverError",
]
__version__ = "0.1.0"
