"""Progress on stderr says its total and the time left; without a terminal it writes a line
every few seconds (the default simulate once ran 596 s saying nothing)."""

from __future__ import annotations

import io
import time

import pytest

from chargedesign.commands import progress as progress_module
from chargedesign.commands.progress import Progress, duration_text


@pytest.fixture
def quick(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(progress_module, "FIRST_AFTER", 0.0)
    monkeypatch.setattr(progress_module, "EVERY", 0.05)


def test_a_count_says_its_total_and_the_time_left(quick: None) -> None:
    stream = io.StringIO()
    with Progress("sweep", unit="points", stream=stream, tty=False) as bar:
        bar.update(1, 4)
        time.sleep(0.1)
        bar.update(2, 4, "1 failed")
        bar.update(4, 4)
    lines = stream.getvalue().splitlines()
    assert lines, "no line without a terminal"
    # which counts are written between the heartbeat's lines depends on the machine's load:
    # some line says the total and the time left, the last says the whole count and its extra
    assert any("/4 points" in line and "left" in line for line in lines), lines
    assert lines[-1].startswith("sweep: 4/4 points (1 failed)") and lines[-1].endswith("done")
    assert all("\r" not in line for line in lines)


def test_a_fraction_on_a_terminal_is_one_line_redrawn(quick: None) -> None:
    stream = io.StringIO()
    bar = Progress("simulate", stream=stream, tty=True)
    bar(0.25)
    time.sleep(0.06)
    bar(0.5)
    bar.close()
    text = stream.getvalue()
    assert text.count("\n") == 1 and text.endswith("\n")
    assert "\rsimulate: [" in text and " 50%" in text and "left" in text


def test_the_heartbeat_speaks_while_one_unit_of_work_runs(quick: None) -> None:
    stream = io.StringIO()
    with Progress("frontier --recommend", unit="probes", stream=stream, tty=False) as bar:
        bar.update(1, 10)
        time.sleep(0.3)  # no update: the heartbeat still writes
    assert stream.getvalue().count("1/10 probes") >= 2


def test_durations_read_at_a_glance() -> None:
    assert duration_text(3.2) == "3.2 s"
    assert duration_text(42.0) == "42 s"
    assert duration_text(185.0) == "3 min 5 s"
    assert duration_text(7800.0) == "2 h 10 min"
