"""Caps on requested work, shared by every reader and command (light: no sympy, no numpy).

Each cap is documented in docs/reliability.md; where raising it makes sense a command-line
option does so explicitly (named beside the cap).
"""

from __future__ import annotations

from typing import NamedTuple

from chargedesign.formatting import PLAIN, fmt
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS

#: highest degree of any field (the exact derivation of conditions grows like degree^3; the
#: check and simulation evaluate Legendre terms per orientation): design, check, simulate,
#: show and export all refuse a longer ``legendre`` list
MAX_FIELD_DEGREE = 6
#: orientations the forward check samples (``check --orientations``); 1000 is the default
MAX_ORIENTATIONS = 1_000_000
#: output samples of a simulation (``simulate --samples``, ``[simulation] samples``)
MAX_SAMPLES = 1_000_000
#: perturbed bodies per tolerance level of the Monte Carlo (``tolerance --samples``; memory:
#: about 11 kB per body and level for the ensemble integration's states)
MAX_TOLERANCE_SAMPLES = 2000
#: tolerance levels of the Monte Carlo (``tolerance --levels``)
MAX_TOLERANCE_LEVELS = 6
#: fixed steps of a run: ``t_end / step`` (``[simulation] step``, ``--step``)
MAX_STEPS = 100_000_000
#: elements drawn by ``show`` (each is a sphere or arrow mesh); ``show --max-elements`` raises it
MAX_SHOW_ELEMENTS = 20_000
#: candidates of an ``linf`` design (a dense problem: 2469 candidates took 15 s, 9900 more than
#: 600 s on this machine); ``design --max-linf-candidates`` raises it
MAX_LINF_CANDIDATES = 5_000
#: candidates of a body whose frontier is located: the charges' minmax that bounds it is a
#: cone program dense in every candidate, and its optimum uses nearly all of them (so no
#: working set helps): 2.9 s of CPU at 257 candidates, 55 s at 925, unfinished after 300 s at
#: 1,935 (docs/benchmarks.md, "The charges' minmax by columns"). ``design`` above it writes the
#: body without its frontier and says so; ``frontier`` refuses such a scene before the work
MAX_FRONTIER_CANDIDATES = 1_000
#: degree of exactness of continuous bodies' quadrature (``check --quadrature-order``): the
#: nodes grow like degree^3
MAX_QUADRATURE_ORDER = 64
#: candidate points of a ``[body]`` region (the condition matrices are dense, rows x points:
#: 250 000 points and 40 conditions take 80 MB per copy)
MAX_CANDIDATES = 250_000
#: elements (charges, masses, dipoles, continuous bodies) of a design.json read by any command:
#: the most candidates a design has; a file of 1e6 charges (50 MB) kept ``check`` busy past
#: 60 s with no word
MAX_DESIGN_ELEMENTS = MAX_CANDIDATES
#: periods of the fastest rate of a body (n, K, sqrt|kappa|, ..., |omega(0)|) a simulation may
#: cover: ``t_end * rate / (2 pi)``; ``simulate --max-periods`` raises it. The default scene
#: once asked for 5.7e6 (t_end 5e7 s at |(p, q)| = 0.72 rad/s): 36 million steps, 596 s on
#: this shared machine. Measured here with taylor: about 6 steps a period on the default body
#: (256 elements, 0.1 ms a step), 34 on the unit-scale one (35 elements): 1e5 periods is a
#: few minutes of CPU at most; the default run (20 periods) takes seconds
MAX_PERIODS = 100_000
#: orbits per level of ``simulate --atlas`` (each is a run of t_end)
MAX_ATLAS_ORBITS = 10_000
#: points of one sweep (grid x random samples), counted before they are built; ``sweep
#: --max-points`` raises it (every point's scene is validated before any runs)
MAX_SWEEP_POINTS = 100_000
#: workers of a sweep (``--workers``): each is a process with its own copy of the library
#: (about 150 MB); past this the machine only thrashes
MAX_WORKERS = 64
#: frames of ``show --animate`` (each is a full render)
MAX_FRAMES = 10_000


def _number(x: float) -> str:
    """An integer as its digits (a seed's 4294967295), anything else as %g."""
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e10 else f"{fmt(x, PLAIN)}"


class OptionRange(NamedTuple):
    """The accepted values of one numeric command-line option (inclusive unless open)."""

    lo: float
    hi: float
    lo_open: bool = False
    hi_open: bool = False

    def text(self) -> str:
        left = "(" if self.lo_open else "["
        right = ")" if self.hi_open else "]"
        return f"{left}{_number(self.lo)}, {_number(self.hi)}{right}"

    def holds(self, value: float) -> bool:
        above = value > self.lo if self.lo_open else value >= self.lo
        below = value < self.hi if self.hi_open else value <= self.hi
        return above and below


_POSITIVE = OptionRange(0.0, 1e30, lo_open=True)
_SEED = OptionRange(0, 2**32 - 1)
_RELATIVE = OptionRange(0.0, 1.0, hi_open=True)

#: the range of every numeric option, by command and option (argparse ``dest``): checked by
#: the CLI before a command runs and appended to each option's ``--help``
#: (docs/reliability.md lists them)
OPTION_RANGES: dict[str, dict[str, OptionRange]] = {
    "design": {
        "n_charges": OptionRange(1, MAX_DESIGN_ELEMENTS),
        "max_charge": _POSITIVE,
        "total_mass": _POSITIVE,
        "total_charge": OptionRange(-1e30, 1e30),
        "max_linf_candidates": OptionRange(1, MAX_DESIGN_ELEMENTS),
    },
    "check": {
        # a loose --tol (even > 1) is a deliberate way to see a broken body pass
        "tol": _POSITIVE,
        "orientations": OptionRange(1, MAX_ORIENTATIONS),
        "seed": _SEED,
        # 0 is a one-node rule: too low for most bodies, and then the check fails (exit 1),
        # which is the point of giving it
        "quadrature_order": OptionRange(0, MAX_QUADRATURE_ORDER),
    },
    "simulate": {
        "t_end": _POSITIVE,
        "tol": OptionRange(0.0, 0.1, lo_open=True),
        "rtol": OptionRange(1e-16, 0.1),
        "atol": OptionRange(0.0, 1.0, lo_open=True),
        "step": _POSITIVE,
        "samples": OptionRange(2, MAX_SAMPLES),
        "orbits": OptionRange(1, MAX_ATLAS_ORBITS),
        "off_level": OptionRange(-1e30, 1e30),
        "max_periods": OptionRange(1, 1e12),
    },
    "show": {
        "gamma": OptionRange(-1e30, 1e30),
        "size": OptionRange(16, 16384),
        "frames": OptionRange(1, MAX_FRAMES),
        "fps": OptionRange(0.0, 1000.0, lo_open=True),
        "max_elements": OptionRange(1, MAX_DESIGN_ELEMENTS),
    },
    "tolerance": {
        "target": OptionRange(0.0, 1.0, lo_open=True, hi_open=True),
        "samples": OptionRange(1, MAX_TOLERANCE_SAMPLES),
        "t_end": _POSITIVE,
        "seed": _SEED,
        # relative errors of material properties (one standard deviation): a 100 % error
        # would allow a negative susceptibility, density or magnetisation
        **dict.fromkeys(MATERIAL_ERROR_KEYS, _RELATIVE),
    },
    "frontier": {
        "realised_fraction": OptionRange(0.0, 1.0, lo_open=True, hi_open=True),
        "realised_gravity": OptionRange(0.0, 100.0),
    },
    "sweep": {
        "workers": OptionRange(1, MAX_WORKERS),
        "chunk": OptionRange(1, MAX_SWEEP_POINTS),
        "max_points": OptionRange(1, 1e9),
        "scheduler_timeout": OptionRange(0.0, 3600.0, lo_open=True),
    },
}
