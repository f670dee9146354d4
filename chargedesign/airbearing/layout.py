"""The testbed's layout: the motions it will run, the pedestal axis, the keep-out cone, and
where every part sits on its mount (chargedesign.airbearing.bearing for the geometry).

:func:`plan_motions` takes the scene's start (refused in one line when its tilt passes the
bearing's limit, with starts that fit offered) or plans starts near the stable relative
equilibrium; :func:`build_layout` places the wheels on their axes, the ballast on sites
clear of the cone and the wheels, and a post under every part, whose mass and inertia join
the platform (the ballast's masses are then closed again on the same sites).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.airbearing.bearing import (
    FULL_SPHERE_PLANNED_DEG,
    KeepOut,
    best_axis,
    clear_of_cone,
    fitting_starts,
    keep_out,
    motion_samples,
    tilt_deg,
)
from chargedesign.airbearing.dynamics import CaseModel, motion_rate
from chargedesign.airbearing.loop import initial_state
from chargedesign.airbearing.mounts import Mounts, radial_posts
from chargedesign.airbearing.platform import (
    Ballast,
    Platform,
    check_fit,
    design_ballast,
    polished,
)
from chargedesign.airbearing.wheels import WheelGeometry, wheel_geometry
from chargedesign.errors import InfeasibleError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.params import Parameters
from chargedesign.physical.drag import cup_drag, cup_half_angle
from chargedesign.physical.state_of_the_art import FULL_SPHERE
from chargedesign.scene.keys import KEY
from chargedesign.scene.testbed import TestbedOptions

#: the turns of the motion the tilt is first read over (the horizon then doubles)
BASE_TURNS = 10.0
#: times the posts and the ballast's masses are closed together
MOUNT_ROUNDS = 4


@dataclass(frozen=True)
class PlannedMotion:
    """A motion the testbed will run: its start (6,), the largest tilt from the pedestal axis
    over the settled horizon (deg), that horizon (s), and its gamma samples."""

    start: np.ndarray
    tilt_max_deg: float
    horizon_s: float
    times: np.ndarray
    gammas: np.ndarray
    settled: bool = True  # a longer horizon no longer raised the tilt (else: the cap)


@dataclass(frozen=True)
class Plan:
    """The planned motions, the pedestal axis u, and where they come from."""

    motions: list[PlannedMotion]
    axis: np.ndarray
    origin: str  # "scene" or "planned"


def _sampled(
    params: Parameters,
    x0: np.ndarray,
    t_end: float,
    axis: np.ndarray | None,
    case: CaseModel | None = None,
) -> Any:
    rate = motion_rate(params, x0[:3], case)
    horizon = max(t_end, BASE_TURNS * 2.0 * math.pi / rate)
    rhs = None if case is None else case.rhs_function()  # a case: its reduced model's motion
    return motion_samples(params, x0, horizon, rate, axis, rhs=rhs)


def plan_motions(params: Parameters, opts: TestbedOptions, case: CaseModel | None = None) -> Plan:
    """The motions and the pedestal axis (see the module docstring). A ``case``'s one
    motion is the scene's start on the case's level (its scene must give one:
    :meth:`~chargedesign.scene.testbed.TestbedOptions.check_case_start`).

    Raises
    ------
    InputError
        The scene's start needs more tilt than the bearing allows (one line: the tilt, the
        limit, and, for the theorem, starts that fit).
    """
    limit = opts.tilt_limit
    if opts.has_start or case is not None:
        assert opts.initial_gamma is not None and opts.initial_p is not None
        assert opts.initial_q is not None
        p, q = opts.initial_p, opts.initial_q
        if case is not None:  # as the case's route always read it: a start of -0.0 is 0.0
            p, q = p or 0.0, q or 0.0
        x0 = initial_state(params, np.array(opts.initial_gamma), p, q, case)
        sampled = _sampled(params, x0, opts.t_end_s, None, case)
        axis = best_axis([sampled.gammas])
        tilt = float(tilt_deg(axis, sampled.gammas).max())
        if case is not None:
            opts.check_case_tilt(case.name, tilt, sampled.horizon_s)
        elif tilt > limit:
            opts.check_start_tilt(tilt, limit, sampled.horizon_s, _alternatives(params, opts))
        motion = PlannedMotion(
            x0, tilt, sampled.horizon_s, sampled.times, sampled.gammas, sampled.settled
        )
        return Plan([motion], axis, "scene")
    reach = min(limit, FULL_SPHERE_PLANNED_DEG)
    count = opts.planned_motions
    tilts = [0.9 * reach * (1.0 - k / count) for k in range(count)]
    starts, gamma_e = fitting_starts(params, tilts)
    samples = [_sampled(params, x0, opts.t_end_s, gamma_e) for x0 in starts]
    axis = best_axis([s.gammas for s in samples])
    if max(float(tilt_deg(axis, s.gammas).max()) for s in samples) > max(
        float(tilt_deg(gamma_e, s.gammas).max()) for s in samples
    ):
        axis = gamma_e
    motions = [
        PlannedMotion(
            x0, float(tilt_deg(axis, s.gammas).max()), s.horizon_s, s.times, s.gammas, s.settled
        )
        for x0, s in zip(starts, samples, strict=True)
    ]
    return Plan(motions, axis, "planned")


def _alternatives(params: Parameters, opts: TestbedOptions) -> str:
    """Starts that fit, for the refusal: one near the stable equilibrium, and the full sphere."""
    try:
        starts, _ = fitting_starts(params, [0.9 * opts.tilt_limit])
    except Exception:  # no stable equilibrium: only the full sphere is offered
        return 'give bearing = "full_sphere" (every attitude)'
    x = starts[0]
    g = ", ".join(fmt(v, PRECISE) for v in x[3:6])
    return (
        f"a start that fits: initial_gamma = [{g}], initial_p = {fmt(x[0], PRECISE)}, "
        f"initial_q = {fmt(x[1], PRECISE)} (tilt {fmt(0.9 * opts.tilt_limit, PLAIN)} deg), "
        'or leave the start out (the tool plans motions that fit), or bearing = "full_sphere"'
    )


@dataclass(frozen=True)
class Layout:
    """Where everything sits: the bearing, the wheels, the ballast and their posts.

    ``shell`` is the bare platform, ``platform`` the shell with every post (what
    testbed.json writes as the platform: the total is it plus the ballast spheres)."""

    style: str
    tilt_limit_deg: float
    axis: np.ndarray
    cone: KeepOut | None
    source: str
    shell: Platform
    platform: Platform
    ballast: Ballast
    wheels: WheelGeometry
    ballast_mounts: Mounts
    wheel_mounts: Mounts

    def allowed(self, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
        return _allowed(self.cone, self.wheels)(centres, radii)

    def bearing_dict(self, opts: TestbedOptions, total_mass: float) -> dict[str, Any]:
        """testbed.json's ``bearing``."""
        out: dict[str, Any] = {
            "style": self.style,
            KEY.tilt_limit_deg: self.tilt_limit_deg,
            "pedestal_axis": self.axis.tolist(),
            "keep_out": None if self.cone is None else self.cone.to_dict(),
            "source": self.source,
            "ball_radius_m": opts.bearing_radius_m,
            KEY.pedestal_radius_m: opts.pedestal_radius if self.cone is not None else None,
            "load_rating_kg": opts.capacity_kg,
            "load_kg": total_mass,
        }
        if self.style == "full_sphere":
            out["full_sphere"] = full_sphere_figures(opts, total_mass)
        return out


def full_sphere_figures(opts: TestbedOptions, total_mass: float) -> dict[str, Any]:
    """The floating ball's own limits: its diameter and sphericity, the payload inside it,
    the cup's coverage, the air film's drag (the cup's Couette film)."""
    R = opts.platform_radius_m
    return {
        "ball_diameter_m": 2.0 * R,
        "largest_ball_diameter_m": FULL_SPHERE["largest_diameter_m"].value,
        "sphericity_m": FULL_SPHERE["sphericity_m"].value,
        "payload_inside_kg": total_mass - opts.platform_mass_kg,
        "cup_half_angle_deg": math.degrees(cup_half_angle()),
        "cup_coverage_sr": FULL_SPHERE["cup_coverage_sr"].value,
        "air_film_drag_N_m_s": cup_drag(R, opts.bearing_gap_m),
        "sources": {k: f.source for k, f in FULL_SPHERE.items()},
    }


def _allowed(cone: KeepOut | None, wheels: WheelGeometry | None) -> Any:
    def allowed(centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
        ok = clear_of_cone(centres, radii, cone)
        if wheels is not None:
            gap = np.linalg.norm(centres[:, None] - wheels.positions[None], axis=-1)
            ok &= (gap >= radii[:, None] + wheels.radii[None]).all(axis=1)
        return ok

    return allowed


def _room(cone: KeepOut | None, centres: np.ndarray) -> np.ndarray | None:
    """Each direction's angular room to the cone, rad (None without a cone)."""
    if cone is None:
        return None
    unit = centres / np.linalg.norm(centres, axis=1, keepdims=True)
    angle = np.arccos(np.clip(unit @ cone.axis, -1.0, 1.0))
    return angle - math.radians(cone.half_angle_deg)


def build_layout(
    params: Parameters,
    opts: TestbedOptions,
    axis: np.ndarray,
    wheel_axes: np.ndarray,
    wheel_momentum: float,
) -> Layout:
    """Wheels, ballast and posts around the bearing (see the module docstring).

    Raises
    ------
    InfeasibleError
        A wheel or a ballast part finds no room clear of the cone inside the envelope.
    """
    style = opts.style
    cone = keep_out(
        axis,
        opts.tilt_limit if opts.bearing != "full_sphere" else 180.0,
        opts.bearing_radius_m,
        opts.pedestal_radius,
    )
    shell = Platform.from_options(opts, axis)
    wheels = wheel_geometry(
        wheel_axes,
        wheel_momentum,
        opts.bearing_radius_m,
        opts.platform_radius_m,
        _allowed(cone, None),
    )

    def posts_under(centres: np.ndarray, radii: np.ndarray, masses: np.ndarray) -> Mounts:
        return radial_posts(
            centres, radii, masses, opts.bearing_radius_m, opts.mount_material, _room(cone, centres)
        )

    wheel_mounts = posts_under(wheels.positions, wheels.radii, wheels.masses)
    allowed = _allowed(cone, wheels)
    base = _with_posts(shell, wheel_mounts)
    ballast = design_ballast(base, params.C, opts, allowed)

    def on_posts(ballast: Ballast) -> tuple[Mounts, Platform, Ballast]:
        """Posts under the ballast as it is, and its masses closed again with them; when
        the same sites cannot absorb the posts (a mass would turn negative), the program
        chooses its sites again with these posts as part of the structure."""
        posts = posts_under(ballast.positions, ballast.radii, ballast.masses)
        platform = _with_posts(base, posts)
        try:
            closed = polished(platform, params.C, opts, ballast.positions, ballast.masses)
        except InfeasibleError:
            closed = design_ballast(platform, params.C, opts, allowed)
        return posts, platform, closed

    for _ in range(MOUNT_ROUNDS):
        posts, platform, ballast = on_posts(ballast)
    check_fit(ballast, opts.platform_radius_m, opts.bearing_radius_m, allowed)
    posts, platform, ballast = on_posts(ballast)
    return Layout(
        style=opts.bearing,
        tilt_limit_deg=opts.tilt_limit if opts.bearing != "full_sphere" else 180.0,
        axis=np.asarray(axis, float),
        cone=cone,
        source=style.source if opts.tilt_limit_deg is None else "the scene's tilt_limit_deg",
        shell=shell,
        platform=platform,
        ballast=ballast,
        wheels=wheels,
        ballast_mounts=posts,
        wheel_mounts=wheel_mounts,
    )


def _with_posts(platform: Platform, posts: Mounts) -> Platform:
    return platform.with_structure(float(posts.masses.sum()), posts.first_moment(), posts.inertia())


__all__ = ["Layout", "Plan", "PlannedMotion", "build_layout", "full_sphere_figures", "plan_motions"]
