"""The command line: a thin layer over the library.

Each command lives in ``chargedesign/commands/<name>.py`` with ``add_arguments(parser)`` and
``run(args) -> int``; command modules import heavy packages only inside ``run`` so that
``chargedesign --help`` stays fast. User mistakes (``ChargeDesignError``) print one line
and exit 2; a failed check exits 1.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

COMMANDS = {
    "verify": "certificate of the theorem and audit of the printed formulas",
    "conditions": "the linear conditions on moments a body must meet",
    "design": "design the body (charges, dipoles, masses) and write design.json",
    "check": "forward check of a design by quadrature and direct Lorentz torque",
    "simulate": "simulate the motion under the effects the scene calls for",
    "show": "3-D view of a design (PyVista)",
    "export": "export a design's geometry (json, csv, vtp, vtu)",
    "bench": "what accuracy costs in time",
    "schema": "print the JSON Schema of design.json or of scene files",
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="chargedesign",
        description=(
            "Bodies that realise the Yehia-Elmandouh integrable case of rigid-body dynamics."
        ),
    )
    parser.add_argument("--version", action="version", version="chargedesign 0.1.0")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, help_text in COMMANDS.items():
        module = importlib.import_module(f"chargedesign.commands.{name}")
        p = sub.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(p)
        p.set_defaults(_module=module)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    from chargedesign.errors import ChargeDesignError

    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args._module.run(args) or 0)
    except ChargeDesignError as exc:
        print(f"chargedesign {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"chargedesign {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader (e.g. `| head`) went away: stop quietly, as Unix tools do
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
