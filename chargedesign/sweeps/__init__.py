"""Sweeps: many scenes through one command, on any ``concurrent.futures.Executor``.

>>> from chargedesign.sweeps import load_sweep, make_executor, run_sweep  # doctest: +SKIP
>>> spec = load_sweep("examples/sweeps/theorem_t_end.sweep")               # doctest: +SKIP
>>> handle = make_executor("process", workers=2)                         # doctest: +SKIP
>>> result = run_sweep(spec, "out/sweep", executor=handle)               # doctest: +SKIP

See docs/sweep.md and :mod:`chargedesign.sweeps.runner` for the output layout.
"""

from __future__ import annotations

from chargedesign.sweeps.registry import COMMANDS, resolve
from chargedesign.sweeps.runner import (
    ExecutorHandle,
    SerialExecutor,
    SweepResult,
    make_executor,
    run_chunk,
    run_point,
    run_sweep,
    summary_rows,
    warm_up,
    write_summary,
)
from chargedesign.sweeps.spec import SweepSpec, as_sweep, load_sweep, sweep_from_dict
from chargedesign.vocabulary import SWEEP_EXECUTORS as EXECUTORS

__all__ = [
    "COMMANDS",
    "EXECUTORS",
    "ExecutorHandle",
    "SerialExecutor",
    "SweepResult",
    "SweepSpec",
    "as_sweep",
    "load_sweep",
    "make_executor",
    "resolve",
    "run_chunk",
    "run_point",
    "run_sweep",
    "summary_rows",
    "sweep_from_dict",
    "warm_up",
    "write_summary",
]
