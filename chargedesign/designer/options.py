"""Design options: the ``[design]`` table's type lives with the scene
(:mod:`chargedesign.scene.design`); the names stay importable from here."""

from chargedesign.scene.design import (
    OBJECTIVES,
    POLISHED_TOL,
    RAW_TOL,
    SPARSITY_METHODS,
    DesignOptions,
    Progress,
)

__all__ = ["OBJECTIVES", "POLISHED_TOL", "RAW_TOL", "SPARSITY_METHODS", "DesignOptions", "Progress"]
