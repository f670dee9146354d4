"""The physical body: media and materials, part sizes and masses, limits and their check.

``materials`` holds the documented data (breakdown fields, densities, magnetisations),
``spec`` reads a scene's physical tables, ``limits`` recomputes every limit independently
from a design's written elements, ``realism`` estimates what the idealised theorem leaves
out, ``bom`` lists the parts.
"""
