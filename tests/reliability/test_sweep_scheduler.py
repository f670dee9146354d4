"""A --scheduler that does not answer, or answers another protocol, is one line within its
timeout: no wait without end, no traceback (not even from Dask's Client.__del__ at exit)."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "examples" / "sweeps" / "theorem_t_end.sweep"


def _server(reply: bytes | None) -> Iterator[str]:
    """A loopback server that accepts and then says ``reply`` to every request, or nothing."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(8)
    listener.settimeout(0.2)
    stop = threading.Event()
    held: list[socket.socket] = []

    def serve() -> None:
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except OSError:
                continue
            held.append(conn)
            if reply is not None:
                try:
                    conn.settimeout(2.0)
                    conn.recv(65536)
                    conn.sendall(reply)
                except OSError:
                    pass

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    finally:
        stop.set()
        thread.join(2.0)
        for conn in held:
            conn.close()
        listener.close()


@pytest.fixture
def silent_server() -> Iterator[str]:
    yield from _server(None)


@pytest.fixture
def http_server() -> Iterator[str]:
    yield from _server(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")


def _sweep(address: str, out: Path) -> tuple[int, str, float]:
    argv = [sys.executable, "-m", "chargedesign", "sweep", str(SWEEP), "--out", str(out)]
    argv += ["--scheduler", address, "--scheduler-timeout", "1"]
    start = time.monotonic()
    done = subprocess.run(argv, capture_output=True, text=True, timeout=120, cwd=out.parent)
    return done.returncode, done.stderr, time.monotonic() - start


def _assert_one_line(code: int, err: str, address: str) -> None:
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2, err
    assert len(lines) == 1, err
    assert f"--scheduler {address}" in lines[0] and "--scheduler-timeout" in lines[0], err
    assert "Traceback" not in err and "Exception ignored" not in err, err


def test_a_scheduler_that_never_answers_is_refused_within_its_timeout(silent_server, tmp_path):
    code, err, _seconds = _sweep(silent_server, tmp_path / "o")
    _assert_one_line(code, err, silent_server)
    assert "no answer" in err
    assert not (tmp_path / "o").exists()


def test_a_server_speaking_http_is_one_line_not_out_of_memory(http_server, tmp_path):
    code, err, _seconds = _sweep(http_server, tmp_path / "o")
    _assert_one_line(code, err, http_server)
    assert "out of memory" not in err
    assert "does not speak Dask's protocol" in err
    assert not (tmp_path / "o").exists()


def test_the_scheduler_timeout_has_a_range(tmp_path, capsys):
    from chargedesign.cli import main

    code = main(["sweep", str(SWEEP), "--out", str(tmp_path / "o"), "--scheduler-timeout", "0"])
    err = capsys.readouterr().err
    assert code == 2 and "--scheduler-timeout" in err and err.count("\n") == 1, err
