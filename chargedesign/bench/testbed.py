"""Testbed benchmarks: the sampled loop's accuracy and what its Monte Carlo costs.

The unit-scale case (``examples/scenes/unit_scale.toml``'s parameters, the simulation's
default start on I3 = 0, the platform's inertia exactly diag(2C, 2C, C)):

1. the plain zero-order hold against the predictive command, noise-free, no delay, over
   20 s at 100 Hz and 1 kHz (2 s at 100 Hz and 400 Hz with ``quick``): their I4 drifts, the
   order each falls with the control period, and times as ratios to the ZOH run of the same
   rate (the baseline in the same run). The issue's outside measurement for the plain ZOH is
   4.3e-2 (100 Hz) and 4.3e-3 (1 kHz);
2. the command on the embedded testbed scene, every stage timed (the tilt search of the
   planned motions, the layout, the loop's runs, the requirement sweep, the window search
   with its recomputed design, the verdict, and the files); ``quick`` shortens its horizon
   to 5 s with 4 seeds;
3. a closed-loop run of 100 control periods (100 Hz, predictive command, tactical gyro,
   attitude noise, 1 um imbalance, bearing drag, 16-bit torque quantisation) and a 100-seed
   Monte Carlo of the same loop in one batch (10 seeds with ``quick``); the baseline is the
   ideal continuous loop over the same time by adaptive DOP853.
"""

from __future__ import annotations

import math
import tempfile
import time
from typing import Any

import numpy as np

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import LoopSettings, continuous_loop, initial_state, run_loop
from chargedesign.airbearing.report import write_testbed
from chargedesign.airbearing.run import default_testbed_scene, testbed_from_scene
from chargedesign.bench.common import UNIT_SCALE, BenchTable, measured
from chargedesign.formatting import PLAIN, fmt
from chargedesign.physical.drag import bearing_drag
from chargedesign.scene import load_scene
from chargedesign.scene.keys import KEY
from chargedesign.scene.testbed import GYRO_GRADES


def _setup() -> tuple[Any, np.ndarray]:
    params = UNIT_SCALE
    inertia = np.diag([2.0, 2.0, 1.0])
    plant = Plant(params, inertia, inertia)
    return plant, initial_state(params, np.array([0.36, 0.48, 0.8]), 0.6, -0.4)


def _timed(plant: Any, x0: np.ndarray, settings: Any, runs: int = 1) -> tuple[Any, float]:
    run, seconds, _ = measured(run_loop, plant, x0, settings, runs=runs, seed=0)
    return run, seconds


def zoh_against_predictive(quick: bool) -> BenchTable:
    plant, x0 = _setup()
    rates, t_end = ((100.0, 400.0), 2.0) if quick else ((100.0, 1000.0), 20.0)
    rows, drift = [], {}
    for rate in rates:
        base = None
        for command in ("zoh", "predictive"):
            settings = LoopSettings(rate_Hz=rate, delay_s=0.0, t_end_s=t_end, command=command)
            run, seconds = _timed(plant, x0, settings)
            base = seconds if base is None else base
            drift[command, rate] = float(run.I4_drift[0])
            rows.append([rate, command, t_end, drift[command, rate], seconds, seconds / base])
    ratio = math.log(rates[1] / rates[0])
    orders = {
        c: math.log(drift[c, rates[0]] / drift[c, rates[1]]) / ratio for c in ("zoh", "predictive")
    }
    return BenchTable(
        title=f"Testbed loop: ZOH against predictive command, unit-scale case, {fmt(t_end, PLAIN)}"
        " s",
        columns=["rate Hz", "command", "t_end s", "I4 drift", "seconds", "time / ZOH's"],
        rows=rows,
        notes=[
            f"measured order in the control period: ZOH {orders['zoh']:.3f}, predictive "
            f"{orders['predictive']:.3f}",
            "outside measurement (issue 23), plain ZOH over 20 s: 4.3e-2 at 100 Hz, 4.3e-3 at "
            "1 kHz",
            "no delay, no noise, no disturbance; plant by fixed-step DOP853 between samples",
        ],
    )


def _loop_settings(rate: float, t_end: float) -> LoopSettings:
    """The benchmark's loop: predictive command, tactical gyro, 1 um imbalance, 16-bit torque."""
    arw, bias = GYRO_GRADES["tactical"]
    return LoopSettings(
        rate_Hz=rate,
        delay_s=1e-3,
        t_end_s=t_end,
        command="predictive",
        gyro_arw=arw,
        gyro_bias=bias,
        attitude_noise=5e-5,
        imbalance_m=1e-6,
        drag_N_m_s=bearing_drag(0.05, 1e-5),
        total_mass_kg=20.0,
        max_torque=5.0,
        resolution=2 * 5.0 / 2**16,
    )


def monte_carlo(quick: bool) -> BenchTable:
    plant, x0 = _setup()
    rate, periods = 100.0, 100
    t_end = periods / rate
    settings = _loop_settings(rate, t_end)
    t0 = time.perf_counter()
    continuous_loop(plant, x0, t_end, 101)
    base = time.perf_counter() - t0
    seeds = 10 if quick else 100
    rows = []
    for runs in (1, seeds):
        run, seconds = _timed(plant, x0, settings, runs)
        rows.append(
            [
                runs,
                periods,
                float(np.median(run.I4_drift)),
                float(np.percentile(run.I4_drift, 95)),
                seconds,
                base,
                seconds / base,
                seconds / runs,
            ]
        )
    return BenchTable(
        title=f"Testbed loop: one run and a {seeds}-seed Monte Carlo of {periods} control periods",
        columns=[
            "runs",
            "periods",
            "I4 drift median",
            "I4 drift p95",
            "seconds",
            "continuous loop s (baseline)",
            "time / baseline",
            "seconds per run",
        ],
        rows=rows,
        notes=[
            "unit-scale case at 100 Hz, 1 ms delay, predictive command, tactical gyro, 5e-5 rad "
            "attitude noise, 1 um imbalance (20 kg), Couette bearing drag, 16-bit torque",
            "the runs of a Monte Carlo go together as one numpy batch (one time loop)",
        ],
    )


#: the quick run's overrides of the embedded scene's [testbed] table (a smoke run)
QUICK_TESTBED: dict[str, Any] = {
    KEY.t_end_s: 2.0,
    "seeds": 2,
    "requirement_rates_Hz": [10.0, 50.0],
    "requirement_seeds": 1,
}


def embedded_command(quick: bool) -> BenchTable:
    """``chargedesign testbed`` on the embedded scene: the stages' seconds and the total."""
    overrides: dict[str, Any] = QUICK_TESTBED if quick else {}
    t0 = time.perf_counter()
    result = testbed_from_scene(load_scene(default_testbed_scene()), **overrides)
    built = time.perf_counter() - t0
    files = 0.0
    if not quick:  # the pictures and the animation are most of a quick run's time
        with tempfile.TemporaryDirectory() as folder:
            t0 = time.perf_counter()
            write_testbed(result, folder)
            files = time.perf_counter() - t0
    rows = [[stage, seconds] for stage, seconds in result.seconds.items()]
    rows += [["verdict and the rest of the build", built - sum(result.seconds.values())]]
    if not quick:
        rows += [["files (json, report, pictures, gif)", files]]
    rows += [["total", built + files]]
    return BenchTable(
        title="Testbed command on the embedded scene"
        + (
            " (2 s horizon, 2 seeds, requirements at 10 and 50 Hz, 1 seed; no files)"
            if quick
            else ""
        ),
        columns=["stage", "seconds"],
        rows=rows,
        notes=[
            f"verdict: {result.verdict.line[:120]}",
            "the planned motions' stage includes the tilt search (the horizon doubling until "
            "the largest tilt settles) and the stable equilibria (chargedesign.topology)",
            "the process's imports (about 1 s) are not counted",
        ],
    )


def run(quick: bool = False) -> list[BenchTable]:
    return [zoh_against_predictive(quick), embedded_command(quick), monte_carlo(quick)]
