"""Many initial states in one call: validation of state sets, ensemble runs and their result.

A scene gives a set of initial states in ``[initial]``::

    [initial]
    states = [[p, q, r, gamma1, gamma2, gamma3], ...]   # 1/s and a direction (normalised)
    # file = "states.csv"   # or a .csv (6 columns, optional header row) or .npy (m, 6) file

Every number is checked (finite, not a bool, six per row) with a one-line error naming the
key and the row. :func:`simulate_ensemble` integrates them all at once: heyoka's batch
integrators (one SIMD lane per state, each with its own step size) on worker threads with the
``taylor`` method, else one batched solve_ivp / Gauss-Legendre call.
"""

from __future__ import annotations

import csv
import io
import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.files import atomic_directory
from chargedesign.formatting import PLAIN, fmt
from chargedesign.results import Result
from chargedesign.scene.keys import KEY
from chargedesign.scene.simulation import check_off_singular_plane, ensemble_states
from chargedesign.scene.states import STATE_COLUMNS
from chargedesign.simulation import monitors as monitors_mod
from chargedesign.simulation.api import (
    initial_state,
    integrate_with_options,
    prepare,
    trajectory_result,
)
from chargedesign.simulation.axes import turning_states
from chargedesign.simulation.result import SimulationResult
from chargedesign.simulation.setup import realised_claims
from chargedesign.simulation.system import quaternion_gamma
from chargedesign.validation import as_array


@dataclass(repr=False)
class EnsembleResult(Result):
    """Many trajectories of one body (see :func:`simulate_ensemble`).

    Attributes
    ----------
    times : ndarray, shape (T,)
    states : ndarray, shape (m, T, 7)
        ``(p, q, r, w, x, y, z)``.
    integrals : ndarray, shape (m, T, 4)
    monitors : list of dict
        Per trajectory, as :func:`.monitors.evaluate`.
    """

    times: np.ndarray
    states: np.ndarray
    integrals: np.ndarray
    monitors: list[dict[str, dict[str, Any]]]
    effects: list[str]
    method: str
    seconds: float
    compile_seconds: float = 0.0
    notes: list[str] = field(default_factory=list)
    events: list[dict[str, Any]] = field(default_factory=list)
    source: str = ""

    def drift(self, name: str) -> np.ndarray:
        """Drift of a monitor per trajectory (NaN where it reports nothing), shape (m,)."""
        return np.array(
            [np.nan if m[name].get("drift") is None else m[name]["drift"] for m in self.monitors]
        )

    def summary(self) -> dict[str, Any]:
        """JSON-ready; the contract's keys first (maxima over the trajectories)."""
        i4 = self.drift("I4")
        reported = np.isfinite(i4)
        out: dict[str, Any] = {
            "I4_rel_drift": float(np.max(i4[reported])) if np.any(reported) else None,
            "I3_max": float(np.max(np.abs(self.integrals[:, :, 2]))),
            "effects": list(self.effects),
            "trajectories": len(self.states),
            "I4_reported_for": int(np.sum(reported)),
        }
        if not np.all(reported):
            # one line: the reasons without their per-trajectory numbers
            reasons = sorted(
                {
                    m["I4"].get("reason", "").split(" (")[0]
                    for m in self.monitors
                    if m["I4"].get("drift") is None
                }
            )
            out["I4_reason"] = (
                f"{int(np.sum(~reported))} of {len(reported)} trajectories: "
                + "; ".join(r for r in reasons if r)
            )
        for name in ("energy", "I3", "kowalevski", "lagrange"):
            d = self.drift(name)
            if np.any(np.isfinite(d)):
                out[f"{name}_max_drift"] = float(np.nanmax(d))
        out.update(
            {
                "method": self.method,
                KEY.t_end: float(self.times[-1]),
                "samples": len(self.times),
                "seconds": self.seconds,
                "compile_seconds": self.compile_seconds,
                "events": [dict(e) for e in self.events],
                "notes": list(self.notes),
                "source": self.source,
            }
        )
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the :meth:`summary` (what ``chargedesign simulate --ensemble --json``
        prints)."""
        return self.summary()

    def _summary(self) -> dict[str, Any]:
        s = self.summary()
        keys = ("trajectories", "I4_rel_drift", "I3_max", "method", KEY.t_end, "seconds")
        return {k: s[k] for k in keys}

    def _text(self) -> str:
        s = self.summary()
        i4 = s["I4_rel_drift"]
        lines = [
            f"ensemble: {s['trajectories']} trajectories, {', '.join(self.effects) or 'free'}, "
            f"{self.method}, t = 0 .. {fmt(s[KEY.t_end], PLAIN)} s in {fmt(s['seconds'])} s "
            f"(+ {fmt(s['compile_seconds'])} s compile)",
            "I4 max relative drift "
            + (f"{fmt(i4)} over {s['I4_reported_for']} trajectories" if i4 is not None else "none")
            + (f" ({s['I4_reason']})" if "I4_reason" in s else ""),
            f"I3 max |I3| {fmt(s['I3_max'])} J s; "
            f"energy max drift {fmt(s.get('energy_max_drift', 0))}",
        ]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)

    def table_csv(self) -> str:
        """One row per trajectory: initial and final state, drifts."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        names = ["energy", "I3", "I4"]
        writer.writerow(
            ["index", *[f"{c}_0" for c in STATE_COLUMNS], *[f"{c}_end" for c in STATE_COLUMNS]]
            + [f"{n}_drift" for n in names]
        )
        for i in range(len(self.states)):
            first, last = self.states[i, 0], self.states[i, -1]
            row: list[Any] = [i]
            for st in (first, last):
                row += [*st[:3].tolist(), *quaternion_gamma(st[None, 3:])[0].tolist()]
            row += [self.monitors[i][n].get("drift") for n in names]
            writer.writerow(["" if v is None else repr(v) for v in row])
        return buf.getvalue()

    def write(self, out_dir: str | os.PathLike[str]) -> list[Path]:
        """``summary.json`` and ``ensemble.csv`` (one row per trajectory)."""
        target = Path(out_dir)
        with atomic_directory(target) as stage:
            (stage / "ensemble.csv").write_text(self.table_csv(), encoding="utf-8")
            summary = self.summary()
            summary["files"] = [str(target / "ensemble.csv"), str(target / "summary.json")]
            (stage / "summary.json").write_text(
                json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8"
            )
        return [target / "ensemble.csv", target / "summary.json"]


def simulate_ensemble(
    source: Any = None,
    states: Any = None,
    *,
    progress: Callable[[float], None] | None = None,
    **kwargs: Any,
) -> EnsembleResult:
    """Simulate a set of initial states of one body in one call.

    Parameters
    ----------
    source
        As for :func:`~chargedesign.simulation.api.simulate`.
    states : array_like, shape (m, 6), optional
        ``(p, q, r, gamma1, gamma2, gamma3)`` per trajectory; default the scene's
        ``[initial] states`` or ``file``.
    **kwargs
        ``effects, t_end, method, tol, rtol, atol, samples, route, gamma3_min, monitors``.
    """

    system, _, _, setup, notes = prepare(source, **kwargs)
    arr = ensemble_states(setup.initial, states)
    rate = setup.axes_rate
    y0 = np.array([initial_state(system, s, rate)[0] for s in arr])
    options = setup.options
    if system.singular:
        g3 = quaternion_gamma(y0[:, 3:])[:, 2]
        bad = np.flatnonzero(np.abs(g3) <= options.gamma3_min)
        if len(bad):
            check_off_singular_plane(
                float(g3[bad[0]]), options.gamma3_min, f"initial.states[{int(bad[0])}]"
            )
    run = integrate_with_options(system, y0, options, progress=progress)
    # the integrator's own time (without a first run's compile, reported apart)
    seconds = float(run.seconds)
    m = len(y0)
    states_out = run.states
    if rate != 0.0:
        # a frame body read in turning axes (see chargedesign.simulation.axes)
        states_out = np.array([turning_states(run.times, run.states[i], rate) for i in range(m)])
    integrals = np.array([system.integrals(states_out[i], rate=rate) for i in range(m)])
    realises = realised_claims(setup, system)
    table = []
    for i in range(m):
        om = states_out[i, :, :3]
        kin = 0.5 * np.einsum("ij,ij->i", om * system.inertia_diagonal(), om)
        ctx = monitors_mod.Context(
            system=system,
            level=None,
            I3_start=float(integrals[i, 0, 2]),
            I3_scale=max(system.C * max(float(np.max(np.abs(om[0]))), 1.0), 1e-300),
            realises=realises,
            axes_rate=rate,
            case=setup.case,
        )
        gamma = quaternion_gamma(states_out[i, :, 3:])
        table.append(monitors_mod.evaluate(ctx, om, gamma, integrals[i], kin, options.monitors))
    extra = dict(run.extra)
    all_notes = list(notes)
    all_notes.extend(extra.get("notes", ()))
    return EnsembleResult(
        times=run.times,
        states=states_out,
        integrals=integrals,
        monitors=table,
        effects=list(system.effects),
        method=str(extra.get("method", options.method)),
        seconds=seconds,
        compile_seconds=float(extra.get("compile_seconds", 0.0)),
        notes=all_notes,
        events=list(run.events),
        source=setup.source,
    )


def simulate_batch(
    source: Any,
    initial_states: Any,
    **kwargs: Any,
) -> list[SimulationResult]:
    """Simulate many trajectories of one body in a single integrator call.

    Parameters
    ----------
    source
        As for :func:`simulate`.
    initial_states : array_like, shape (m, 6)
        ``(p, q, r, gamma1, gamma2, gamma3)`` per trajectory.
    **kwargs
        ``effects``, ``t_end``, ``rtol``, ``atol``, ``method``, ``max_step``, ``step``,
        ``samples``, ``route``, ``gamma3_min``, ``progress``, ``design_progress`` as for
        :func:`simulate`.

    Notes
    -----
    With ``taylor`` (the default) the trajectories run on heyoka batch integrators: each has
    its own step size and a singular-plane event stops only its own trajectory (the others
    keep their last state after it). With the solve_ivp methods one adaptive step size serves
    all trajectories and an event on any trajectory stops the whole batch. For the summaries
    of many trajectories see :func:`chargedesign.simulation.ensemble.simulate_ensemble`.
    """
    progress = kwargs.pop("progress", None)
    states = as_array(initial_states, "initial_states", (None, 6))
    system, _, _, setup, notes = prepare(source, **kwargs)
    y0 = np.array([initial_state(system, s, setup.axes_rate)[0] for s in states])
    options = setup.options
    if system.singular:
        g3 = quaternion_gamma(y0[:, 3:])[:, 2]
        if np.any(np.abs(g3) <= options.gamma3_min):
            bad = int(np.argmin(np.abs(g3)))
            check_off_singular_plane(g3[bad], options.gamma3_min, f"initial_states[{bad}]")
    run = integrate_with_options(system, y0, options, progress=progress)
    return [
        trajectory_result(system, run.times, run.states[i], run, None, setup, notes, None)
        for i in range(len(y0))
    ]
