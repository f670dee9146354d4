"""The air-bearing testbed: a platform on a spherical air bearing whose reaction wheels make
it move as the theorem says (``chargedesign testbed``, ``cd.testbed``; docs/testbed.md).

Modules, one concern each: :mod:`.options` (the ``[testbed]`` table, its defaults and their
sources, its schema fragment), :mod:`.bearing` (tilt, pedestal axis, keep-out cone, motions
that fit, the tilt map), :mod:`.layout` (planned motions; wheels, ballast and posts around the
bearing), :mod:`.mounts` (posts and their bending), :mod:`.platform` (platform and ballast:
the mass program), :mod:`.dynamics` (plant, command law, fixed-step DOP853), :mod:`.loop`
(the sampled loop with sensors, estimator, motors, wheel limits and disturbances),
:mod:`.wheels` (array, geometry and sizing), :mod:`.balance` (linear response: balance and
placement tolerances), :mod:`.requirements` (grade x rate sweep), :mod:`.verdict`
(requirements against the state of the art, the verdict, the window), :mod:`.result`
(:class:`TestbedResult`), :mod:`.report` (files and pictures), :mod:`.run` (the stage).
"""

from __future__ import annotations

# only the light table parser here (the scene schema imports it); the stage is
# chargedesign.airbearing.run, the result chargedesign.airbearing.result
from chargedesign.airbearing.options import TestbedOptions, table_schema

__all__ = ["TestbedOptions", "table_schema"]
