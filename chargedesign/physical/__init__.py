"""The physical body: media and materials, part sizes and masses, limits and their check.

``materials`` holds the documented data (breakdown fields, densities, magnetisations),
``coulomb`` the Coulomb field (direct and matrix-product forms), ``field_bounds`` the applied
field's largest magnitude over a region, ``limits`` recomputes every limit independently
from a design's written elements, ``realism`` estimates what the idealised theorem leaves
out, ``bom`` lists the parts.
"""
