"""The command line's arguments, one function per command: light on purpose.

``chargedesign --help`` (and every command's ``--help``) builds the whole parser from this
module alone; the command's own module (``chargedesign/commands/<name>.py``, whose ``run``
imports the stages at its top) is imported only when that command runs
(:func:`chargedesign.cli.main`).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from chargedesign.formatting import PLAIN, fmt
from chargedesign.limits import MAX_TOLERANCE_LEVELS as MAX_LEVELS
from chargedesign.limits import MAX_TOLERANCE_SAMPLES as MAX_SAMPLES
from chargedesign.scene.keys import DECLARED, KEY, declared
from chargedesign.schemas import NAMES, default_text
from chargedesign.vocabulary import CHECK_DEFAULT_ORIENTATIONS as DEFAULT_ORIENTATIONS
from chargedesign.vocabulary import CHECK_DEFAULT_TOL as DEFAULT_TOL
from chargedesign.vocabulary import EFFECTS, PRECISIONS
from chargedesign.vocabulary import EXPORT_FORMATS as FORMATS


def key_help(table: str, name: str, extra: str = "", read_from: str = "scene") -> str:
    """The help of an option that sets the key ``table.name``, from the key's declaration
    (chargedesign.scene.keys): its doc, unit and default; ``extra`` is what the option adds,
    ``read_from`` the file whose table the option overrides (a scene, or a design that
    recorded it)."""
    key = declared(table, name)
    unit = f", {key.unit}" if key.unit else ""
    return (
        f"{key.doc}{unit}{extra} (default: the {read_from}'s [{table}] {name}, else "
        f"{default_text(key, source=False).replace('`', '')})"
    )


def key_options(parser: argparse.ArgumentParser, table: str, read_from: str = "scene") -> None:
    """One option per key of ``table`` declared with one (``Key.option``, its metavar):
    ``--max-charge Q`` sets ``[design] max_charge``, its type, help and default the key's
    (``read_from``: see :func:`key_help`)."""
    for key in DECLARED[table]:
        if key.option:
            parser.add_argument(
                "--" + key.name.replace("_", "-"),
                type=int if key.schema.get("type") == "integer" else float,
                default=None,
                metavar=key.option,
                help=key_help(table, key.name, read_from=read_from),
            )


def _key_choices(table: str, name: str) -> tuple[str, ...]:
    """The declared choices of a scene key (its JSON Schema's enum)."""
    return tuple(declared(table, name).schema["enum"])


#: the benchmark areas (``bench --only``)
AREAS = (
    "certificate",
    "fields",
    "design",
    "physical",
    "check",
    "simulate",
    "tolerance",
    "sweep",
    "testbed",
    "bifurcation",
)


def verify_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "case",
        nargs="?",
        default=None,
        help="a case file (TOML with a [case] table): certify its claimed integral; "
        "default: the theorem's certificate and the audit of the printed formulas",
    )
    parser.add_argument("--json", action="store_true", help="print JSON")


def catalogue_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON")


def conditions_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML); default: the embedded scene"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument(
        "--exact",
        action="store_true",
        help="read the inputs as the decimals they print as and report exact rational values",
    )


def design_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML); default: the embedded scene"
    )
    parser.add_argument(
        "--out", default="out", metavar="DIR", help="output directory (default: out)"
    )
    parser.add_argument("--json", action="store_true", help="print a JSON summary")
    parser.add_argument(
        "--objective",
        choices=_key_choices("design", "objective"),
        default=None,
        help=key_help(
            "design",
            "objective",
            ": l1 (sparse), l2 (smooth), linf (smallest largest weight) or robust (l1 "
            "weighted by each place's placement sensitivity)",
        ),
    )
    parser.add_argument(
        "--robust-weight",
        type=float,
        default=None,
        metavar="BETA",
        help=key_help("design", KEY.robust_weight),
    )
    parser.add_argument(
        "--solver",
        default=None,
        metavar="NAME",
        help=key_help("design", "solver", " (auto: HiGHS for linear programs, Clarabel for cones)"),
    )
    key_options(parser, "design")
    parser.add_argument(
        "--no-polish", action="store_true", help="keep the solvers' weights (no polishing)"
    )
    parser.add_argument("--no-picture", action="store_true", help="do not render design.png")
    parser.add_argument("--quiet", action="store_true", help="no progress messages on stderr")
    parser.add_argument(
        "--verbose",
        action="store_true",
        help="print the full report (default: the verdict and a short summary; the report "
        "is in DIR/report.md)",
    )
    parser.add_argument(
        "--max-linf-candidates",
        type=int,
        default=None,
        metavar="N",
        help="raise the cap on candidates of an linf design (default "
        "chargedesign.limits.MAX_LINF_CANDIDATES)",
    )
    parser.add_argument(
        "--no-forward-check",
        action="store_true",
        help="write the body without the forward check (not recommended: it may miss the theorem)",
    )


def check_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("design", metavar="DESIGN", help="design.json to check")
    parser.add_argument("--json", action="store_true", help="print JSON (contract keys first)")
    parser.add_argument(
        "--tol",
        type=float,
        default=DEFAULT_TOL,
        metavar="T",
        help=f"relative tolerance for the claimed quantities (default {fmt(DEFAULT_TOL, PLAIN)})",
    )
    parser.add_argument(
        "--orientations",
        type=int,
        default=DEFAULT_ORIENTATIONS,
        metavar="N",
        help=f"orientations gamma sampled (default {DEFAULT_ORIENTATIONS}, at most "
        "chargedesign.limits.MAX_ORIENTATIONS = 1000000)",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="seed of the random orientations (default 0)"
    )
    parser.add_argument(
        "--quadrature-order",
        type=int,
        default=None,
        metavar="D",
        help="degree of exactness for continuous bodies (default: exact for the check)",
    )
    parser.add_argument(
        "--precision",
        default="auto",
        metavar="P",
        help="arithmetic of the sums: " + ", ".join(PRECISIONS) + " (default auto: "
        "double-double where a claimed quantity's contributions cancel too far for double "
        "precision to decide it)",
    )


def simulate_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "source",
        nargs="?",
        default=None,
        metavar="SCENE_OR_DESIGN",
        help="scene (.toml) or design (.json); default: the embedded default scene",
    )
    parser.add_argument(
        "--effects",
        nargs="+",
        choices=EFFECTS,
        default=None,
        help="effects to compute (default: the scene's, else all with a source)",
    )
    parser.add_argument("--out", default=None, metavar="DIR", help="write outputs into DIR")
    parser.add_argument(
        "--route",
        choices=_key_choices("simulation", "route"),
        default=None,
        help=key_help("simulation", "route"),
    )
    parser.add_argument(
        "--method",
        default=None,
        help=key_help("simulation", "method", " (DOP853 where heyoka is missing)"),
    )
    parser.add_argument("--tol", type=float, default=None, help=key_help("simulation", "tol"))
    parser.add_argument(
        "--monitors",
        nargs="+",
        default=None,
        metavar="NAME",
        help="integrals whose drift to report even where they are no integral: energy, "
        "gamma_norm, I3, I4, kowalevski, lagrange, goriachev_chaplygin",
    )
    parser.add_argument(
        "--atlas",
        action="store_true",
        help="Poincare atlas on gamma3 = 0: orbits on one energy level on I3 = 0 and on "
        "--off-level (default 0.5 C J s) (atlas.png, atlas.csv in --out, default out/atlas)",
    )
    parser.add_argument(
        "--orbits", type=int, default=None, help="orbits per level of --atlas (default 50)"
    )
    parser.add_argument(
        "--fli", action="store_true", help="with --atlas: the fast Lyapunov indicator map"
    )
    parser.add_argument(
        "--axes",
        default=None,
        metavar="AXES",
        help="axes the motion is written in: turning (default for a frame body: its own "
        "motion read in axes turning at its larmor.rate about Z, I4 with that n) or inertial "
        "(as integrated, n = 0); a body without a frame reading has only inertial",
    )
    key_options(parser, "simulation")
    parser.add_argument(
        "--off-level",
        type=float,
        default=None,
        metavar="I3",
        help="start on the level I3 = value (J s) instead of the scene's (default: I3 = 0); "
        "same gamma, p, q, r solved from it: the theorem's I4 is then not conserved",
    )
    parser.add_argument(
        "--poincare", action="store_true", help="record a Poincare section (poincare.png)"
    )
    parser.add_argument(
        "--max-periods",
        type=float,
        default=None,
        metavar="N",
        help="raise the cap on the periods of the body's fastest rate a run covers (default "
        "chargedesign.limits.MAX_PERIODS = 1e5)",
    )
    parser.add_argument("--json", action="store_true", help="print the JSON summary")
    parser.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress on stderr with the time left (default: on; a bar on a terminal, a line "
        "every few seconds without one); --no-progress also silences the 'designing body ...' "
        "lines",
    )


def show_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("design", metavar="DESIGN", help="design.json (or a .csv/.vtp export)")
    parser.add_argument(
        "--screenshot", metavar="PNG", help="render off screen to this PNG file instead of a window"
    )
    parser.add_argument(
        "--gamma",
        nargs=3,
        type=float,
        metavar=("G1", "G2", "G3"),
        help="field axis (space Z) in body axes, normalised; default 0 0 1",
    )
    parser.add_argument(
        "--scene",
        metavar="SCENE",
        help="outline the candidate region of this scene's [body] table",
    )
    parser.add_argument(
        "--size",
        nargs=2,
        type=int,
        metavar=("W", "H"),
        help="image size in pixels (default 1024 768; 480 360 for --animate)",
    )
    parser.add_argument(
        "--animate", metavar="TRAJ", help="animate a simulated motion (.npz from simulate)"
    )
    parser.add_argument("--out", metavar="GIF", help="animation file (.gif; .mp4 with ffmpeg)")
    parser.add_argument(
        "--frames", type=int, default=None, help="with --animate: frames (default 60)"
    )
    parser.add_argument(
        "--fps", type=float, default=None, help="with --animate: frames per second (default 15)"
    )
    parser.add_argument(
        "--max-elements",
        type=int,
        default=None,
        metavar="N",
        help="draw designs of up to N elements (default chargedesign.limits.MAX_SHOW_ELEMENTS "
        "= 20000)",
    )
    parser.add_argument("--json", action="store_true", help="print the written files as JSON")


def export_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("design", metavar="DESIGN", help="design.json (or a .csv/.vtp/.vtu export)")
    parser.add_argument(
        "--format",
        metavar="F",
        help="one of " + ", ".join(FORMATS) + " (default: from the extension of --out)",
    )
    parser.add_argument("--out", metavar="PATH", required=True, help="file to write")
    parser.add_argument("--json", action="store_true", help="print a JSON summary")


def frontier_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML) with [medium]; default: embedded"
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    parser.add_argument(
        "--scan",
        action="store_true",
        help="sweep size x medium x field x density, plot K_max (n_max for the charges reading) "
        "and fit the scaling law",
    )
    parser.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="write realised_window.png here (with --scan: frontier_scan.csv/.png)",
    )
    parser.add_argument(
        "--realised-fraction",
        type=float,
        default=None,
        metavar="F",
        help=key_help("design", KEY.realised_fraction),
    )
    parser.add_argument(
        "--realised-gravity",
        type=float,
        default=None,
        metavar="G",
        help=key_help("design", KEY.realised_gravity),
    )
    parser.add_argument(
        "--recommend",
        default=None,
        metavar="PATH",
        help="search field, materials, size and medium for the widest realised window and write "
        "that scene (TOML) to PATH, every change named",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress messages on stderr")


def bench_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print the tables as JSON")
    parser.add_argument(
        "--quick", action="store_true", help="small sizes: a smoke run of a few seconds per area"
    )
    parser.add_argument(
        "--only", choices=AREAS, action="append", help="run only these areas (repeatable)"
    )
    parser.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="write benchmarks.md and plots into DIR (e.g. docs); default: print only",
    )


def tolerance_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("design", metavar="DESIGN", help="design.json")
    parser.add_argument("--position", metavar="E", help="position error, e.g. 20um or 0.1%%")
    parser.add_argument("--charge", metavar="E", help="charge error, C or %% (e.g. 1%%)")
    parser.add_argument("--dipole", metavar="E", help="dipole moment error, A m^2 or %%")
    parser.add_argument("--mass", metavar="E", help="mass error, kg or %%")
    key_options(parser, "tolerance", read_from="design")
    parser.add_argument(
        "--target",
        type=float,
        default=1e-4,
        metavar="EPS",
        help="target relative error of mu, V and the inertia for the per-element tolerances "
        "(default 1e-4)",
    )
    parser.add_argument(
        "--samples",
        type=int,
        default=200,
        metavar="N",
        help=f"perturbed bodies per tolerance level (default 200, at most {MAX_SAMPLES})",
    )
    parser.add_argument(
        "--t-end", type=float, default=100.0, metavar="T", help="simulated time, s (default 100)"
    )
    parser.add_argument(
        "--levels",
        default="0.01,0.1,1",
        metavar="F,F,...",
        help="scale factors of the errors for the drift-against-tolerance curve "
        f"(default 0.01,0.1,1; at most {MAX_LEVELS})",
    )
    parser.add_argument(
        "--no-simulate", action="store_true", help="error distributions only, no I4 drift"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the draws (default 0)")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="write tolerance.json, design.json (with a 'tolerance' block), errors.csv, "
        "drift.csv, drift_over_time.csv and drift.png (atomically)",
    )


def sweep_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("sweep", metavar="SWEEP.toml", help="the sweep file")
    parser.add_argument("--out", required=True, metavar="DIR", help="output directory")
    parser.add_argument(
        "--workers", type=int, default=None, metavar="N", help="workers (default: the cores, <= 8)"
    )
    parser.add_argument(
        "--executor",
        default="process",
        metavar="E",
        help="process (default), dask (LocalCluster) or serial",
    )
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="join a running Dask cluster (tcp://host:8786); implies --executor dask",
    )
    parser.add_argument(
        "--scheduler-timeout",
        type=float,
        default=None,  # 5 s; given without --scheduler it is refused (it would be ignored)
        metavar="S",
        help="seconds to wait for the --scheduler to answer (default 5)",
    )
    parser.add_argument(
        "--resume", action="store_true", help="skip points already done in DIR, run the rest"
    )
    parser.add_argument(
        "--chunk", type=int, default=None, metavar="K", help="points per task (default: automatic)"
    )
    parser.add_argument(
        "--max-points",
        type=int,
        default=None,
        metavar="N",
        help="raise the cap on points of one sweep (default chargedesign.limits.MAX_SWEEP_POINTS "
        "= 100000)",
    )
    parser.add_argument("--json", action="store_true", help="print the outcome as JSON")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def schema_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "name", choices=NAMES, help="design (design.json), scene (TOML) or testbed (testbed.json)"
    )


def testbed_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene",
        nargs="?",
        default=None,
        help="scene file (TOML) with [testbed]; default: the embedded testbed scene "
        "(examples/scenes/testbed.toml)",
    )
    parser.add_argument(
        "--out", default="out/testbed", metavar="DIR", help="output folder (default out/testbed)"
    )
    parser.add_argument("--json", action="store_true", help="print testbed.json's content")
    parser.add_argument("--quiet", action="store_true", help="no progress messages on stderr")


def bifurcation_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML); default: embedded"
    )
    parser.add_argument(
        "--h-range",
        nargs=2,
        type=float,
        metavar=("LO", "HI"),
        default=None,
        help="energy range in J (default: from the least energy on the level to the top of "
        "the amended potential plus half its span)",
    )
    parser.add_argument("--out", default="out", metavar="DIR", help="output folder (default out/)")
    parser.add_argument(
        "--at",
        type=float,
        default=None,
        metavar="H",
        help="also draw the atlas and the FLI map at the energy H (J) beside the diagram "
        "(bifurcation_at.png)",
    )
    parser.add_argument(
        "--tori",
        nargs=2,
        type=float,
        default=None,
        metavar=("H", "K"),
        help="only count the tori of the level H = h (J), I4 = k (1/s^4) on I3 = 0, by the flow "
        '(no files written); with --json: {"h": h, "k": k, "tori": n}',
    )
    parser.add_argument(
        "--level",
        default=None,
        metavar="G",
        help="a case scene's I3 level (a number or a fraction; default: the case's own level,"
        " or 0 for a general case)",
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.add_argument("--quiet", action="store_true", help="no progress message on stderr")


def sources_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--json", action="store_true", help="print the table as a JSON list of rows"
    )


#: command name -> the function that adds its arguments
ARGUMENTS: dict[str, Callable[[argparse.ArgumentParser], None]] = {
    "verify": verify_arguments,
    "conditions": conditions_arguments,
    "design": design_arguments,
    "check": check_arguments,
    "simulate": simulate_arguments,
    "show": show_arguments,
    "export": export_arguments,
    "frontier": frontier_arguments,
    "bench": bench_arguments,
    "tolerance": tolerance_arguments,
    "sweep": sweep_arguments,
    "schema": schema_arguments,
    "testbed": testbed_arguments,
    "bifurcation": bifurcation_arguments,
    "catalogue": catalogue_arguments,
    "sources": sources_arguments,
}
