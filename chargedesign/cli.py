"""The command line: a thin layer over the library.

Each command's arguments are a function in :mod:`chargedesign.commands.arguments` (light:
the whole parser, so ``--help``, is built from it alone); the command itself is
``run(args) -> int`` in ``chargedesign/commands/<name>.py``, which imports its stages at the
top and is imported (by name, with :mod:`importlib`) only when that command runs, so that
``chargedesign --help`` stays fast. User mistakes (``ChargeDesignError``) print one line
and exit 2; a failed check exits 1.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any, NoReturn

from chargedesign.commands.arguments import ARGUMENTS
from chargedesign.errors import ChargeDesignError, InputError
from chargedesign.files import abandon_outputs, hold_signal, signals_held
from chargedesign.limits import OPTION_RANGES
from chargedesign.validation import check_input_number

COMMANDS = {
    "verify": "certificate of the theorem and audit of the printed formulas, or of a case file",
    "conditions": "the linear conditions on moments a body must meet",
    "design": "design the body (charges, dipoles, masses) and write design.json",
    "check": "forward check of a design by quadrature and direct Lorentz torque",
    "simulate": "simulate the motion under the effects the scene calls for",
    "show": "3-D view of a design (PyVista)",
    "export": "export a design's geometry (json, csv, vtp, vtu)",
    "frontier": "the largest time rate a body realises within every physical limit",
    "bench": "what accuracy costs in time",
    "tolerance": "manufacturing tolerances: exact sensitivity, Monte Carlo of perturbed bodies",
    "sweep": "run design, check, simulate, frontier or tolerance over a grid of scenes",
    "schema": "print the JSON Schema of design.json or of scene files",
    "testbed": "air-bearing platform, ballast, wheels and sampled closed loop (testbed.json)",
    "bifurcation": "bifurcation diagram of (H, I4) on I3 = 0: critical set, types, chambers",
    "catalogue": "the paper's integrable cases of (ep), each certified exactly",
    "sources": "every physical figure the tool uses, its source and whether it was checked",
}


class Parser(argparse.ArgumentParser):
    """argparse that reads ``-3e-1`` as a negative number, not an option (Python < 3.13
    takes only ``-3`` and ``-0.3``); subcommands' parsers are of the same class."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message: str) -> NoReturn:
        """A usage mistake in one line, as every other bad input gets (argparse's own
        prints the whole usage first); ``--help`` still prints it."""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


#: a negative number in any float spelling: -3, -0.3, -.3, -3., -3e-1, -3.0E+2
NEGATIVE_NUMBER = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="chargedesign",
        description=(
            "Bodies that realise the Yehia-Elmandouh integrable case of rigid-body dynamics."
        ),
    )
    parser.add_argument("--version", action="version", version="chargedesign 0.1.0")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, help_text in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        ARGUMENTS[name](p)
        _document_ranges(p, name)
    return parser


def command_module(name: str) -> ModuleType:
    """The module that runs a command (``chargedesign.commands.<name>``), imported when the
    command runs: the one place the command line loads the stages lazily. Only the
    commands listed in COMMANDS are imported, whatever string is passed."""
    if name not in COMMANDS:
        raise InputError(f"command: one of {', '.join(COMMANDS)}, got {name!r}")
    return importlib.import_module(f"chargedesign.commands.{name}")


def _document_ranges(parser: argparse.ArgumentParser, command: str) -> None:
    """Append each numeric option's accepted range (chargedesign.limits.OPTION_RANGES) to
    its ``--help``: the range documented is the range checked."""

    ranges = OPTION_RANGES.get(command, {})
    for action in parser._actions:
        bounds = ranges.get(action.dest)
        if bounds is not None and action.help is not argparse.SUPPRESS:
            action.help = f"{action.help or ''} [range {bounds.text()}]".strip()


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that every ``finally`` (staging cleanup) runs."""


#: seconds a SIGTERM waits for the Python-level unwinding before the process is ended (a
#: solver or renderer in C code only returns to Python when it is done)
SIGTERM_GRACE = 2.0


def on_sigterm(signum: int, frame: object) -> None:
    if not hold_signal(signum):  # inside a held block it is raised again when the block ends
        raise Terminated()


def _on_sigint(signum: int, frame: object) -> None:
    if not hold_signal(signum):
        raise KeyboardInterrupt()


def _install_sigterm() -> Callable[[], None]:
    """SIGTERM unwinds the run (finally blocks remove staging); if the main thread sits in C
    code, a watchdog woken through the signal wakeup fd removes the open staging folders and
    ends the process after ``SIGTERM_GRACE`` seconds. Returns the function that uninstalls."""
    import os
    import signal
    import threading
    import time

    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    previous_fd = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    previous = signal.signal(signal.SIGTERM, on_sigterm)
    previous_int = signal.signal(signal.SIGINT, _on_sigint)

    def watch() -> None:
        # signals go to the main thread, whose handler unwinds the run
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
        while True:
            try:
                data = os.read(read_fd, 64)
            except OSError:
                return
            if not data:
                return
            if signal.SIGTERM in data:
                # the grace period, and never in the middle of a held block (an output's
                # swap, VTK): that block ends, then the handler unwinds the run
                deadline = time.monotonic() + SIGTERM_GRACE
                while time.monotonic() < deadline or signals_held():
                    time.sleep(0.05)
                abandon_outputs()
                print("chargedesign: terminated", file=sys.stderr, flush=True)
                os._exit(143)

    threading.Thread(target=watch, name="chargedesign-sigterm", daemon=True).start()

    def uninstall() -> None:
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, previous_int)
        signal.set_wakeup_fd(previous_fd)
        os.close(write_fd)

    return uninstall


def check_arguments(args: argparse.Namespace) -> None:
    """The command line's numbers pass the same input range as files' (docs/reliability.md),
    and each option its own range (chargedesign.limits.OPTION_RANGES, shown in ``--help``)."""

    ranges = OPTION_RANGES.get(getattr(args, "command", None) or "", {})
    for name, value in vars(args).items():
        if name.startswith("_"):
            continue
        option = "--" + name.replace("_", "-")
        values = value if isinstance(value, (list, tuple)) else [value]
        for item in values:
            if isinstance(item, float):
                check_input_number(item, option)
            elif isinstance(item, int) and not isinstance(item, bool) and abs(item) > 10**18:
                check_input_number(item, option, hi=1e18)
            bounds = ranges.get(name)
            if (
                bounds is not None
                and isinstance(item, (int, float))
                and not isinstance(item, bool)
                and not bounds.holds(item)
            ):
                raise InputError(f"{option}: expected a value in {bounds.text()}, got {item!r}")


def main(argv: Sequence[str] | None = None) -> int:
    import threading

    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_usage(sys.stderr)
        print(
            "chargedesign: error: give a command (" + ", ".join(COMMANDS) + "); "
            "chargedesign --help describes them",
            file=sys.stderr,
        )
        return 2
    import warnings

    uninstall = None
    if threading.current_thread() is threading.main_thread():
        uninstall = _install_sigterm()
    previous_show = warnings.showwarning
    warnings.showwarning = _one_line_warning(args.command)
    try:
        check_arguments(args)
        return int(command_module(args.command).run(args) or 0)
    except ChargeDesignError as exc:
        print(f"chargedesign {args.command}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except Terminated:
        print(f"chargedesign {args.command}: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print(f"chargedesign {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader (e.g. `| head`) went away: stop quietly, as Unix tools do
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except MemoryError:
        print(
            f"chargedesign {args.command}: error: out of memory (ask for less work: fewer "
            "candidates, samples or orientations)",
            file=sys.stderr,
        )
        return 2
    except OSError as exc:
        # every kind (permissions, read-only or full disks, /sys paths): one line naming the
        # path and the reason
        where = exc.filename if exc.filename is not None else "file system"
        reason = exc.strerror or type(exc).__name__
        if exc.filename2 is not None:
            where = f"{where} -> {exc.filename2}"
        print(f"chargedesign {args.command}: error: {where}: {reason}", file=sys.stderr)
        return 2
    finally:
        warnings.showwarning = previous_show
        if uninstall is not None:
            uninstall()


def _one_line_warning(command: str) -> Callable[..., None]:
    """Library warnings (numpy overflow, ...) as one line each, without source lines."""

    def show(message: Warning | str, category: type[Warning], *args: object, **kw: object) -> None:
        text = _one_line(str(message))
        print(f"chargedesign {command}: warning: {category.__name__}: {text}", file=sys.stderr)

    return show


def _one_line(text: str) -> str:
    return " ".join(text.split()) if "\n" in text or "\r" in text else text


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
