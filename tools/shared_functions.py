"""How many package functions the designs of a theorem scene and of its ``[case]`` twin share.

    python tools/shared_functions.py THEOREM.toml            # writes the twin beside /tmp
    python tools/shared_functions.py THEOREM.toml CASE.toml  # two given scenes

Issue 39's measure of "one model": ``cd.design(path)`` is run on each scene in a fresh process
(so that caches warmed by the first design do not hide functions from the second) and every
package function entered is recorded with ``sys.setprofile`` (module path and qualified name,
comprehensions included). It prints both counts, the shared count, shared / union, whether
the two give the same body (every element's position and weight, to :data:`SAME_BODY` of the
largest of its kind), and with ``--list`` the functions on one side only.

The twin of a theorem scene is the same file without ``[parameters]`` and ``[simulation]``,
with a ``[case]`` holding the theorem's inertia, V, l and I4 at those parameters as exact text
(:func:`chargedesign.model.catalogue.theorem_case`).
"""

from __future__ import annotations

import argparse
import json
import pickle
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path


def write_twin(theorem_scene: Path, out: Path) -> Path:
    """The ``[case]`` twin of a theorem scene (see the module's text)."""
    import sympy as sp

    from chargedesign.model.catalogue import theorem_case
    from chargedesign.params import Parameters

    text = theorem_scene.read_text("utf-8")
    given = tomllib.loads(text).get("parameters", {})
    params = Parameters(**{("lam" if k == "lambda" else k): v for k, v in given.items()})
    case = theorem_case(params)
    kept, skipping = [], False
    for line in text.splitlines():
        if line.strip().startswith("["):
            skipping = line.split("#")[0].strip() in ("[parameters]", "[simulation]")
        if not skipping:
            kept.append(line)
    kept += [
        "",
        "[case]",
        f'name = "{theorem_scene.stem} as a case"',
        f"inertia = {json.dumps([sp.sstr(x) for x in case.inertia])}",
        f'V = "{sp.sstr(case.V)}"',
        f"l = {json.dumps([sp.sstr(x) for x in case.l])}",
        f'integral = "{sp.sstr(case.integral)}"',
        "level = 0",
    ]
    out.write_text("\n".join(kept) + "\n", "utf-8")
    return out


#: the body's arrays compared: the positions and weights of every kind of element
BODY_ARRAYS = (
    "charge_positions",
    "charge_values",
    "dipole_positions",
    "dipole_moments",
    "mass_positions",
    "mass_values",
)
#: largest difference of two bodies' arrays, relative to the largest entry of each, that is the
#: same body (the two routes round the same figures differently in the last bits)
SAME_BODY = 1e-9


def body_difference(a: dict[str, list], b: dict[str, list]) -> float:
    """The largest difference of two bodies' arrays (:data:`BODY_ARRAYS`), each relative to the
    largest magnitude of that array in ``a``; infinite when a count differs."""
    import numpy as np

    worst = 0.0
    for name in BODY_ARRAYS:
        x, y = np.asarray(a[name], dtype=float), np.asarray(b[name], dtype=float)
        if x.shape != y.shape:
            return float("inf")
        if x.size:
            scale = max(float(np.max(np.abs(x))), 1e-300)
            worst = max(worst, float(np.max(np.abs(x - y))) / scale)
    return worst


def functions_called(scene: Path) -> tuple[set[tuple[str, str]], dict[str, list]]:
    """Every package function ``cd.design(scene)`` enters, in this process, and the body's
    arrays (:data:`BODY_ARRAYS`)."""
    import chargedesign as cd

    seen: set[tuple[str, str]] = set()

    def record(frame, event, arg):
        if event == "call":
            code = frame.f_code
            if "/chargedesign/" in code.co_filename:
                seen.add((code.co_filename.split("/chargedesign/", 1)[1], code.co_qualname))

    sys.setprofile(record)
    try:
        design = cd.design(str(scene)).design
    finally:
        sys.setprofile(None)
    return seen, {name: getattr(design, name).tolist() for name in BODY_ARRAYS}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("theorem", type=Path)
    parser.add_argument("case", type=Path, nargs="?")
    parser.add_argument("--list", action="store_true", help="print the one-sided functions")
    parser.add_argument("--record", type=Path, help=argparse.SUPPRESS)  # the child's output
    args = parser.parse_args()
    if args.record is not None:
        args.record.write_bytes(pickle.dumps(functions_called(args.theorem)))
        return 0
    with tempfile.TemporaryDirectory() as folder:
        case = args.case or write_twin(args.theorem, Path(folder) / "twin.toml")
        sides = []
        for scene in (args.theorem, case):
            out = Path(folder) / f"{len(sides)}.pickle"
            subprocess.run([sys.executable, __file__, str(scene), "--record", str(out)], check=True)
            sides.append(pickle.loads(out.read_bytes()))
    (theorem, theorem_body), (twin, twin_body) = sides
    shared = theorem & twin
    difference = body_difference(theorem_body, twin_body)
    same = "yes" if difference <= SAME_BODY else "NO"
    print(
        f"theorem {len(theorem)}, case {len(twin)}, shared {len(shared)}, "
        f"shared / union {len(shared) / len(theorem | twin):.3f}, same body {same} "
        f"(largest relative difference {difference:.1e})"
    )
    if args.list:
        for title, only in (("theorem only", theorem - twin), ("case only", twin - theorem)):
            print(f"{title} ({len(only)}):")
            for path, name in sorted(only):
                print(f"  {path}: {name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
