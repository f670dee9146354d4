"""The realised window's picture agrees with its numbers: the shaded interval's ends are where
the drawn laws cross the fraction (within the picture's sampling), including a window whose low
end a body designed there moved (the Chaplygin example's case: the laws of the body at s_max
put gravity 3.5 x the fraction at the confirmed s_low)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from chargedesign.designer.frontier import window_figure
from chargedesign.physical.window import Parasitic, WindowModel, solve_window


def power_law(key: str, value: float, exponent: float) -> Parasitic:
    return Parasitic(key, key, f"~ x^{exponent}", lambda x: value * np.asarray(x) ** exponent)


def model_at(s_ref: float, *items: Parasitic) -> WindowModel:
    return WindowModel(s_ref, 1e-3, "kappa", 1.0, list(items), None, 9.8)


def drawn(fig) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
    """The picture's own data: the rates, the worst drawn law at each, the shaded interval."""
    ax = fig.axes[0]
    laws = [line for line in ax.get_lines() if line.get_gid() == "law"]
    assert laws, "no law drawn"
    x = np.asarray(laws[0].get_xdata(), float)
    y = np.vstack([np.nan_to_num(np.asarray(line.get_ydata(), float)) for line in laws])
    (span,) = [p for p in ax.patches if p.get_label() == "realised"]
    xs = np.asarray(span.get_path().vertices @ span.get_patch_transform().get_matrix()[:2, :2].T)
    xs = xs[:, 0] + span.get_patch_transform().get_matrix()[0, 2]
    return x, y.max(axis=0), (float(xs.min()), float(xs.max()))


def assert_ends_cross(x, worst, lo, hi, *, s_max):
    inside = (x > lo) & (x < hi)
    assert inside.any() and np.all(worst[inside] <= 1.0 + 1e-9), worst[inside].max()
    below = x[x < lo]
    # the low end is where the drawn laws cross 1: the sample just below it is above 1
    assert below.size and worst[x < lo][-1] > 1.0, (lo, worst[x < lo][-1])
    # the high end is a law's crossing too, or the frontier s_max (drawn as its own line)
    if hi < s_max * (1 - 1e-9):
        assert worst[x > hi][0] > 1.0


def test_the_shaded_window_ends_where_the_drawn_laws_cross_the_fraction():
    # the laws of the body at s_max = 20: gravity 4e-3 x^-2 (crosses at s = 2), eddy rising
    at_max = model_at(20.0, power_law("gravity", 1e-5, -2.0), power_law("eddy", 1e-7, 7 / 3))
    window = solve_window(at_max, 0.0, 20.0, floor_text="floor", ceiling_text="ceiling")
    assert window.s_low == pytest.approx(2.0, rel=1e-6)
    # a body designed at s = 1 is lighter: its own gravity law crosses at 1, the end moves
    lighter = model_at(1.0, power_law("gravity", 1e-3, -2.0), power_law("eddy", 1e-11, 7 / 3))
    window.set_end(True, 1.0, "gravity (the body designed at s = 1)")
    window.end_laws["low"] = lighter
    fig = window_figure(window, 20.0)
    try:
        x, worst, (lo, hi) = drawn(fig)
        assert lo == pytest.approx(1.0) and hi == pytest.approx(20.0)
        assert_ends_cross(x, worst, lo, hi, s_max=20.0)
        assert "the body designed at s = 1" in fig.axes[0].get_title()
    finally:
        plt.close(fig)


def test_the_body_at_s_max_alone_draws_its_own_laws_crossing_at_both_ends():
    at_max = model_at(1e3, power_law("gravity", 4e-3 * 1e-6, -2.0), power_law("eddy", 1e-2, 2.0))
    window = solve_window(at_max, 0.0, 1e3, floor_text="floor", ceiling_text="ceiling")
    assert window.s_high is not None and window.s_high < 1e3
    fig = window_figure(window, 1e3)
    try:
        x, worst, (lo, hi) = drawn(fig)
        assert (lo, hi) == pytest.approx((window.s_low, window.s_high))
        assert_ends_cross(x, worst, lo, hi, s_max=1e3)
    finally:
        plt.close(fig)


def test_the_old_picture_would_fail_the_check():
    """The check can fail: the s_max body's laws drawn with the moved end disagree."""
    at_max = model_at(20.0, power_law("gravity", 1e-5, -2.0))
    window = solve_window(at_max, 0.0, 20.0, floor_text="floor", ceiling_text="ceiling")
    window.set_end(True, 1.0, "moved by a body whose laws are not kept")
    fig = window_figure(window, 20.0)
    try:
        x, worst, (lo, hi) = drawn(fig)
        with pytest.raises(AssertionError):
            assert_ends_cross(x, worst, lo, hi, s_max=20.0)
    finally:
        plt.close(fig)
