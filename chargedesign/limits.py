"""Caps on requested work, shared by every reader and command (light: no sympy, no numpy).

Each cap is documented in docs/reliability.md; where raising it makes sense a command-line
option does so explicitly (named beside the cap).
"""

from __future__ import annotations

#: highest degree of any field (the exact derivation of conditions grows like degree^3; the
#: check and simulation evaluate Legendre terms per orientation): design, check, simulate,
#: show and export all refuse a longer ``legendre`` list
MAX_FIELD_DEGREE = 6
#: orientations the forward check samples (``check --orientations``); 1000 is the default
MAX_ORIENTATIONS = 1_000_000
#: output samples of a simulation (``simulate --samples``, ``[simulation] samples``)
MAX_SAMPLES = 1_000_000
#: fixed steps of a run: ``t_end / step`` (``[simulation] step``, ``--step``)
MAX_STEPS = 100_000_000
#: elements drawn by ``show`` (each is a sphere or arrow mesh); ``show --max-elements`` raises it
MAX_SHOW_ELEMENTS = 20_000
#: candidates of an ``linf`` design (a dense problem: 2469 candidates took 15 s, 9900 more than
#: 600 s on this machine); ``design --max-linf-candidates`` raises it
MAX_LINF_CANDIDATES = 5_000
#: degree of exactness of continuous bodies' quadrature (``check --quadrature-order``): the
#: nodes grow like degree^3
MAX_QUADRATURE_ORDER = 64
