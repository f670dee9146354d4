"""Outputs all or nothing: a run's files change together or not at all (docs/reliability.md).

- :func:`atomic_directory` stages a whole output folder beside it
  (``.NAME.staging.PID.XXXX``) and swaps it in with one rename (an atomic exchange on Linux,
  else rename-aside, rename-in): a reader sees the old folder or the new one, never a mix.
  Files of the old folder that this run did not write are carried into the new one (hard
  links), so they stay. While a folder is open, every atomic write into it (another
  :func:`atomic_directory` or :func:`atomic_path` on the same folder, in this process) joins
  the same staging folder: the folder still changes once.
- :func:`atomic_path` writes one file through a temporary beside it (``.NAME.tmp.PID.XXXX``)
  and one ``os.replace``.
- Staging and temporary names carry the creating process id; every run removes those whose
  process is gone (a run killed with SIGKILL) from the folder it writes into. SIGINT and
  SIGTERM unwind normally (the CLI turns SIGTERM into an exception), so a run cleans its own
  staging; the final swap runs with both signals deferred.
- Paths: output goes only to regular files and real folders. A FIFO, device or socket is
  refused, and so is a symbolic link (file or folder): chargedesign does not write through
  links; give the real path.
"""

from __future__ import annotations

import ctypes
import json
import os
import re
import secrets
import shutil
import signal
import stat
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from chargedesign.errors import InputError

#: names of this module's staging, temporary and set-aside entries: ``.NAME.KIND.PID.TOKEN...``
_OWN_NAME = re.compile(r"^\.(?P<name>.+)\.(?P<kind>staging|tmp|old)\.(?P<pid>\d+)\.[^.]+")
#: folders open for writing in this process: absolute target -> its staging folder
_OPEN: dict[str, Path] = {}
_DEFERRED = (signal.SIGINT, signal.SIGTERM)
#: temporaries of open atomic_path blocks in this process
_TEMPS: set[Path] = set()


def abandon_outputs() -> None:
    """Remove this process's open staging folders and temporaries (a forced exit follows).

    Called by the CLI's SIGTERM watchdog when the main thread cannot unwind in time.
    """
    for staging in list(_OPEN.values()):
        shutil.rmtree(staging, ignore_errors=True)
    for tmp in list(_TEMPS):
        try:
            tmp.unlink()
        except OSError:
            pass


# --------------------------------------------------------------------------- signals


#: depth of nested deferred_signals blocks in the main thread, and signals that arrived there
_HELD = {"depth": 0}
_PENDING: list[int] = []


def hold_signal(signum: int) -> bool:
    """For the CLI's Python-level handlers: True (and the signal kept for later) inside a
    :func:`deferred_signals` block, where it must not interrupt; False elsewhere."""
    if _HELD["depth"] > 0:
        _PENDING.append(signum)
        return True
    return False


def signals_held() -> bool:
    """Whether the main thread is inside a :func:`deferred_signals` block."""
    return _HELD["depth"] > 0


@contextmanager
def deferred_signals() -> Iterator[None]:
    """Hold SIGINT and SIGTERM until the block ends (then they are delivered as usual).

    Used around the final swap of outputs and around VTK's imports and rendering (a signal
    inside VTK's C++ code may crash the interpreter). The main thread blocks them, and a
    signal another thread received (its C handler then asks the main thread to run the
    Python handler) is kept by :func:`hold_signal` and raised again when the block ends.
    Elsewhere than in the main thread, a no-op.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old: set[int | signal.Signals] | None = None
    if hasattr(signal, "pthread_sigmask"):
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _DEFERRED)
    _HELD["depth"] += 1
    try:
        yield
    finally:
        _HELD["depth"] -= 1
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        if _HELD["depth"] == 0 and _PENDING:
            signum = _PENDING[0]
            _PENDING.clear()
            signal.raise_signal(signum)


def import_held(name: str) -> Any:
    """Import a module with SIGINT and SIGTERM held: a signal inside a C++ extension's
    initialisation (VTK) can crash the interpreter instead of unwinding it."""
    import importlib

    with deferred_signals():
        return importlib.import_module(name)


# --------------------------------------------------------------------------- paths


def _kind_of(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a special file"


def check_output_path(path: str | os.PathLike[str], *, directory: bool = False) -> Path:
    """Refuse to write onto anything but a regular file (or a real folder, ``directory=True``).

    Raises InputError for a symbolic link (naming its target), a FIFO, device or socket, a
    folder where a file goes or a file where a folder goes. A missing path is fine.
    """
    target = Path(path)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        return target
    except OSError as exc:
        raise InputError(f"{target}: cannot write ({exc.strerror or exc})") from exc
    if stat.S_ISLNK(info.st_mode):
        try:
            link = os.readlink(target)
        except OSError:  # pragma: no cover - raced away
            link = "?"
        raise InputError(
            f"{target}: is a symbolic link (to {link}); chargedesign does not write through "
            "links, give the real path"
        )
    if directory:
        if stat.S_ISDIR(info.st_mode):
            return target
        if stat.S_ISREG(info.st_mode):
            raise InputError(f"{target}: expected an output directory, it is a file")
        raise InputError(f"{target}: expected an output directory, it is {_kind_of(info.st_mode)}")
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"{target}: cannot write a file, it is a directory")
    if not stat.S_ISREG(info.st_mode):
        raise InputError(
            f"{target}: is {_kind_of(info.st_mode)}; chargedesign writes only regular files"
        )
    return target


def _parent_dir(path: Path) -> Path:
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        raise InputError(f"{path}: cannot write, directory {parent} does not exist")
    if not parent.is_dir():
        raise InputError(f"{path}: cannot write, {parent} is not a directory")
    return parent


def _oserror(target: Path, exc: OSError) -> InputError:
    name = exc.filename if exc.filename is not None else target
    return InputError(f"{name}: cannot write ({exc.strerror or exc})")


# --------------------------------------------------------------------------- stale staging


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # PermissionError: another user's process, alive
        return True
    return True


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        try:
            path.unlink()
        except OSError:
            pass


def clean_stale(folder: str | os.PathLike[str]) -> list[Path]:
    """Remove staging folders and temporaries in ``folder`` whose creating process is gone.

    A set-aside old folder (``.NAME.old.PID.*``, a run killed between its two renames) is
    put back when ``NAME`` is missing, so the folder holds its last complete outputs.
    Returns the paths removed or restored.
    """
    base = Path(folder)
    done: list[Path] = []
    try:
        entries = list(os.scandir(base))
    except OSError:
        return done
    for entry in entries:
        match = _OWN_NAME.match(entry.name)
        if match is None or _pid_alive(int(match["pid"])):
            continue
        path = base / entry.name
        original = base / match["name"]
        if match["kind"] == "old" and not os.path.lexists(original):
            try:
                os.rename(path, original)
                done.append(path)
                continue
            except OSError:
                pass
        _remove(path)
        done.append(path)
    return done


# --------------------------------------------------------------------------- files


def _umask() -> int:
    """The current umask (read by setting it and setting it back)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; it replaces ``path`` only if the block succeeds.

    ``path`` must be a regular file or missing (see :func:`check_output_path`). Inside an
    open :func:`atomic_directory` of its folder the file goes into that folder's staging.
    """
    target = Path(path)
    staged = _OPEN.get(os.path.abspath(target.parent))
    if staged is not None:
        target = staged / target.name
    check_output_path(target)
    parent = _parent_dir(target)
    clean_stale(parent)
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{target.name}.tmp.{os.getpid()}.", suffix=target.suffix, dir=parent
        )
    except OSError as exc:
        raise _oserror(target, exc) from exc
    os.close(fd)
    tmp_path = Path(tmp)
    _TEMPS.add(tmp_path)
    try:
        yield tmp_path
        try:
            os.chmod(tmp_path, 0o666 & ~_umask())  # mkstemp creates 0600; use the usual mode
            check_output_path(target)  # it may have become a link or FIFO meanwhile
            with deferred_signals():
                os.replace(tmp_path, target)
        except OSError as exc:
            raise _oserror(target, exc) from exc
    finally:
        _TEMPS.discard(tmp_path)
        if os.path.lexists(tmp_path):
            tmp_path.unlink()


def write_file_atomic(path: str | os.PathLike[str], write: Callable[[Path], None]) -> None:
    """Write ``path`` through ``write(temporary path)`` beside it (:func:`atomic_path`); an OS
    failure of the writer becomes one line naming the file."""
    target = Path(path)
    try:
        with atomic_path(target) as tmp:
            write(tmp)
    except OSError as exc:
        raise InputError(f"{target}: cannot write ({exc.strerror or exc})") from exc


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json_atomic(path: str | os.PathLike[str], data: Any) -> None:
    write_text_atomic(path, json.dumps(data, indent=2, allow_nan=False) + "\n")


# --------------------------------------------------------------------------- folders


def _link_or_copy(src: str, dst: str) -> None:
    try:
        os.link(src, dst, follow_symlinks=False)
    except OSError:
        shutil.copy2(src, dst, follow_symlinks=False)


def _carry(src: Path, dst: Path) -> None:
    """Put ``src`` (an entry of the old folder) at ``dst`` without touching ``src``."""
    if src.is_symlink():
        os.symlink(os.readlink(src), dst)
    elif src.is_dir():
        shutil.copytree(src, dst, symlinks=True, copy_function=_link_or_copy)
    elif src.is_file():
        _link_or_copy(str(src), str(dst))
    # FIFOs, sockets, devices inside an output folder are not carried


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); False if unsupported."""
    if not os.uname().sysname == "Linux":
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_uint,
    ]
    result = renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if result == 0:
        return True
    errno = ctypes.get_errno()
    if errno in (22, 38, 95):  # EINVAL, ENOSYS, EOPNOTSUPP: the file system cannot exchange
        return False
    raise OSError(errno, os.strerror(errno), str(b))


def _swap_in(staging: Path, target: Path) -> None:
    """Make ``staging`` the folder ``target`` with one visible change; remove the old one."""
    if not os.path.lexists(target):
        os.rename(staging, target)
        return
    if _exchange(staging, target):
        shutil.rmtree(staging, ignore_errors=True)  # it holds the old outputs now
        return
    aside = target.parent / f".{target.name}.old.{os.getpid()}.{secrets.token_hex(4)}"
    os.rename(target, aside)
    try:
        os.rename(staging, target)
    except OSError:
        os.rename(aside, target)
        raise
    shutil.rmtree(aside, ignore_errors=True)


def _inside_cwd(target: Path) -> bool:
    try:
        cwd = Path.cwd().resolve()
        real = target.resolve()
    except OSError:
        return False
    return cwd == real or real in cwd.parents


def _refuse_working_directory(target: Path, option: str = "") -> None:
    """An output folder may not be the working directory or one of its parents (it holds the
    inputs and everything else the user keeps there)."""
    if _inside_cwd(target) and target.exists():
        raise InputError(
            f"{option}{target}: is the working directory (or holds it); give an output folder "
            "of its own, e.g. --out out"
        )


@contextmanager
def atomic_directory(path: str | os.PathLike[str], *, drop: Iterable[str] = ()) -> Iterator[Path]:
    """Yield a staging folder; on success it becomes ``path`` in one swap (all or nothing).

    Files of ``path`` not written by this run are carried over (hard links), except the
    names in ``drop``; on failure or interruption nothing in ``path`` changes and the staging
    folder is removed. A nested call on the same folder (in this process) joins the open one.
    """
    target = Path(path)
    key = os.path.abspath(target)
    if key in _OPEN:
        yield _OPEN[key]
        return
    check_output_path(target, directory=True)
    _refuse_working_directory(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _oserror(target.parent, exc) from exc
    clean_stale(target.parent)
    try:
        staging = Path(
            tempfile.mkdtemp(prefix=f".{target.name}.staging.{os.getpid()}.", dir=target.parent)
        )
    except OSError as exc:
        raise _oserror(target, exc) from exc
    _OPEN[key] = staging
    dropped = set(drop)
    try:
        yield staging
        del _OPEN[key]
        try:
            if target.is_dir():
                os.chmod(staging, stat.S_IMODE(os.stat(target).st_mode))
                for entry in target.iterdir():
                    name = entry.name
                    if name in dropped or _OWN_NAME.match(name):
                        continue
                    if not os.path.lexists(staging / name):
                        _carry(entry, staging / name)
            else:
                os.chmod(staging, 0o777 & ~_umask())
            check_output_path(target, directory=True)
            with deferred_signals():
                _swap_in(staging, target)
        except OSError as exc:
            raise _oserror(target, exc) from exc
    finally:
        _OPEN.pop(key, None)
        if os.path.lexists(staging):
            shutil.rmtree(staging, ignore_errors=True)


# --------------------------------------------------------------------------- the boundary check


def _nearest_existing(path: Path) -> Path:
    """The path itself or its nearest ancestor that exists (``.`` for a bare relative name)."""
    probe = Path(os.path.abspath(path))
    while not os.path.lexists(probe) and probe.parent != probe:
        probe = probe.parent
    return probe


def _probe_writable(folder: Path, shown: str) -> None:
    """Create and remove one temporary file in ``folder``: the only test that sees read-only
    mounts, immutable folders (chattr +i, which root's ``os.access`` does not), /proc and /sys."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".probe.tmp.{os.getpid()}.", dir=folder)
    except OSError as exc:
        raise InputError(
            f"{shown}: cannot write there ({exc.strerror or type(exc).__name__} in {folder}); "
            "nothing was done"
        ) from exc
    os.close(fd)
    try:
        os.unlink(tmp)
    except OSError:  # pragma: no cover - raced away
        pass


def _same_file(a: Path, b: Path) -> bool:
    """The same file: the same real path (links, ``..``) or the same inode (hard links)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output_location(
    path: str | os.PathLike[str],
    *,
    option: str,
    directory: bool = False,
    inputs: Iterable[str | os.PathLike[str] | None] = (),
    writes: Iterable[str] = (),
) -> Path:
    """The one check of an output location, made at a command's entry before any work.

    Parameters
    ----------
    path : path-like
        The output: a file, or a folder (``directory=True``).
    option : str
        How the user named it (``--out``, ``--screenshot``, ``output.dir``), for the message.
    directory : bool
        True when ``path`` is a folder the command fills.
    inputs : iterable of path-like
        The command's input files (None entries are skipped). The output may be none of them,
        directly or through a symbolic link, ``..`` or a hard link; for a folder, none of the
        files it ``writes`` (names inside it) may be an input.
    writes : iterable of str
        For a folder: the names the command may write into it.

    Returns
    -------
    Path
        ``path`` unchanged.

    Raises
    ------
    InputError
        One line naming the option and the reason: a special file (FIFO, device, socket) or a
        symbolic link, a file where a folder is meant (or the reverse), a location that cannot
        be created or written (a missing parent that cannot be made, /proc, a read-only or
        immutable folder), one of the command's own inputs, or (a folder) the working
        directory or one of its parents.
    """
    target = Path(path)
    try:
        check_output_path(target, directory=directory)
    except InputError as exc:
        raise InputError(f"{option}: {exc}") from None
    if directory:
        # also for commands that fill a folder point by point (sweep), not in one swap
        _refuse_working_directory(target, f"{option}: ")
    sources = [Path(p) for p in inputs if p is not None]
    outputs = [target / name for name in writes] if directory else [target]
    for source in sources:
        if not os.path.lexists(source):
            continue
        for out in outputs:
            if _same_file(out, source):
                raise InputError(
                    f"{option}: {out} is the command's input {source}; writing it would destroy "
                    "the input: give another output"
                )
        if directory and _same_file(target, source):
            raise InputError(f"{option}: {target} is the command's input {source}")
    existing = _nearest_existing(target)
    absolute = Path(os.path.abspath(target))
    if not directory and existing not in (absolute, absolute.parent):
        # a file's writer makes no folder: refused now, not after the work (frontier
        # --recommend new/rec.toml searched for 51 s first)
        raise InputError(
            f"{option}: {target}: cannot write it, directory {target.parent} does not exist"
        )
    if not existing.is_dir() and not (not directory and existing == absolute):
        # an existing file is a valid target (it is replaced whole), a folder's is not
        raise InputError(f"{option}: {target}: cannot create it, {existing} is not a directory")
    probes = [existing]
    if existing == absolute:
        # an existing file's folder takes the temporary; an existing folder is swapped from
        # its parent (staging beside it) and must itself be changeable (not immutable)
        probes = [existing.parent] if not directory else [existing, existing.parent]
    for folder in probes:
        _probe_writable(folder, f"{option}: {target}")
    return target


def check_outputs(
    outputs: Iterable[tuple[str, str | os.PathLike[str] | None, bool]],
    inputs: Iterable[str | os.PathLike[str] | None] = (),
    writes: Iterable[str] = (),
) -> None:
    """:func:`check_output_location` for each ``(option, path, directory)`` of a command
    (None paths are skipped), against the same inputs."""
    sources = list(inputs)
    names = list(writes)
    for option, path, directory in outputs:
        if path is None:
            continue
        check_output_location(
            path, option=option, directory=directory, inputs=sources, writes=names
        )
