"""tools/route_formats.py routes f-string number formats through fmt without changing text."""

import importlib.util
from pathlib import Path

import numpy as np

SPEC = importlib.util.spec_from_file_location(
    "route_formats", Path(__file__).resolve().parents[2] / "tools" / "route_formats.py"
)
route_formats = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(route_formats)

SOURCE = """
import numpy as np


def text(x, y, v):
    return (
        f"a {x:.3g} b {y['k']:.4g} c {v:g} d {{x:.3g}} e {x:>10.3e} f {x:.0f} g {x!r} "
        "h {x:.3g}"
    )
"""


def test_routed_text_is_the_same_text():
    out, used = route_formats.convert_source(SOURCE)
    assert used == {"fmt", "PRECISE", "PLAIN", "ERROR"}
    assert "from chargedesign.formatting import ERROR, PLAIN, PRECISE, fmt" in out
    assert "{fmt(x)}" in out and "{fmt(x, ERROR):>10}" in out and "{x:.0f}" in out
    before, after = {}, {}
    exec(SOURCE, before)
    exec(out, after)
    for x, y, v in ((0.012345, {"k": 2.0 / 3.0}, 1e-7), (-3.5e8, {"k": np.float64(7)}, 12)):
        assert after["text"](x, y, v) == before["text"](x, y, v)
