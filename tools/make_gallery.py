"""Regenerate the pictures of the documentation's gallery (docs/gallery.md).

Designs the embedded default scene and the example scenes, and draws each body with
``Design.plot`` into an off-screen plotter of its own. Run::

    .venv/bin/python tools/make_gallery.py [OUT_DIR]

OUT_DIR defaults to docs/images. Takes about half a minute.
"""

from __future__ import annotations

import sys
from pathlib import Path

import chargedesign as cd

ROOT = Path(__file__).resolve().parents[1]  # the repository
SCENES = {
    "default": None,
    "yehia2003": ROOT / "examples" / "scenes" / "yehia2003.toml",
    "si_scale": ROOT / "examples" / "scenes" / "si_scale.toml",
}


def main(out_dir: str | None = None) -> int:
    out = Path(out_dir or ROOT / "docs" / "images")
    out.mkdir(parents=True, exist_ok=True)
    for name, scene in SCENES.items():
        result = cd.design(scene)
        # a new plotter (off screen here) that is not shown: we take its picture
        plotter = result.design.plot(
            region=result.candidates.region, show=False, window_size=(900, 680)
        )
        try:
            path = out / f"gallery_{name}.png"
            plotter.screenshot(str(path))
        finally:
            plotter.close()
        print(f"{path}: {result!r}")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
