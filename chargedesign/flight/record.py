"""The flight of a designed body: its release, release tolerance and observation, recorded.

:func:`add_flight` computes them for a design held in free fall or in orbit (its
``design.support``, :func:`chargedesign.physical.support.support_record`) and records them
as ``design.support["flight"]``: ``release`` (:class:`~.release.Start`), ``tolerance``
(:class:`~.release.ReleaseTolerance`), ``observation`` (:class:`~.observation.Observation`)
and ``lines`` (the words the report's "Flight" section shows). The designer cannot call it
(the integrator service sits above the designer), so the command that writes the design
does, after the design is accepted.
"""

from __future__ import annotations

from typing import Any

from chargedesign.flight.observation import observe
from chargedesign.flight.release import release_start, release_tolerance
from chargedesign.formatting import fmt


def flight_record(design: Any, flight_s: float, marker_radius: float) -> dict[str, Any]:
    """The release, its tolerance and the cameras' reconstruction for ``design`` over a flight
    of ``flight_s`` (s), markers at ``marker_radius`` (m) on the body."""
    params = design.body_parameters
    start = release_start(params, flight_s)
    tolerance = release_tolerance(params, start)
    seen = observe(params, start, marker_radius)
    lines = [
        f"release: on I3 = 0 in {start.name} (h = {fmt(start.h)} J, I4 = {fmt(start.k)} "
        f"1/s^4), {fmt(start.turns)} turns in {fmt(flight_s)} s",
        str(tolerance),
        f"what the cameras would show: {seen}",
    ]
    return {
        "release": start.to_dict(),
        "tolerance": tolerance.to_dict(),
        "observation": seen.to_dict(),
        "lines": lines,
    }


def add_flight(design: Any) -> None:
    """Record the flight in ``design.support["flight"]`` when the design is held in free fall
    (its flight: the microgravity time less the release and the caging); nothing otherwise."""
    support = design.support
    if not support or support.get("style") != "free_fall" or not support.get("flight_s"):
        return
    region = float((design.buildability or {}).get("region_radius_m", 0.0)) or 0.05
    support["flight"] = flight_record(design, float(support["flight_s"]), region)
