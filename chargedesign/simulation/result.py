"""The result of a simulation: trajectory, integrals, drift monitors and output files.

Drift definitions (all maxima over the output samples, t = 0 the first sample):

- ``I1_rel_drift = max |I1(t) - I1(0)| / max_t T(t)``: energy error relative to the largest
  kinetic energy ``T = 1/2 omega . I omega`` (the potential carries an arbitrary constant, so
  ``|I1(0)|`` is no scale); absolute when the body never moves.
- ``I2_max_dev = max ||gamma|^2 - 1|`` (rounding level: gamma is built from the quaternion).
- ``I3_max = max |I3(t)|`` (J s): on the level ``I3 = 0`` it is the distance from the level;
  ``I3_max_dev = max |I3(t) - I3(0)|``.
- ``I4_rel_drift = max |I4(t) - I4(0)| / |I4(0)|`` (absolute when ``I4(0) = 0``).

Axes: ``axes = "inertial"`` (the states as integrated) or ``"turning"`` (a frame body's motion
read in axes turning at ``axes_rate`` about Z, :mod:`.axes`; the integrals are then the
turning axes', I4 with n = ``axes_rate``). The summary, ``trajectory.npz`` and
``trajectory.csv`` (column ``axes_rate``, 1/s, 0 for inertial axes) say which.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.files import atomic_directory, atomic_path
from chargedesign.formatting import CELL, PLAIN, ROUGH, fmt
from chargedesign.params import Parameters
from chargedesign.results import Result
from chargedesign.scene.keys import KEY
from chargedesign.simulation.integrate import STATE_NAMES
from chargedesign.validation import input_error

INTEGRAL_NAMES = ("I1", "I2", "I3", "I4")


@dataclass(repr=False)
class SimulationResult(Result):
    """One simulated trajectory.

    Attributes
    ----------
    times : ndarray, shape (T,)
        Sample times, s.
    omega : ndarray, shape (T, 3)
        Angular velocity in body axes, 1/s.
    gamma : ndarray, shape (T, 3)
        Unit vector of space Z in body axes.
    rotation : ndarray, shape (T, 3, 3)
        Body-to-space rotations (``rotation[k].T @ e_Z == gamma[k]``).
    quaternion : ndarray, shape (T, 4)
        The integrated quaternions ``(w, x, y, z)`` (their norm is monitored, not reset).
    integrals : ndarray, shape (T, 4)
        ``I1`` (J), ``I2``, ``I3`` (J s, physical canonical momentum about Z), ``I4`` (1/s^4).
    kinetic : ndarray, shape (T,)
        Kinetic energy, J.
    effects : list of str
        The effects that were computed.
    notes : list of str
        Skipped effects and other remarks.
    events : list of dict
        E.g. ``{"kind": "singular_plane", "t": ..., "gamma3": ...}``.
    axes : str
        ``inertial`` or ``turning``: the axes ``omega``, ``rotation`` and the integrals are
        read in.
    axes_rate : float
        Their rate about Z, 1/s (0 for inertial axes).
    larmor : dict or None
        The simulated design's Larmor reading ``{"reading", "rate"}`` (None: none given).
    """

    times: np.ndarray
    omega: np.ndarray
    gamma: np.ndarray
    rotation: np.ndarray
    quaternion: np.ndarray
    integrals: np.ndarray
    kinetic: np.ndarray
    effects: list[str]
    notes: list[str] = field(default_factory=list)
    events: list[dict[str, Any]] = field(default_factory=list)
    parameters: Parameters = field(default_factory=Parameters)
    route: str = "reduced"
    method: str = "DOP853"
    rtol: float = 0.0
    atol: float = 0.0
    t_end: float = 0.0
    steps: int = 0
    rhs_evaluations: int = 0
    seconds: float = 0.0
    level: float | None = None
    poincare: np.ndarray | None = None
    poincare_section: str | None = None
    source: str = ""
    #: what was simulated and where it came from (``designed_from_scene``, ``counts``, ...)
    body: dict[str, Any] | None = None
    #: tolerance of the taylor method (None: machine epsilon, or another method)
    tol: float | None = None
    #: monitors (see :mod:`.monitors`): {name: {"integral", "requested", "drift", "reason"}}
    monitors: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: seconds spent compiling the taylor integrator (0 when reused from this process)
    compile_seconds: float = 0.0
    axes: str = "inertial"
    axes_rate: float = 0.0
    larmor: dict[str, Any] | None = None

    @property
    def completed(self) -> bool:
        """True when the run reached ``t_end`` (no terminal event)."""
        return not any(e.get("terminal") for e in self.events)

    def drift(self) -> dict[str, float]:
        """Drift monitors (see the module docstring for the definitions)."""
        I = self.integrals
        d = np.abs(I - I[0])
        kin = float(np.max(self.kinetic)) if len(self.kinetic) else 0.0
        i4_0 = abs(float(I[0, 3]))
        return {
            "I1_rel_drift": float(np.max(d[:, 0]) / (kin if kin > 0.0 else 1.0)),
            "I2_max_dev": float(np.max(np.abs(I[:, 1] - 1.0))),
            "I3_max": float(np.max(np.abs(I[:, 2]))),
            "I3_max_dev": float(np.max(d[:, 2])),
            "I4_rel_drift": float(np.max(d[:, 3]) / (i4_0 if i4_0 > 0.0 else 1.0)),
            "quaternion_norm_max_dev": float(
                np.max(np.abs(np.einsum("ij,ij->i", self.quaternion, self.quaternion) - 1.0))
            ),
        }

    def _initial_record(self) -> dict[str, Any]:
        """The summary's ``initial``: I1, I3, I4, omega and gamma at the first sample."""
        return {
            "I1": float(self.integrals[0, 0]),
            "I3": float(self.integrals[0, 2]),
            "I4": float(self.integrals[0, 3]),
            "omega": self.omega[0].tolist(),
            "gamma": self.gamma[0].tolist(),
        }

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary; the contract's keys come first.

        ``I4_rel_drift`` is a number where I4 is an integral of the run or was asked for
        (``monitors``), else None with the reason in ``I4_reason``.
        """
        d = self.drift()
        i4 = self.monitors.get("I4")
        i4_drift: float | None = d["I4_rel_drift"]
        if i4 is not None and i4.get("drift") is None:
            i4_drift = None
        out: dict[str, Any] = {
            "I4_rel_drift": i4_drift,
            "I3_max": d["I3_max"],
            "effects": list(self.effects),
            "I1_rel_drift": d["I1_rel_drift"],
            "I2_max_dev": d["I2_max_dev"],
            "I3_max_dev": d["I3_max_dev"],
            "quaternion_norm_max_dev": d["quaternion_norm_max_dev"],
            "monitors": {k: dict(v) for k, v in self.monitors.items()},
            "initial": self._initial_record(),
            "level": None if self.level is None else f"I3={fmt(self.level, PLAIN)}",
            KEY.t_end: self.t_end,
            "t_reached": float(self.times[-1]),
            "completed": self.completed,
            "route": self.route,
            "method": self.method,
            "rtol": self.rtol,
            "atol": self.atol,
            "tol": self.tol,
            "compile_seconds": self.compile_seconds,
            "steps": self.steps,
            "rhs_evaluations": self.rhs_evaluations,
            "seconds": self.seconds,
            "samples": len(self.times),
            "events": [dict(e) for e in self.events],
            "notes": list(self.notes),
            "parameters": self.parameters.as_dict(),
            "source": self.source,
            "axes": self.axes,
            "axes_rate": self.axes_rate,
            "larmor": None if self.larmor is None else dict(self.larmor),
        }
        if i4 is not None and "reason" in i4:
            out["I4_reason"] = i4["reason"]
        case_f = self.monitors.get("F", {})
        if case_f.get("drift") is not None:  # a case design: its own integral's drift
            out["F_rel_drift"] = case_f["drift"]
        if self.poincare is not None:
            out["poincare_points"] = len(self.poincare)
        if self.body is not None:
            out["body"] = dict(self.body)
        return out

    # ------------------------------------------------------------------ result protocol
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the :meth:`summary` (what ``chargedesign simulate --json`` prints)."""
        return self.summary()

    def _summary(self) -> dict[str, Any]:
        d = self.drift()
        return {
            "effects": list(self.effects),
            "t_reached": float(self.times[-1]),
            "samples": len(self.times),
            "I4_rel_drift": d["I4_rel_drift"],
            "I3_max": d["I3_max"],
            "method": self.method,
            "completed": self.completed,
            "axes": self.axes,
        }

    def _text(self) -> str:
        return summary_text(self.summary())

    def plot(self, ax: Any = None) -> Any:
        """The integrals' deviations against time (:func:`plot_integrals`): four panels, or
        together on a log scale in ``ax``; returns the Axes."""
        return plot_integrals(self, ax=ax)

    # ------------------------------------------------------------------ files
    def trajectory_csv(self) -> str:
        """The trajectory as CSV text (one row per sample; the last column ``axes_rate`` is
        the rate of the axes the row is read in, 1/s: 0 for inertial axes)."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        header = ["t", "p", "q", "r", "gamma1", "gamma2", "gamma3"]
        header += [f"R{i}{j}" for i in range(1, 4) for j in range(1, 4)]
        header += [*INTEGRAL_NAMES, "axes_rate"]
        writer.writerow(header)
        table = np.column_stack(
            [
                self.times,
                self.omega,
                self.gamma,
                self.rotation.reshape(-1, 9),
                self.integrals,
                np.full(len(self.times), self.axes_rate),
            ]
        )
        for row in table:
            writer.writerow([repr(float(v)) for v in row])
        return buf.getvalue()

    def write(
        self,
        out_dir: str | os.PathLike[str],
        *,
        trajectory: bool = True,
        plot: bool = True,
        poincare: bool = True,
        poincare_axes: tuple[str, str] = ("gamma2", "q"),
    ) -> list[Path]:
        """Write the outputs into ``out_dir`` atomically; returns the paths written.

        Files: ``summary.json`` always; ``trajectory.npz`` (keys t, omega, gamma, rotation,
        integrals, quaternion, axes, axes_rate) and ``trajectory.csv``; ``integrals.png``;
        ``poincare.png`` when a section was recorded.
        """
        import json

        names: list[str] = []
        target = Path(out_dir)
        with atomic_directory(target) as stage:
            if trajectory:
                np.savez(
                    stage / "trajectory.npz",
                    t=self.times,
                    omega=self.omega,
                    gamma=self.gamma,
                    rotation=self.rotation,
                    integrals=self.integrals,
                    quaternion=self.quaternion,
                    axes=np.array(self.axes),
                    axes_rate=np.array(self.axes_rate),
                )
                (stage / "trajectory.csv").write_text(self.trajectory_csv(), encoding="utf-8")
                names += ["trajectory.npz", "trajectory.csv"]
            if plot:
                plot_integrals(self, stage / "integrals.png")
                names.append("integrals.png")
            if poincare and self.poincare is not None:
                plot_poincare(self, stage / "poincare.png", poincare_axes)
                names.append("poincare.png")
            summary = self.summary()
            summary["files"] = [str(target / n) for n in [*names, "summary.json"]]
            (stage / "summary.json").write_text(
                json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8"
            )
            names.append("summary.json")
        return [target / n for n in names]


def _integral_series(result: SimulationResult) -> list[tuple[np.ndarray, str]]:
    """The four integrals' deviations from their initial values, each with its label."""
    I = result.integrals
    kin = float(np.max(result.kinetic)) or 1.0
    i4_0 = abs(float(I[0, 3])) or 1.0
    return [
        ((I[:, 0] - I[0, 0]) / kin, "(I1 - I1(0)) / max T"),
        (I[:, 1] - 1.0, "|gamma|^2 - 1"),
        (I[:, 2] - I[0, 2], "I3 - I3(0)  [J s]"),
        ((I[:, 3] - I[0, 3]) / i4_0, "(I4 - I4(0)) / |I4(0)|"),
    ]


def _save_png(fig: Any, path: str | os.PathLike[str]) -> None:
    """The figure as PNG at ``path``, written atomically."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100)


def _figure(path: Any, figsize: tuple[float, float]) -> Any:
    """A new Figure: pyplot's (shown in notebooks) when drawing for a user, a bare Agg one
    (no pyplot state, no display) when only writing a file."""
    if path is None:
        import matplotlib.pyplot as plt

        return plt.figure(figsize=figsize)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig


def _deviations_on_one_axes(
    ax: Any, t: np.ndarray, series: list[tuple[np.ndarray, str]], title: str
) -> None:
    """The integrals' absolute deviations together on one log-scale Axes."""
    for values, label in series:
        # drifts are exactly zero at t = 0 and may be at rounding: floor them for the log
        ax.semilogy(t, np.maximum(np.abs(values), 1e-300), lw=0.8, label=label)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("|deviation from t = 0|")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    ax.set_title(title, fontsize=9)


def plot_integrals(
    result: SimulationResult, path: str | os.PathLike[str] | None = None, *, ax: Any = None
) -> Any:
    """The four integrals' deviations from their initial values against time.

    Parameters
    ----------
    result : SimulationResult
    path : path, optional
        Also write the figure there as PNG.
    ax : matplotlib Axes or sequence of 4 Axes, optional
        One Axes: the absolute deviations together on a log scale; four: one panel each (the
        layout of a new figure when ``ax`` is None).

    Returns
    -------
    matplotlib Axes, or ndarray of 4 Axes
    """
    t = result.times
    series = _integral_series(result)
    level = "" if result.level is None else f", level I3 = {fmt(result.level, PLAIN)}"
    title = f"Integrals along the motion ({', '.join(result.effects) or 'free'}{level})"
    if ax is not None and not isinstance(ax, (list, tuple, np.ndarray)):
        _deviations_on_one_axes(ax, t, series, title)
        if path is not None:
            _save_png(ax.figure, path)
        return ax
    if ax is None:
        fig = _figure(path, (8, 8))
        axes = fig.subplots(4, 1, sharex=True)
        fig.suptitle(title)
    else:
        axes = np.ravel(ax)
        if len(axes) != 4:
            raise input_error("ax", "one Axes or a sequence of 4", f"{len(axes)} axes")
        fig = axes[0].figure
    for panel, (values, label) in zip(axes, series, strict=True):
        panel.plot(t, values, lw=0.8)
        panel.set_ylabel(label, fontsize=8)
        panel.grid(True, alpha=0.3)
        panel.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    axes[-1].set_xlabel("t [s]")
    if ax is None:
        fig.tight_layout()
    if path is not None:
        _save_png(fig, path)
    return axes


def plot_poincare(
    result: SimulationResult,
    path: str | os.PathLike[str] | None = None,
    coordinates: tuple[str, str] = ("gamma2", "q"),
    *,
    ax: Any = None,
) -> Any:
    """The Poincare section points in two state coordinates (``STATE_NAMES``).

    Draws into ``ax`` when given (else a new figure), writes a PNG to ``path`` when given, and
    returns the Axes.
    """
    for name in coordinates:
        if name not in STATE_NAMES:
            raise input_error("coordinates", "names among " + ", ".join(STATE_NAMES), name)
    pts = result.poincare if result.poincare is not None else np.zeros((0, 7))
    ix, iy = (1 + STATE_NAMES.index(a) for a in coordinates)
    if ax is None:
        ax = _figure(path, (6, 6)).subplots()
    ax.plot(pts[:, ix], pts[:, iy], ".", ms=2)
    ax.set_xlabel(coordinates[0])
    ax.set_ylabel(coordinates[1])
    ax.set_title(f"Poincare section {result.poincare_section} = 0 (upward), {len(pts)} points")
    ax.grid(True, alpha=0.3)
    if path is not None:
        ax.figure.tight_layout()
        _save_png(ax.figure, path)
    return ax


def _setup_lines(s: dict[str, Any], body: dict[str, Any]) -> list[str]:
    """What was simulated and how, the axes it is read in and the body designed for it."""
    effects = ", ".join(s["effects"]) or "none (torque-free)"
    if s["method"] == "taylor":
        tol = s.get("tol")
        how = f"taylor (heyoka), tol {'machine epsilon' if tol is None else format(tol, 'g')}"
    else:
        how = f"{s['method']}, rtol {fmt(s['rtol'], PLAIN)}, atol {fmt(s['atol'], PLAIN)}"
    lines = [f"simulated: {effects} ({s['route']} route, {how})"]
    larmor = s.get("larmor") or {}
    if s.get("axes") == "turning":
        lines.append(
            f"axes: turning at n = {fmt(s['axes_rate'], PLAIN)} 1/s about Z (frame body: "
            f"its own physics at n = 0, read as omega - n gamma; I1, I3, I4 with n = "
            f"{fmt(s['axes_rate'], PLAIN)}; the start is given in these axes)"
        )
    elif larmor.get("reading") == "frame":
        lines.append(
            f"axes: inertial (frame body: its own physics at n = 0, integrals with n = 0; "
            f"--axes turning reads it at n = {fmt(larmor['rate'], PLAIN)})"
        )
    if body.get("designed_from_scene"):
        c = body["counts"]
        lines.append(
            f"body: designed from the scene's [body] ({body['shape']}, {body['candidates']} "
            f"candidates): {c['charges']} charges, {c['dipoles']} dipoles, {c['masses']} masses, "
            f"residual {fmt(body['residuals']['max_after_polish'], ROUGH)}"
        )
    return lines


def _drift_lines(s: dict[str, Any]) -> list[str]:
    """The time span and effort, and the integrals' drifts."""
    return [
        f"t = 0 .. {fmt(s['t_reached'], PLAIN)} s of {fmt(s[KEY.t_end], PLAIN)} s: "
        f"{s['steps']} steps, "
        + (
            f"{fmt(s['seconds'])} s (+ {fmt(s['compile_seconds'])} s compile)"
            if s["method"] == "taylor"
            else f"{s['rhs_evaluations']} evaluations, {fmt(s['seconds'])} s"
        ),
        (
            f"I4 relative drift {fmt(s['I4_rel_drift'])}"
            if s["I4_rel_drift"] is not None
            else f"I4 relative drift not reported: {s.get('I4_reason', 'no integral')}"
        )
        + f"; I3 max |I3| {fmt(s['I3_max'])} J s"
        + (f" (level {s['level']})" if s["level"] else "")
        + f", drift {fmt(s['I3_max_dev'])}",
        f"I1 relative drift {fmt(s['I1_rel_drift'])}; max ||gamma|^2 - 1| {fmt(s['I2_max_dev'])}",
    ] + (
        [f"the case's integral F: relative drift {fmt(s['F_rel_drift'])}"]
        if "F_rel_drift" in s
        else []
    )


def _level_lines(s: dict[str, Any], body: dict[str, Any]) -> list[str]:
    """Whether I4 is an integral on the run's level of I3, and how to leave the level."""
    realises_theorem = {"mu", "V", "inertia"} <= set(body.get("realises", ()))
    if s["level"] == "I3=0" and (s["effects"] == ["theorem"] or realises_theorem):
        # a level of the order of C omega with omega ~ 1/s
        example = 0.5 * float(s["parameters"].get("C", 1.0))
        return [
            f"on I3 = 0 the theorem's I4 is an integral; --off-level {fmt(example, PLAIN)} "
            "starts off the level"
        ]
    if s["level"] is not None and s["level"] != "I3=0" and realises_theorem:
        return [
            f"{s['level'].replace('=', ' = ')} is off the theorem's level I3 = 0: I4 is no "
            "integral there, I1 and I3 are"
        ]
    return []


def summary_text(s: dict[str, Any]) -> str:
    """The text ``chargedesign simulate`` prints, from a :meth:`SimulationResult.summary`
    (with ``files`` when the run wrote some)."""
    body = s.get("body") or {}
    lines = _setup_lines(s, body) + _drift_lines(s)
    for event in s["events"]:
        lines.append(f"event: {event['kind']} at t = {fmt(event['t'], CELL)} s")
    lines += _level_lines(s, body)
    notes = s["notes"]
    if body.get("designed_from_scene"):
        # already said on the body line
        notes = [n for n in notes if not n.startswith("body designed from the scene's")]
    for name, m in (s.get("monitors") or {}).items():
        if name in ("energy", "gamma_norm", "I3", "I4") or m.get("drift") is None:
            continue
        kind = "integral" if m.get("integral") else "asked for, no integral here"
        lines.append(f"{name}: drift {fmt(m['drift'])} ({m.get('scale', 'relative')}; {kind})")
    lines += [f"note: {n}" for n in notes]
    lines += [f"wrote {f}" for f in s.get("files", [])]
    return "\n".join(lines)
