"""`chargedesign show DESIGN`: a 3-D view of a design (PyVista).

Without options a window opens (needs a display). ``--screenshot PNG`` renders off screen to a
file; ``--animate TRAJ.npz --out GIF`` animates a simulated motion in the space frame.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from chargedesign import viz
from chargedesign.errors import InputError
from chargedesign.export import load_any_design
from chargedesign.files import check_outputs
from chargedesign.scene import load_scene
from chargedesign.validation import input_error

#: the animation's frames and frames per second when --frames / --fps are not given
ANIMATION_FRAMES = 60
ANIMATION_FPS = 15.0


def run(args: argparse.Namespace) -> int:
    for option, value in (("--frames", args.frames), ("--fps", args.fps)):
        if value is not None and args.animate is None:  # needs its companion
            raise InputError(f"{option}: sets the animation; give --animate TRAJ.npz too")
    if args.animate is None and args.out is not None:
        raise InputError("--out: names the animation file; give --animate TRAJ.npz too")
    if args.animate is not None and args.out is None:
        raise InputError("--animate: needs --out FILE.gif for the animation")

    # before reading and rendering; never onto the design, the trajectory or the scene
    check_outputs(
        [("--screenshot", args.screenshot, False), ("--out", args.out, False)],
        inputs=[args.design, args.animate, args.scene],
    )
    if args.screenshot is not None and args.out is not None and _same(args.screenshot, args.out):
        raise InputError("--out: the same file as --screenshot; give two names")
    design = load_any_design(args.design)
    if problem := viz.too_many_elements(design, args.max_elements):
        raise InputError(problem)
    region = None
    if args.scene is not None:
        body = load_scene(args.scene).body
        region = dict(body.table) if body is not None and body.table else None
        if region is None:
            raise InputError(f"{args.scene}: the scene has no [body] table to outline")
    written: dict[str, str] = {}
    if args.screenshot is not None:
        size = tuple(args.size) if args.size else (1024, 768)
        _check_path(args.screenshot, "screenshot path", viz.SCREENSHOT_SUFFIXES)
        _check_view(size, args.gamma)
        path = viz.render_screenshot(
            design,
            args.screenshot,
            region=region,
            window_size=size,
            gamma=args.gamma,
            max_elements=args.max_elements,
        )
        written["screenshot"] = str(path)
    if args.animate is not None:
        size = tuple(args.size) if args.size else (480, 360)
        _check_animation(args.out)
        _check_view(size, None)
        path = viz.animate(
            design,
            args.animate,
            args.out,
            frames=ANIMATION_FRAMES if args.frames is None else args.frames,
            fps=ANIMATION_FPS if args.fps is None else args.fps,
            region=region,
            window_size=size,
            max_elements=args.max_elements,
            progress=_frame_progress,
        )
        written["animation"] = str(path)
    if not written:
        if not viz.in_notebook() and not viz.display_available():
            raise InputError(viz.NO_DISPLAY)
        size = tuple(args.size) if args.size else (1024, 768)
        _check_view(size, args.gamma)
        viz.show_interactive(
            design,
            region=region,
            gamma=args.gamma,
            window_size=size,
            max_elements=args.max_elements,
        )
        return 0
    if args.json:
        print(json.dumps(written))
    else:
        for what, name in written.items():
            print(f"wrote {what}: {name}")
    return 0


def _check_path(path: str, what: str, suffixes: tuple[str, ...]) -> None:
    """The output file's kind, from its name (before any rendering)."""
    from pathlib import Path

    if Path(path).suffix.lower() not in suffixes:
        ending = " or ".join(suffixes)
        raise input_error(what, f"a file name ending in {ending}", str(Path(path)))


def _check_animation(out: str) -> None:
    """An animation file: .gif, or .mp4 with imageio-ffmpeg installed."""
    from pathlib import Path

    _check_path(out, "animation path", viz.ANIMATION_SUFFIXES)
    if Path(out).suffix.lower() == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise InputError(viz.mp4_missing(Path(out))) from None


def _check_view(size: tuple[int, ...], gamma: list[float] | None) -> None:
    """The picture's size (the option's range reaches past what a window takes) and the field
    axis (a direction: not zero)."""
    if not viz.window_size_ok(size):
        raise input_error("window_size", viz.WINDOW_SIZE_EXPECTED, size)
    if gamma is not None and float(np.linalg.norm(np.asarray(gamma, dtype=float))) == 0.0:
        raise input_error("gamma", "a non-zero vector", gamma)


def _same(a: str, b: str) -> bool:
    import os

    return os.path.realpath(a) == os.path.realpath(b)


def _frame_progress(done: int, total: int) -> None:
    """Progress of an animation on stderr: about ten lines, and the last frame."""
    import sys

    step = max(1, total // 10)
    if done == 1 or done % step == 0 or done == total:
        print(f"show: rendered frame {done}/{total}", file=sys.stderr, flush=True)
