"""The air-bearing testbed: a platform on a spherical air bearing whose reaction wheels make it
move as the theorem says (``chargedesign testbed``, ``cd.testbed``; docs/testbed.md).

The ``[testbed]`` table is read with the scene (:mod:`chargedesign.scene.testbed`, its keys
declared in :mod:`chargedesign.scene.keys`). Modules, one concern each: :mod:`.bearing` (tilt,
pedestal axis, keep-out cone, motions that fit, the tilt map), :mod:`.layout` (planned motions;
wheels, ballast and posts around the bearing), :mod:`.mounts` (posts and their bending),
:mod:`.platform` (platform and ballast: the mass program), :mod:`.dynamics` (plant, command
law, a case of (ep) as the plant's model), :mod:`.loop` (the sampled loop with sensors,
estimator, motors, wheel limits and disturbances), :mod:`.wheels` (array, geometry and sizing),
:mod:`.balance` (linear response: balance and placement tolerances), :mod:`.requirements`
(grade x rate sweep), :mod:`.verdict` (requirements against the state of the art, the verdict,
the window), :mod:`.result` (:class:`TestbedResult`), :mod:`.report` (files and pictures),
:mod:`.run` (the stage).
"""

from __future__ import annotations

# nothing imported here: the stage is chargedesign.airbearing.run, the result
# chargedesign.airbearing.result
__all__: list[str] = []
