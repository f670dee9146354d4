"""The testbed's result (the one result protocol): testbed.json's content, text, HTML."""

from __future__ import annotations

import re
import textwrap
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.airbearing.actuators import catalogue
from chargedesign.airbearing.bearing import TiltMap
from chargedesign.airbearing.dynamics import CaseModel
from chargedesign.airbearing.layout import Layout, Plan
from chargedesign.airbearing.loop import LoopRun
from chargedesign.airbearing.platform import Ballast, Platform
from chargedesign.airbearing.requirements import Requirements
from chargedesign.airbearing.verdict import Requirement, Verdict, Window
from chargedesign.airbearing.wheels import PlannedNeeds, WheelNeeds
from chargedesign.formatting import PLAIN, PRECISE, fmt, fmt_length
from chargedesign.params import Parameters
from chargedesign.results import Result, json_ready
from chargedesign.scene.keys import KEY
from chargedesign.scene.testbed import SOURCES, TestbedOptions


def _quantiles(x: np.ndarray) -> dict[str, float]:
    return {
        "I4_relative_drift_median": float(np.median(x)),
        "I4_relative_drift_p95": float(np.percentile(x, 95)),
        "I4_relative_drift_max": float(np.max(x)),
    }


@dataclass(repr=False)
class TestbedResult(Result):
    """An air-bearing testbed: platform, ballast, wheels, loop runs, requirements.

    ``runs`` holds the loop ensembles by name: ``zoh_noise_free``, ``predictive_noise_free``
    (one run each: no noise, no disturbances, no quantisation) and ``nominal`` (the scene's
    command, sensors, disturbances and quantisation, ``seeds`` runs). See docs/testbed.md.
    """

    parameters: Parameters
    options: TestbedOptions
    platform: Platform
    ballast: Ballast
    inertia_total: np.ndarray
    com_total: np.ndarray
    wheel_axes: np.ndarray
    wheel_limits: tuple[float, float, float]
    needs: WheelNeeds  # the scene's own motion (the runs' start)
    planned: PlannedNeeds  # every planned motion (the wheels are sized for the largest)
    initial_state: np.ndarray
    runs: dict[str, LoopRun]
    requirements: Requirements | None
    tolerances: dict[str, Any]
    ideal_states: np.ndarray
    seconds: dict[str, float] = field(default_factory=dict)
    layout: Layout | None = None
    plan: Plan | None = None
    compliance_offset_m: float = 0.0
    state_of_the_art: list[Requirement] = field(default_factory=list)
    verdict: Verdict = field(default_factory=lambda: Verdict(False, None, "not assessed"))
    window: Window | None = None
    windows: list[Window] = field(default_factory=list)
    window_check: dict[str, Any] = field(default_factory=dict)  # the recommended, recomputed
    tilt_map: TiltMap | None = None
    case: CaseModel | None = None  # a case of (ep) flown instead of the theorem

    __test__ = False  # not a pytest class

    @property
    def total_mass(self) -> float:
        return self.platform.mass_kg + self.ballast.total_mass

    @property
    def flown(self) -> str:
        """What the wheels make the platform fly: the theorem's parameters or a case."""
        if self.case is None:
            return str(self.parameters)
        r = self.case.record
        return (
            f"case {self.case.name} (inertia {r.get('inertia_kg_m2')} kg m^2, V = {r.get('V')}, "
            f"level {r.get('level')}, flown on I3 = {fmt(self.case.level_value, PLAIN)})"
        )

    @property
    def monitored(self) -> str:
        """The monitored integral's name: the theorem's I4, or the case's F."""
        return "I4" if self.case is None else f"F (case {self.case.name})"

    @property
    def turns(self) -> float:
        """The run's length in turns of the motion, ``t_simulated |omega(0)| / 2 pi``."""
        rate = float(np.linalg.norm(self.initial_state[:3]))
        return self.runs["nominal"].t_simulated_s * rate / (2.0 * np.pi)

    def _loop(self, name: str) -> dict[str, Any]:
        run = self.runs[name]
        out: dict[str, Any] = {"I4_relative_drift": float(run.I4_drift.max())}
        if name == "nominal" or len(run.I4_drift) > 1:  # an ensemble: its spread
            out = _quantiles(run.I4_drift)
        turns = max(self.turns, 1e-300)
        out["I4_relative_drift_per_turn"] = float(np.median(run.I4_drift)) / turns
        out["I3_max_J_s"] = float(run.I3_max.max())
        out["I3_max_per_turn_J_s"] = float(run.I3_max.max()) / turns
        out["wheel_torque_max_N_m"] = float(run.wheel_torque_max.max())
        out["wheel_momentum_max_N_m_s"] = float(run.wheel_momentum_max.max())
        out["runs"] = len(run.I4_drift)
        return out

    def _results(self) -> dict[str, Any]:
        """testbed.json's ``results``: the runs, the wheels' peaks and needs."""
        o = self.options
        nominal = self.runs["nominal"]
        return {
            "initial_state": self.initial_state.tolist(),
            KEY.t_end_s: o.t_end_s,
            "turns": self.turns,
            "command": o.command,
            **{name: self._loop(name) for name in self.runs},
            "wheel_momentum_max_N_m_s": float(nominal.wheel_momentum_max.max()),
            "wheel_torque_max_N_m": float(nominal.wheel_torque_max.max()),
            "wheel_needs": self._wheel_needs(),
            KEY.planned_motions: [
                {"initial_state": start, **_needs(motion), **self._tilt(k)}
                for k, (start, motion) in enumerate(
                    zip(self.planned.starts, self.planned.motions, strict=True)
                )
            ],
            KEY.target_I4_drift: o.target_I4_drift,
            "t_simulated_s": self.runs["nominal"].t_simulated_s,
            **self._estimation(),
        }

    def _tilt(self, k: int) -> dict[str, Any]:
        if self.plan is None:
            return {}
        m = self.plan.motions[k]
        return {"tilt_max_deg": m.tilt_max_deg, "horizon_s": m.horizon_s, "tilt_settled": m.settled}

    def _estimation(self) -> dict[str, Any]:
        """The estimator's residual and convergence time, the calibrated bias's error."""
        run = self.runs["nominal"]
        out: dict[str, Any] = {}
        if run.offset_error is not None:
            assert run.offset_error_index is not None
            curve = np.median(run.offset_error, axis=0)
            times = run.times[run.offset_error_index]
            final = float(curve[-1])
            above = np.flatnonzero(curve > 2.0 * final)
            settle = (
                float(times[above[-1] + 1]) if above.size and above[-1] + 1 < len(times) else 0.0
            )
            out["centre_of_mass_estimator"] = {
                "residual_offset_m": final,
                "convergence_time_s": settle,
                "residual_includes": "the mounts' compliance left after its estimate",
                "offset_before_m": self.options.imbalance_m,
                "method": "recursive least squares of (r_c, b, K) on the integrated torque "
                "balance; weight torque, posts' bending and drag fed forward",
            }
        if run.bias_error is not None:
            out["gyro_bias_residual_rad_per_s"] = float(np.median(run.bias_error))
        return out

    def _wheel_needs(self) -> dict[str, Any]:
        """The largest needs over the planned motions, and which motion has each."""
        planned = self.planned
        most = planned.motions[planned.momentum_motion]
        return {
            "torque_N_m": planned.torque,
            "momentum_N_m_s": planned.momentum,
            "momentum_norm_N_m_s": most.momentum_norm,
            "momentum_bound_N_m_s": most.momentum_bound,
            "torque_motion": planned.torque_motion,
            "momentum_motion": planned.momentum_motion,
            "motions": len(planned.motions),
        }

    def to_dict(self) -> dict[str, Any]:
        results = self._results()
        o = self.options
        arw, bias = o.gyro
        torque, momentum, resolution = self.wheel_limits
        return json_ready(
            {
                "parameters": self.parameters.as_dict(),
                "platform": {
                    "mass_kg": self.platform.mass_kg,
                    "inertia_kg_m2": self.platform.inertia,
                    "com_m": self.platform.com,
                    "radius_m": self.platform.radius_m,
                },
                "ballast": {
                    "positions": self.ballast.positions,
                    "masses": self.ballast.masses,
                    "radii": self.ballast.radii,
                    "material": self.ballast.material,
                    "density_kg_m3": self.ballast.density,
                    "mounts": [] if self.layout is None else self.layout.ballast_mounts.to_list(),
                },
                "bearing": None
                if self.layout is None
                else {
                    **self.layout.bearing_dict(o, self.total_mass),
                    "tilt_map": None if self.tilt_map is None else self.tilt_map.to_dict(),
                },
                "wheels": {
                    "axes": self.wheel_axes,
                    **self._wheel_layout(),
                    KEY.max_torque_N_m: torque,
                    KEY.max_momentum_N_m_s: momentum,
                    KEY.torque_resolution_N_m: resolution,
                    KEY.motor_bandwidth_Hz: o.motor_bandwidth_Hz,  # null: ideal torque sources
                    "friction_N_m": o.wheel_friction_N_m or 0.0,
                },
                "control": {KEY.rate_Hz: o.rate_Hz, KEY.delay_s: o.delay_s, "command": o.command},
                "sensors": {
                    KEY.gyro_grade: o.gyro_grade,
                    KEY.gyro_arw_rad_per_sqrt_s: arw,
                    KEY.gyro_bias_rad_per_s: bias,
                    KEY.attitude_sensor: o.attitude_sensor,
                    KEY.attitude_noise_rad: o.attitude[0],
                    KEY.attitude_rate_Hz: o.attitude[1],
                },
                "disturbances": {KEY.imbalance_m: o.imbalance_m, KEY.drag_N_m_s: o.drag},
                "inertia_total_kg_m2": self.inertia_total,
                "com_total_m": self.com_total,
                "total_mass_kg": self.total_mass,
                "results": results,
                "requirements": None if self.requirements is None else self.requirements.to_dict(),
                "tolerances": self.tolerances,
                "mounts_offset_m": self.compliance_offset_m,
                "state_of_the_art": [r.to_dict() for r in self.state_of_the_art],
                "verdict": self.verdict.to_dict(),
                "actuators": [a.to_dict() for a in catalogue()],
                "window": None
                if self.window is None
                else {
                    **self.window.to_dict(),
                    "recommended_recomputed": self.window_check,
                    "styles": {
                        w.style: {
                            k: v
                            for k, v in w.to_dict().items()
                            if k not in ("rates", "sizes", "masses")
                        }
                        for w in self.windows
                    },
                },
                "sources": SOURCES,
                "seconds": self.seconds,
                **({} if self.case is None else {"case": dict(self.case.record)}),
            }
        )

    def _wheel_layout(self) -> dict[str, Any]:
        if self.layout is None:
            return {}
        w = self.layout.wheels
        return {
            "positions": w.positions,
            "radii": w.radii,
            "disc_radii_m": w.disc_radii,
            "masses_kg": w.masses,
            "spin_inertia_kg_m2": w.spin_inertia,
            "mounts": self.layout.wheel_mounts.to_list(),
        }

    def _summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "buildable": self.verdict.buildable,
            "total_mass_kg": self.total_mass,
            "ballast_parts": len(self.ballast.masses),
            "wheel_torque_N_m": self.wheel_limits[0],
            "wheel_momentum_N_m_s": self.wheel_limits[1],
        }
        for name, run in self.runs.items():
            out[f"{name}_I4_drift"] = float(np.median(run.I4_drift))
        return out

    def _text(self) -> str:
        o = self.options
        torque, momentum, _ = self.wheel_limits
        simulated = self.runs["nominal"].t_simulated_s
        lines = [
            self.verdict.line,
            f"air-bearing testbed for {self.flown}",
            f"platform {fmt(self.platform.mass_kg, PLAIN)} kg + ballast"
            f" {fmt(self.ballast.total_mass, PRECISE)} kg "
            f"({len(self.ballast.masses)} {self.ballast.material} spheres) = "
            f"{fmt(self.total_mass, PRECISE)} kg (bearing rated {fmt(o.capacity_kg, PLAIN)}"
            " kg)",
            f"wheels ({o.wheels}): {fmt(torque, PRECISE)} N m, {fmt(momentum, PRECISE)} N m s each"
            " (the "
            f"{len(self.planned.motions)} planned motions need at most "
            f"{fmt(self.planned.torque, PRECISE)} N m (motion {self.planned.torque_motion}), "
            f"{fmt(self.planned.momentum, PRECISE)} N m s (motion {self.planned.momentum_motion}); "
            f"scene's motion: momentum bound {fmt(self.needs.momentum_bound, PRECISE)} N m s)",
            f"loop {fmt(o.rate_Hz, PLAIN)} Hz, delay {fmt(o.delay_s, PLAIN)} s, command"
            f" {o.command}; {self.monitored} relative drift "
            f"over {fmt(simulated, PLAIN)} s simulated ({fmt(self.turns)} turns of the motion"
            + (
                f"; t_end_s = {fmt(o.t_end_s, PLAIN)} s rounded to whole control periods)"
                if abs(simulated - o.t_end_s) > 1e-9 * o.t_end_s
                else ")"
            )
            + ":",
        ]
        if self.layout is not None and self.plan is not None:
            tilt = max(m.tilt_max_deg for m in self.plan.motions)
            lines.insert(
                2,
                f"bearing {self.layout.style}: tilt limit {fmt(self.layout.tilt_limit_deg, PLAIN)}"
                f" deg, pedestal axis {np.round(self.layout.axis, 4).tolist()}; the "
                f"{len(self.plan.motions)} planned motions need at most {fmt(tilt, PRECISE)} deg",
            )
        for name, run in self.runs.items():
            d = run.I4_drift
            spread = (
                f"median {fmt(np.median(d))}, p95 {fmt(np.percentile(d, 95))} ({len(d)} seeds)"
                if len(d) > 1
                else f"{fmt(d[0])}"
            )
            lines.append(f"  {name}: {spread}")
        lines.append(
            "  (nominal: every effect on: gyro noise and bias, attitude sensor, imbalance, drag, "
            "mounts, encoders, quantisation; target "
            f"{fmt(o.target_I4_drift, PLAIN)})"
        )
        tol = self.tolerances
        lines.append(
            f"for {self.monitored} within {fmt(o.target_I4_drift, PLAIN)}: centre of mass within "
            f"{fmt_length(tol[KEY.imbalance_m])} of O, bearing drag below "
            f"{fmt(tol['drag_max_N_m_s'])} N m s (now {fmt(o.drag)}), A - B within "
            f"{fmt(tol['inertia']['A_minus_B_kg_m2'])} kg m^2"
        )
        if self.requirements is not None:
            for grade, rate in self.requirements.lowest_rate_Hz.items():
                need = f"{fmt(rate, PLAIN)} Hz" if rate is not None else "none of the rates tried"
                lines.append(
                    f"  {grade} gyro: lowest loop rate within the target without drag, "
                    f"imbalance and mounts: {need}"
                )
        for r in self.state_of_the_art:
            lines.append(f"  [{'met' if r.met else 'MISSED'}] {r.line()}")
        if self.window is not None:
            lines.append(self.window.line())
        return terminal_text(lines)


#: a source's checked status as the figures carry it inline (moved to one line at the end)
_UNVERIFIED = re.compile(r"\s*\[(?:unverified[^\]]*|[A-Za-z0-9_.\-]+, unverified)\]")


def terminal_text(lines: list[str], width: int = 160) -> str:
    """Lines for a terminal: each wrapped to ``width`` characters; the sources' inline
    ``[unverified ...]`` marks gathered into one closing line (report.md lists the sources)."""
    marks = 0
    out: list[str] = []
    for line in lines:
        marks += len(_UNVERIFIED.findall(line))
        line = _UNVERIFIED.sub("", line)
        indent = " " * (len(line) - len(line.lstrip()))
        out += textwrap.wrap(
            line, width, subsequent_indent=indent + "  ", break_on_hyphens=False
        ) or [""]
    if marks:
        out.append(
            f"({marks} figures above rest on sources not yet checked: report.md and "
            "`chargedesign sources` list every source with its status)"
        )
    return "\n".join(out) + "\n"


def _needs(motion: WheelNeeds) -> dict[str, float]:
    return {
        "torque_N_m": motion.torque,
        "momentum_N_m_s": motion.momentum,
        "momentum_norm_N_m_s": motion.momentum_norm,
        "momentum_bound_N_m_s": motion.momentum_bound,
    }


__all__ = ["TestbedResult"]
