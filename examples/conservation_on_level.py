"""The quartic integral I4 of a designed body: conserved on the level I3 = 0, not off it.

Designs the unit-scale body (examples/scenes/unit_scale.toml), then integrates its motion
from the forces on its own elements
(Lorentz force on the charges, electric force, dipoles in the magnetic field, gravity on the
masses) twice from the same gamma, p, q: once with r chosen so that I3 = 0, once with
I3 = 0.5 J s. Nothing enforces I4 (no projection). The same start is integrated with the
theorem's reduced model (its V and mu) as a cross-check: a body that realises the theorem
moves like it. Run::

    .venv/bin/python examples/conservation_on_level.py [OUT_DIR]

OUT_DIR defaults to $CHARGEDESIGN_OUT, else out/examples/conservation; writes I4_drift.png.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt
import numpy as np

from chargedesign.designer import design_from_scene
from chargedesign.scene import load_scene
from chargedesign.simulation import simulate

#: the mathematical case at unit scale (the embedded default is a slow, buildable SI body)
UNIT_SCENE = Path(__file__).resolve().parent / "scenes" / "unit_scale.toml"

T_END = 50.0  # s
START = {"gamma": [0.36, 0.48, 0.8], "p": 0.6, "q": -0.4}


def relative_i4_drift(result) -> np.ndarray:
    """|I4(t) - I4(0)| / |I4(0)| along a trajectory, shape (T,)."""
    i4 = result.integrals[:, 3]
    return np.abs(i4 - i4[0]) / abs(i4[0])


def main(out_dir: str | None = None) -> int:
    out = Path(out_dir or os.environ.get("CHARGEDESIGN_OUT") or "out/examples/conservation")
    design = design_from_scene(load_scene(UNIT_SCENE)).design
    runs = {}
    for label, level in (("on the level I3 = 0", "I3=0"), ("off the level I3 = 0.5", "I3=0.5")):
        result = simulate(design, t_end=T_END, initial={**START, "level": level})
        drift = relative_i4_drift(result)
        runs[label] = (result, drift)
        summary = result.summary()
        print(
            f"{label}: I4 relative drift {drift.max():.2e}, energy drift "
            f"{summary['I1_rel_drift']:.2e}, max |I3| {summary['I3_max']:.2e} J s "
            f"({', '.join(result.effects)})"
        )
    body = runs["on the level I3 = 0"][0]
    theorem = simulate(
        design.parameters, t_end=T_END, initial={**START, "level": "I3=0"}, effects=["theorem"]
    )
    # output samples are the integrators' own step ends: compare where both end, at T_END
    gap = max(
        np.abs(body.gamma[-1] - theorem.gamma[-1]).max(),
        np.abs(body.omega[-1] - theorem.omega[-1]).max(),
    )
    print(f"designed body vs the theorem's reduced model at t = {T_END:g} s: state gap {gap:.2e}")

    fig, ax = plt.subplots(figsize=(7, 4))
    for label, (result, drift) in runs.items():
        ax.semilogy(result.times[1:], np.maximum(drift[1:], 1e-17), label=label)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|I4(t) - I4(0)| / |I4(0)|")
    ax.set_title("designed body, forces on its own elements (DOP853, rtol 1e-12)")
    ax.legend()
    out.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out / "I4_drift.png", dpi=100)
    plt.close(fig)
    print(f"wrote {out / 'I4_drift.png'}")
    on_level = runs["on the level I3 = 0"][1].max()
    off_level = runs["off the level I3 = 0.5"][1].max()
    return 0 if on_level < 1e-8 < 1e-3 < off_level and gap < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:2]))
