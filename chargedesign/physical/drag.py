"""The air film's viscous drag of an air bearing (the testbed's bearing and the full sphere's
cup): Couette flow in a thin gap, the torque per unit rate.

Every figure is SI; the viscosity's source is at :data:`AIR_VISCOSITY`.
"""

from __future__ import annotations

import math

from chargedesign.physical.sources import value
from chargedesign.physical.state_of_the_art import FULL_SPHERE

#: dynamic viscosity of air at 20 C, Pa s (sources table: media.viscosity.air, checked)
AIR_VISCOSITY_KEY = "media.viscosity.air"
AIR_VISCOSITY = value(AIR_VISCOSITY_KEY)


def bearing_drag(radius: float, gap: float, viscosity: float = AIR_VISCOSITY) -> float:
    """Viscous drag coefficient (N m s) of a hemispherical air film: ``(4 pi/3) eta R^4 / h``.

    The film's shear stress is ``eta v / h`` with ``v = omega R sin(theta)`` at polar angle
    theta from the spin axis; its torque ``int (eta omega R sin / h) R sin R^2 sin dtheta
    dphi`` over the hemisphere is ``(4 pi / 3) eta R^4 omega / h``.
    """
    return 4.0 * math.pi / 3.0 * viscosity * radius**4 / gap


def cup_half_angle() -> float:
    """The full sphere's cup half-angle, rad (from its coverage, state_of_the_art)."""
    coverage = FULL_SPHERE["cup_coverage_sr"].value
    return math.acos(1.0 - coverage / (2.0 * math.pi))


def cup_drag(radius: float, gap: float) -> float:
    """Couette drag (N m s) of a cup of half-angle a under a ball of radius R, about the
    cup's axis: the hemisphere's ``(4 pi/3) eta R^4 / h`` times the cap's share of
    ``int sin^3``, ``(2/3 - cos a + cos^3 a / 3) / (2/3)`` (a spin about the axis; other axes
    shear the film no more than this order)."""
    c = math.cos(cup_half_angle())
    return (2.0 / 3.0 - c + c**3 / 3.0) / (2.0 / 3.0) * bearing_drag(radius, gap)


__all__ = ["AIR_VISCOSITY", "AIR_VISCOSITY_KEY", "bearing_drag", "cup_drag", "cup_half_angle"]
