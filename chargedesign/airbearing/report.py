"""The testbed's files: testbed.json, report.md and pictures, written all at once.

``write_testbed(result, out)`` writes into a staging folder that replaces ``out`` in one swap
(:func:`chargedesign.files.atomic_directory`): ``testbed.json``, ``report.md``,
``window.png`` (the feasibility window's shortfall over rate, size and mass),
``drift_vs_rate.png`` (the requirements: drift against control rate, one line per gyro
grade), ``drift_time.png`` (the runs' I4 drift in time), ``wheels.png`` (the wheels' momentum
against its bound), ``testbed.png`` (PyVista: platform, ballast, wheels; skipped with a note
where no off-screen OpenGL is available) and ``motion.gif`` (the emulated motion beside the
ideal one: gamma's trace on the unit sphere).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.airbearing.actuators import catalogue
from chargedesign.airbearing.result import TestbedResult
from chargedesign.files import atomic_directory, atomic_path, write_json_atomic, write_text_atomic
from chargedesign.formatting import FULL, PLAIN, PRECISE, ROUGH, fmt, fmt_length
from chargedesign.model import evaluators
from chargedesign.physical.sources import cite, cited_keys, sources_table_lines
from chargedesign.scene.keys import KEY
from chargedesign.scene.testbed import SOURCES

#: the files a testbed run writes (the picture and animation when they can be drawn)
OUTPUTS = (
    "testbed.json",
    "report.md",
    "drift_vs_rate.png",
    "drift_time.png",
    "wheels.png",
    "testbed.png",
    "tilt_map.png",
    "window.png",
    "motion.gif",
)


def write_testbed(result: TestbedResult, out: str | os.PathLike[str]) -> list[str]:
    """Write the testbed's files into ``out`` (atomically); returns the names written."""
    import matplotlib

    matplotlib.use("Agg")
    notes: list[str] = []
    with atomic_directory(out, drop=OUTPUTS) as stage:
        written = ["testbed.json"]
        write_json_atomic(stage / "testbed.json", result.to_dict())
        if result.requirements is not None:
            plot_requirements(result, stage / "drift_vs_rate.png")
            written.append("drift_vs_rate.png")
        if result.tilt_map is not None:
            plot_tilt_map(result, stage / "tilt_map.png")
            written.append("tilt_map.png")
        if result.window is not None:
            plot_window(result, stage / "window.png")
            written.append("window.png")
        plot_drift(result, stage / "drift_time.png")
        plot_wheels(result, stage / "wheels.png")
        written += ["drift_time.png", "wheels.png"]
        if render_testbed(result, stage / "testbed.png", notes):
            written.append("testbed.png")
        animate_motion(result, stage / "motion.gif")
        written.append("motion.gif")
        write_text_atomic(stage / "report.md", report_markdown(result, written, notes))
        written.append("report.md")
    return written


def plot_requirements(result: TestbedResult, path: Path) -> None:
    import matplotlib.pyplot as plt

    req = result.requirements
    assert req is not None
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for i, grade in enumerate(req.grades):
        ax.loglog(req.rates_Hz, np.maximum(req.drift[i], 1e-17), "o-", label=f"{grade} gyro")
    ax.axhline(req.target, color="k", ls="--", lw=1, label="target")
    ax.set_xlabel("control rate (Hz)")
    ax.set_ylabel(f"I4 relative drift over {fmt(result.options.t_end_s, PLAIN)} s (worst seed)")
    ax.set_title(f"command: {result.options.command}")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    _save(fig, path)


def plot_tilt_map(result: TestbedResult, path: Path) -> None:
    """The bifurcation diagram's (H, I4) plane coloured by the tilt its tori need from the
    pedestal axis, the contour at the bearing's limit, and the planned motions."""
    import matplotlib.pyplot as plt

    m = result.tilt_map
    assert m is not None
    H = np.repeat(m.h[:, None], m.k.shape[1], axis=1)
    keep = np.isfinite(m.tilt)
    h, k, tilt = H[keep], m.k[keep], m.tilt[keep]  # each energy has its own I4 values
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    mesh = ax.tripcolor(h, k, tilt, shading="gouraud", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="tilt the torus needs (deg)")
    if tilt.min() < m.limit_deg < tilt.max():
        ax.tricontour(h, k, tilt, levels=[m.limit_deg], colors="red", linewidths=1.5)
    ax.plot([], [], color="red", label=f"the bearing's limit, {fmt(m.limit_deg, PLAIN)} deg")
    if result.plan is not None:
        starts = np.array([p.start for p in result.plan.motions])
        values = evaluators.integrals(starts, result.parameters)
        ax.plot(values[:, 0], values[:, 3], "w^", mec="k", label="planned motions")
    ax.set_xlabel("H (J)")
    ax.set_ylabel("I4")
    ax.set_title("tori of (H, I4) on I3 = 0 and the tilt they need", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    _save(fig, path)


def plot_window(result: TestbedResult, path: Path) -> None:
    """The recommended window's worst shortfall over (rate, size) and (rate, mass) through
    the recommended design, the contour where it is 1 (inside: below), the scene and the
    recommended design marked."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    w = result.window
    if w is None:
        return
    i, j, k, m = w.best_index()
    rate, size, mass, motion = w.recommended()
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.4), layout="constrained")
    panels = (
        (w.sizes, w.margin[:, :, k, m], "size factor L", size, f"mass x{fmt(mass)}"),
        (w.masses, w.margin[:, j, :, m], "mass factor m", mass, f"size x{fmt(size)}"),
    )
    shortfall = w.margin[:, :, :, m]
    norm = LogNorm(vmin=float(shortfall.min()), vmax=float(shortfall.max()))
    for ax, (ys, grid, label, y_best, fixed) in zip(axes, panels, strict=True):
        mesh = ax.pcolormesh(w.rates, ys, grid.T, norm=norm, cmap="magma_r", shading="auto")
        if grid.min() < 1.0 < grid.max():
            ax.contour(w.rates, ys, grid.T, levels=[1.0], colors="cyan", linewidths=1.5)
        ax.plot([1.0], [1.0], "wo", mec="k", label="the scene")
        ax.plot([rate], [y_best], "c*", mec="k", ms=12, label="recommended")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("rate factor s")
        ax.set_ylabel(label)
        ax.set_title(f"{fixed}, {motion}", fontsize=9)
        ax.legend(fontsize=8, loc="lower left")
    fig.colorbar(mesh, ax=axes, label="worst shortfall (inside the window: < 1)")
    fig.suptitle(
        f"feasibility window, {w.style} bearing"
        + (f": none, best misses by {fmt(float(w.margin[i, j, k, m]))}" if w.empty else ""),
        fontsize=10,
    )
    _save(fig, path)


def plot_drift(result: TestbedResult, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for name, run in result.runs.items():
        curve = np.median(run.I4_drift_curve, axis=0)
        ax.semilogy(run.times[1:], np.maximum(curve[1:], 1e-17), label=name)  # 0 at t = 0
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|I4(t) - I4(0)| / |I4(0)| (median over seeds)")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    _save(fig, path)


def plot_wheels(result: TestbedResult, path: Path) -> None:
    import matplotlib.pyplot as plt

    needs = result.needs
    h = np.linalg.norm(needs.states[:, 6:9], axis=1)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(needs.times, h, label="|h| (ideal loop)")
    share = np.linalg.pinv(result.wheel_axes.T)  # body -> wheels, as the loop shares it
    for k, motion in enumerate(result.planned.motions):
        wheel = np.abs(motion.states[:, 6:9] @ share.T).max(axis=1)
        label = "largest wheel's |h_i|, each planned motion" if k == 0 else None
        ax.plot(motion.times, wheel, color="0.55", lw=0.8, label=label)
    ax.axhline(needs.momentum_bound, color="r", ls="--", lw=1, label="bound |L| + max |J omega|")
    ax.axhline(result.wheel_limits[1], color="k", ls=":", lw=1, label="one wheel's capacity")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("wheel momentum (N m s)")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    _save(fig, path)


def _save(fig: Any, path: Path) -> None:
    import matplotlib.pyplot as plt

    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)


def render_testbed(result: TestbedResult, path: Path, notes: list[str]) -> bool:
    """PyVista picture of the platform shell, ballast spheres and wheels (False if none)."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        # no display: VTK's EGL window, not a failed X attempt (as chargedesign.viz does)
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    try:
        import pyvista as pv

        pv.OFF_SCREEN = True
        plotter = pv.Plotter(off_screen=True, window_size=[800, 600])
    except Exception as exc:  # no pyvista or no OpenGL here: the report says so
        notes.append(f"no 3-D picture ({type(exc).__name__}: {exc})")
        return False
    try:
        _draw_layout(pv, plotter, result)
        u = np.array([0.0, 0.0, 1.0]) if result.layout is None else result.layout.axis
        side = np.cross(u, [0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.cross(u, [1.0, 0.0, 0.0])
        side /= np.linalg.norm(side)
        R = result.platform.radius_m
        plotter.camera_position = [tuple(4.5 * R * side + 1.0 * R * u), (0, 0, 0), tuple(u)]
        plotter.add_legend(size=(0.22, 0.2), bcolor="white")  # type: ignore[call-arg]
        plotter.add_text("body axes; the pedestal axis points up", font_size=9)
        plotter.add_axes()  # type: ignore[call-arg]  # pyvista's decorator confuses mypy
        with atomic_path(path) as tmp:
            plotter.screenshot(str(tmp))
        return True
    except Exception as exc:  # rendering needs OpenGL: keep the other outputs
        notes.append(f"no 3-D picture ({type(exc).__name__}: {exc})")
        return False
    finally:
        plotter.close()


def _draw_layout(pv: Any, plotter: Any, result: TestbedResult) -> None:
    """The platform's shell (with the pedestal's opening), the bearing's ball, the pedestal
    and its keep-out cone (or the full sphere's cup), the ballast and the wheels on their
    posts, in body axes."""
    o, layout = result.options, result.layout
    R, Rb = result.platform.radius_m, o.bearing_radius_m
    u = np.array([0.0, 0.0, 1.0]) if layout is None else layout.axis
    cone = None if layout is None else layout.cone
    shell = pv.Sphere(radius=R, center=(0, 0, 0), theta_resolution=60, phi_resolution=60)
    if cone is not None:  # the opening the pedestal passes through
        alpha = np.radians(cone.half_angle_deg)
        shell = shell.clip(normal=tuple(u), origin=tuple(-u * R * np.cos(alpha)), invert=False)
    plotter.add_mesh(shell, color="lightgrey", opacity=0.25, label="platform shell")
    hub = "bearing ball" if cone is not None else "hub (posts root)"
    plotter.add_mesh(pv.Sphere(radius=Rb), color="steelblue", label=hub)
    if cone is not None:
        length = 1.3 * R
        plotter.add_mesh(
            pv.Cylinder(
                center=tuple(-u * (Rb + length / 2)),
                direction=tuple(u),
                radius=o.pedestal_radius,
                height=length,
            ),
            color="dimgray",
            label="pedestal",
        )
        height = 1.2 * R
        radius = height * np.tan(np.radians(min(cone.half_angle_deg, 80.0)))
        plotter.add_mesh(
            pv.Cone(
                center=tuple(-u * height / 2),
                direction=tuple(u),
                height=height,
                radius=radius,
                resolution=48,
                capping=False,
            ),
            color="red",
            opacity=0.12,
            label="keep-out cone",
        )
    else:  # the full sphere's cup, below
        cup = pv.Sphere(radius=1.04 * R, theta_resolution=60, phi_resolution=60)
        cup = cup.clip(normal=tuple(-u), origin=tuple(-u * 0.5 * R), invert=False)
        plotter.add_mesh(cup, color="dimgray", opacity=0.5, label="air cup")
    b = result.ballast
    for pos, rad in zip(b.positions, b.radii, strict=True):
        plotter.add_mesh(pv.Sphere(radius=float(rad), center=pos), color="goldenrod")
    if layout is None:
        return
    w = layout.wheels
    for pos, axis, disc in zip(w.positions, result.wheel_axes, w.disc_radii, strict=True):
        plotter.add_mesh(
            pv.Cylinder(center=pos, direction=axis, radius=float(disc), height=0.3 * float(disc)),
            color="firebrick",
        )
    for mounts in (layout.ballast_mounts, layout.wheel_mounts):
        for e, s1, s2, d in zip(
            mounts.directions, mounts.root_m, mounts.tip_m, mounts.diameters_m, strict=True
        ):
            plotter.add_mesh(
                pv.Cylinder(
                    center=e * (s1 + s2) / 2,
                    direction=e,
                    radius=float(d) / 2,
                    height=float(s2 - s1),
                ),
                color="black",
            )


def animate_motion(result: TestbedResult, path: Path, frames: int = 40) -> None:
    """GIF: gamma's trace (the vertical seen from the platform) of the emulated run (seed 0
    of the nominal ensemble) beside the ideal continuous loop's, (gamma1, gamma2)."""
    import imageio.v3 as iio
    import matplotlib.pyplot as plt

    run = result.runs["nominal"]
    assert run.states is not None
    emulated = run.states[0, :, 3:6]
    ideal = result.ideal_states[:, 3:6]
    t_em = run.times
    t_id = result.needs.times
    images = []
    fig, ax = plt.subplots(figsize=(4, 4), dpi=60)
    (ideal_line,) = ax.plot([], [], color="tab:blue", lw=1, label="ideal")
    (emulated_line,) = ax.plot([], [], color="tab:red", lw=1, ls="--", label="emulated")
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="lower right")
    title = ax.set_title("", fontsize=9)
    for k in np.linspace(0, len(t_em) - 1, frames).astype(int):  # one figure, lines updated
        j = int(np.searchsorted(t_id, t_em[k]))
        ideal_line.set_data(ideal[: j + 1, 0], ideal[: j + 1, 1])
        emulated_line.set_data(emulated[: k + 1, 0], emulated[: k + 1, 1])
        title.set_text(f"gamma1, gamma2  t = {t_em[k]:.2f} s")
        fig.canvas.draw()
        rgba = fig.canvas.buffer_rgba()  # type: ignore[attr-defined]  # the Agg canvas
        images.append(np.asarray(rgba)[..., :3].copy())
    plt.close(fig)
    with atomic_path(path) as tmp:
        iio.imwrite(tmp, np.stack(images), extension=".gif", duration=80, loop=0)


def report_markdown(result: TestbedResult, written: list[str], notes: list[str]) -> str:
    """The human report (Markdown)."""
    lines = ["# Air-bearing testbed", "", f"**{result.verdict.line}**", ""]
    lines += ["```", str(result).rstrip(), "```", ""]
    lines += _case_section(result)
    lines += _state_of_the_art_section(result) + _bearing_section(result)
    lines += _platform_section(result) + _wheel_section(result) + _loop_section(result)
    lines += _estimator_section(result) + _requirements_section(result) + _window_section(result)
    lines += ["## Files", ""] + [f"- `{name}`" for name in [*written, "report.md"]]
    lines += [f"- note: {n}" for n in notes]
    lines += ["", "## Sources of the defaults", ""]
    lines += [f"- {k}: {v}" for k, v in SOURCES.items()]
    lines += _actuator_section()
    # inline a figure carries its key only; its checked status is in the one sources section
    text, keys = cited_keys("\n".join(lines))
    if keys:
        text += "\n" + "\n".join(["", "## Sources", *sources_table_lines(keys)])
    return text + "\n"


def _actuator_section() -> list[str]:
    """The actuator catalogue the window searched."""
    lines = [
        "",
        "## Actuator catalogue",
        "",
        "The wheels of every design the window tries are the lightest of these covering its "
        "torque and momentum on each axis (or the nearest where none does):",
        "",
        "| actuator | kind | torque (N m) | momentum (N m s) | mass (kg) | checked |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for a in catalogue():
        status = " (in development)" if a.in_development else ""
        marks = "; ".join(cite(k) for k in a.keys)
        lines.append(
            f"| {a.name}{status} | {a.kind} | {fmt(a.torque)} | {fmt(a.momentum)} | "
            f"{fmt(a.mass)} | {'yes' if a.checked else 'no'} {marks} |"
        )
    return lines


def _case_section(result: TestbedResult) -> list[str]:
    """What a case's testbed flies (nothing for the theorem's)."""
    if result.case is None:
        return []
    r = result.case.record
    return [
        f"## The case: {r['name']}",
        "",
        f"- source: {r.get('source') or 'not given'};",
        f"- inertia {r['inertia_kg_m2']} kg m^2, V = {r['V']}, l . gamma = {r['l_dot_gamma']};",
        f"- claimed integral F = {r['integral']}, level {r['level']}; flown on I3 = "
        f"{fmt(result.case.level_value, PLAIN)} (a general case on the area-zero level);",
        "- the wheels apply the case's torque `gamma x dV/dgamma - omega x mu` and what the "
        "platform's own inertia J lacks: `h' = -J f - omega x (J omega + h)`, f the case's "
        "Euler-Poisson right-hand side (its V and l differentiated in sympy, then numeric);",
        "- **every I4 figure below (runs, tolerances, requirements, pictures) is the relative "
        "drift of the case's F**; testbed.json's `case` says so;",
        "- no tilt map: it is drawn on the theorem's bifurcation diagram, which a case does not "
        "have here yet (the planned motion is the scene's start, its tilt over a settled "
        "horizon as for the theorem).",
        "",
    ]


def _state_of_the_art_section(result: TestbedResult) -> list[str]:
    lines = [
        "## Requirements against the state of the art",
        "",
        "tolerance: met when best <= required; capacity: met when required <= best. The nominal "
        "Monte Carlo runs with every effect on (gyro noise and bias, the attitude sensor, "
        "imbalance, drag, the posts' bending, encoders, quantisation).",
        "",
        "| requirement | kind | required | best | unit | met | source |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in result.state_of_the_art:
        source = r.source + (f" ({r.unmet_reason})" if r.unmet_reason else "")
        lines.append(
            f"| {r.name} | {r.kind} | {fmt(r.required)} | {fmt(r.best)} | {r.unit} | "
            f"{'yes' if r.met else '**no**'} | {source} |"
        )
    return [*lines, ""]


def _bearing_section(result: TestbedResult) -> list[str]:
    layout, plan = result.layout, result.plan
    if layout is None or plan is None:
        return []
    d = layout.bearing_dict(result.options, result.total_mass)
    origin = (
        "the scene's start"
        if plan.origin == "scene"
        else "planned near the stable relative equilibrium on I3 = 0 (the scene gives no start)"
    )
    lines = [
        "## Bearing and planned motions",
        "",
        f"- {layout.style} bearing, tilt limit {fmt(layout.tilt_limit_deg, PLAIN)} deg "
        f"({layout.source}); pedestal axis u = {np.round(layout.axis, 5).tolist()} (body axes), "
        "the centre of the smallest cap holding every planned motion's vertical;",
    ]
    if layout.cone is not None:
        lines.append(
            f"- keep-out cone about -u, half-angle {fmt(layout.cone.half_angle_deg, PRECISE)} deg "
            f"(tilt limit + the pedestal's {fmt(result.options.pedestal_radius * 1e3, PLAIN)} mm "
            f"radius seen from the {fmt(result.options.bearing_radius_m * 1e3, PLAIN)} mm ball): "
            "every ballast part, wheel and post is clear of it;"
        )
    else:
        fs = d["full_sphere"]
        lines.append(
            f"- full sphere: ball {fmt(fs['ball_diameter_m'], PLAIN)} m across (largest built "
            f"about {fmt(fs['largest_ball_diameter_m'], PLAIN)} m), sphericity "
            f"{fmt_length(fs['sphericity_m'])}, payload inside "
            f"{fmt(fs['payload_inside_kg'])} kg, cup half-angle "
            f"{fmt(fs['cup_half_angle_deg'], PLAIN)} deg ({fmt(fs['cup_coverage_sr'])} sr), air "
            f"film drag {fmt(fs['air_film_drag_N_m_s'])} N m s;"
        )
    lines += [
        f"- load {fmt(result.total_mass, PRECISE)} kg of "
        f"{fmt(result.options.capacity_kg, PLAIN)} kg rated;",
        f"- planned motions ({origin}); the largest tilt is read over a horizon that doubles "
        "until a longer one raises it by less than 0.05 deg:",
        "",
        "| motion | start [p, q, r, gamma] | largest tilt (deg) | horizon (s) |",
        "| --- | --- | --- | --- |",
    ]
    for k, m in enumerate(plan.motions):
        start = ", ".join(fmt(v, PRECISE) for v in m.start)
        lines.append(
            f"| {k} | [{start}] | {fmt(m.tilt_max_deg, PRECISE)} | {fmt(m.horizon_s, PLAIN)} |"
        )
    posts = layout.ballast_mounts
    lines += [
        "",
        f"- mounts: {len(posts.masses)} {posts.material} posts under the ballast and "
        f"{len(layout.wheel_mounts.masses)} under the wheels ({fmt(float(posts.masses.sum()))} kg, "
        "in the platform's mass and inertia); bending under the turning gravity moves the "
        f"centre of mass by up to {fmt_length(result.compliance_offset_m)} normal to gravity.",
        "",
    ]
    return lines


def _estimator_section(result: TestbedResult) -> list[str]:
    est = result.to_dict()["results"].get("centre_of_mass_estimator")
    if est is None:
        return []
    return [
        "## Centre-of-mass estimator",
        "",
        f"Recursive least squares of the offset, the drag and the posts' bending on the "
        f"integrated torque balance, fed forward: from {fmt_length(est['offset_before_m'])} "
        f"(the balancing floor) the estimate's largest error normal to gravity ends at "
        f"{fmt_length(est['residual_offset_m'])} (median of the nominal seeds; the posts' "
        f"bending left after its estimate included), within twice that from "
        f"{fmt(est['convergence_time_s'], PLAIN)} s on.",
        "",
    ]


def _window_section(result: TestbedResult) -> list[str]:
    if result.window is None:
        return []
    return [
        "## Feasibility window",
        "",
        "The design scaled in time (rate x s: n, K x s, kappa x s^2), size (x L) and mass "
        "(x m: inertia x m L^2), flying all the planned motions or one alone, on each bearing "
        "style; each requirement by its law (chargedesign/airbearing/verdict.py). At every "
        "design the wheels are chosen from the actuator catalogue (below): the lightest covering "
        "its torque and momentum, its mass (one per axis) counted within the platform's. The "
        "nominal drift is measured at the scene's design only.",
        "",
        *[f"- {w.line()}" for w in result.windows],
        "",
        f"Recommended: {result.window.line()}",
        "",
        *_unverified_binding(result),
        *_recomputed_lines(result.window_check),
    ]


def _unverified_binding(result: TestbedResult) -> list[str]:
    """Say so when the recommended design's binding limit, or any figure it rests on, is
    unverified (not read in its source) or the scene's own."""
    if result.window is None:
        return []
    rec = result.window.to_dict()["recommended"]
    lines = []
    source = rec["binding_source"]
    if not source["checked"]:
        lines.append(
            f"The binding limit ({rec['binding']}) rests on an unverified figure: {source['key']}."
        )
    if rec["unverified"]:
        lines.append(
            "The recommended design rests on unverified figures: "
            + ", ".join(rec["unverified"])
            + "."
        )
    return [*lines, ""] if lines else []


def _recomputed_lines(check: dict) -> list[str]:
    if not check:
        return []
    rows = [
        f"| {name} | {fmt(r['law'])} | {fmt(r['recomputed'])} |"
        for name, r in check["required"].items()
    ]
    return [
        f"The recommended design recomputed in full (rate x{fmt(check['rate_factor'])}, size "
        f"x{fmt(check['size_factor'])}, mass x{fmt(check['mass_factor'])}, "
        f"{check['motion']}): the laws agree within {fmt(check['largest_law_error'])}.",
        "",
        "| requirement | by the law | recomputed |",
        "| --- | --- | --- |",
        *rows,
        "",
    ]


def _platform_section(result: TestbedResult) -> list[str]:
    o, tol, C = result.options, result.tolerances, result.parameters.C
    diagonal = ", ".join(f"{fmt(x, FULL)}" for x in np.diag(result.inertia_total))
    products = min(tol["inertia"][f"product_{k}_kg_m2"] for k in ("xy", "xz", "yz"))
    place = tol["ballast_placement_m"]
    tightest = int(np.argmin(place["binding"]))
    why = (
        "its balance"
        if place["through_balance"][tightest] <= place["through_inertia"][tightest]
        else "its inertia"
    )
    return [
        "## Platform and ballast",
        "",
        f"- platform: {fmt(o.platform_mass_kg, PLAIN)} kg, envelope radius"
        f" {fmt(o.platform_radius_m, PLAIN)} m; "
        f"ballast {fmt(result.ballast.total_mass, PRECISE)} kg of {result.ballast.material} in "
        f"{len(result.ballast.masses)} spheres;",
        f"- total inertia about O: diag({diagonal}) kg m^2 (target A = B = 2C ="
        f" {fmt(2 * C, PLAIN)}, "
        f"C = {fmt(C, PLAIN)}); centre of mass "
        f"{fmt_length(float(np.linalg.norm(result.com_total)))} from O;",
        f"- for I4 within {fmt(o.target_I4_drift, PLAIN)} over {fmt(o.t_end_s, PLAIN)} s: A - B"
        " within "
        f"{fmt(tol['inertia']['A_minus_B_kg_m2'])} kg m^2, products within {fmt(products)} "
        f"kg m^2, centre of mass within {fmt_length(tol[KEY.imbalance_m])} of O; the tightest "
        f"part (number {tightest}) placed within "
        f"{fmt_length(float(place['binding'][tightest]))} ({why} binds).",
        "",
    ]


def _wheel_section(result: TestbedResult) -> list[str]:
    r = result.to_dict()["results"]
    needs = r["wheel_needs"]
    return [
        "## Wheels",
        "",
        f"- {result.options.wheels} array, sized over {needs['motions']} planned motions "
        "(above; motion 0 is the loop's start);",
        f"- the most torque on one wheel, {fmt(needs['torque_N_m'], PRECISE)} N m, is motion "
        f"{needs['torque_motion']}'s; the most momentum, {fmt(needs['momentum_N_m_s'], PRECISE)} N"
        " m s, "
        f"is motion {needs['momentum_motion']}'s, whose |h| stays below "
        f"|L| + max |J omega| = {fmt(needs['momentum_bound_N_m_s'], PRECISE)} N m s "
        f"(reached {fmt(needs['momentum_norm_N_m_s'], PRECISE)});",
        f"- each wheel's limits are {fmt(result.wheel_limits[0], PRECISE)} N m and "
        f"{fmt(result.wheel_limits[1], PRECISE)} N m s; its momentum saturates at the limit in the "
        "sampled loop;",
        f"- the nominal runs used at most {fmt(r['wheel_torque_max_N_m'], PRECISE)} N m and "
        f"{fmt(r['wheel_momentum_max_N_m_s'], PRECISE)} N m s.",
        "",
    ]


def _loop_section(result: TestbedResult) -> list[str]:
    tol = result.tolerances
    turns = max(result.turns, 1e-300)
    lines = [
        "## The loop",
        "",
        f"Over {fmt(result.runs['nominal'].t_simulated_s, PLAIN)} s simulated, "
        f"{fmt(result.turns)} turns of the motion (t |omega(0)| / 2 pi):",
        "",
        "| run | I4 relative drift | per turn | I3 max (J s) | per turn |",
        "| --- | --- | --- | --- | --- |",
    ]
    for name, run in result.runs.items():
        drift = (
            f"median {fmt(np.median(run.I4_drift))}, p95 {fmt(np.percentile(run.I4_drift, 95))}"
            if len(run.I4_drift) > 1
            else f"{fmt(run.I4_drift[0])}"
        )
        i3 = float(run.I3_max.max())
        per_turn = float(np.median(run.I4_drift)) / turns
        lines.append(f"| {name} | {drift} | {fmt(per_turn)} | {fmt(i3)} | {fmt(i3 / turns)} |")
    return [
        *lines,
        "",
        f"Drag alone would drift I4 by {fmt(tol['drag_drift'])}, the imbalance by "
        f"{fmt(tol['imbalance_drift'])} (linear response along the planned motion): the target "
        f"needs the drag below {fmt(tol['drag_max_N_m_s'])} N m s and the centre of mass within "
        f"{fmt_length(tol[KEY.imbalance_m])} of O (each alone using the whole target).",
        "",
    ]


def _requirements_section(result: TestbedResult) -> list[str]:
    req = result.requirements
    if req is None:
        return []
    lines = [
        "## Requirements",
        "",
        "I4 drift (worst of the seeds) against the control rate, command "
        f"`{result.options.command}`, without drag, imbalance and the posts' bending (their "
        "effects are the nominal run's and the tolerances above); target "
        f"{fmt(req.target, PLAIN)}:",
        "",
        "| gyro | " + " | ".join(f"{fmt(x, PLAIN)} Hz" for x in req.rates_Hz) + " | lowest rate |",
        "| --- " * (len(req.rates_Hz) + 2) + "|",
    ]
    for i, g in enumerate(req.grades):
        low = req.lowest_rate_Hz[g]
        cells = " | ".join(f"{fmt(x, ROUGH)}" for x in req.drift[i])
        lines.append(f"| {g} | {cells} | {'-' if low is None else f'{fmt(low, PLAIN)} Hz'} |")
    return [*lines, ""]


__all__ = [
    "OUTPUTS",
    "animate_motion",
    "plot_drift",
    "plot_requirements",
    "plot_wheels",
    "render_testbed",
    "report_markdown",
    "write_testbed",
]
