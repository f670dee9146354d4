"""The bifurcation diagrams of the gallery: the unit-scale case and its two classical limits.

- the unit-scale case (examples/scenes/unit_scale.toml);
- Yehia's 2003 limit (K = 0, the same c, d, n, kappa);
- Chaplygin's limit (K = n = 0), compared with the closed-form curves
  ``k = (h / C + kappa sqrt(c^2 + d^2))^2`` and ``k = (h / C - kappa sqrt(c^2 + d^2))^2``.

Run::

    .venv/bin/python tools/bifurcation_gallery.py [OUT_DIR]

OUT_DIR defaults to docs/images (bifurcation_*.png). Takes about half a minute.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import chargedesign as cd

ROOT = Path(__file__).resolve().parents[1]  # the repository
UNIT = cd.Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
CASES = {
    "unit_scale": UNIT,
    "yehia2003": UNIT.replace(K=0.0),
    "chaplygin": UNIT.replace(K=0.0, n=0.0),
}


def chaplygin_gap(diagram: cd.BifurcationDiagram) -> float:
    """Largest distance (relative to the largest k) from a computed non-degenerate branch point
    to the nearer of the two closed-form curves."""
    p = diagram.raw.params
    a = p.kappa * np.hypot(p.c, p.d)
    hk = np.concatenate([b.hk for b in diagram.branches if not b.exact])
    curves = np.stack([(hk[:, 0] / p.C + a) ** 2, (hk[:, 0] / p.C - a) ** 2], axis=1)
    gap = np.min(np.abs(curves - hk[:, 1:2]), axis=1)
    return float(np.max(gap) / np.max(hk[:, 1]))


def main(out_dir: str | None = None) -> int:
    out = Path(out_dir or ROOT / "docs" / "images")
    out.mkdir(parents=True, exist_ok=True)
    for name, params in CASES.items():
        diagram = cd.bifurcation(params)
        fig = diagram.plot()
        fig.suptitle(f"{name}: {params}", fontsize=8)
        path = out / f"bifurcation_{name}.png"
        fig.savefig(path, dpi=110)
        print(f"{path}: {diagram!r}")
        if name == "chaplygin":
            print(
                f"chaplygin closed-form curves: largest relative gap {chaplygin_gap(diagram):.2e}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else None))
