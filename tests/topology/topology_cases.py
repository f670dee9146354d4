"""Parameter sets the topology tests share (besides the unit scene's)."""

from __future__ import annotations

from unit_scene import UNIT_PARAMETERS as UNIT

#: a generic case: every one of c, d, n, K, kappa non-zero, |kappa| < K^2 sqrt(c^2 + d^2)
#: (the inner shape: three critical energies on the equator, chambers of 2 and 4 tori)
GENERIC = UNIT.replace(kappa=0.05)
