"""Physical constants (SI): the one place the package defines them.

Values are CODATA 2018 (the SI 2019 exact ones exact); the material data, with their
sources, live in :mod:`chargedesign.physical.materials`.
"""

from __future__ import annotations

import math

#: vacuum permittivity, F/m (CODATA 2018)
EPSILON_0 = 8.8541878128e-12
#: vacuum permeability, H/m (CODATA 2018)
MU_0 = 1.25663706212e-6
#: Coulomb constant 1 / (4 pi eps0), N m^2 / C^2
COULOMB = 1.0 / (4.0 * math.pi * EPSILON_0)
#: speed of light, m/s (exact)
LIGHT_SPEED = 299792458.0
#: elementary charge, C (SI 2019, exact)
ELEMENTARY_CHARGE = 1.602176634e-19
#: Bohr radius, m (CODATA 2022, the value scipy.constants gives)
BOHR_RADIUS = 5.29177210544e-11
#: standard gravity, m/s^2 (exact, by definition)
STANDARD_GRAVITY = 9.80665
