"""Progress reports (`sim.common.progress`): a tqdm bar on a terminal, plain lines at most one per period in a log."""
import io

from sim.common import progress as module
from sim.common.progress import PlainProgress, progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_log_gets_plain_lines_at_most_one_per_period_and_a_last_one(monkeypatch):
    now = [0.0]
    monkeypatch.setattr(module.time, "monotonic", lambda: now[0])
    log = io.StringIO()
    report = progress(100, "tasks", "run", stream=log)
    assert isinstance(report, PlainProgress)
    for step in range(100):
        now[0] = step * 1.0  # one run a second: a line every PLAIN_EVERY_S runs
        report.update()
    report.write("a line of its own")
    report.close()
    lines = log.getvalue().splitlines()
    period = int(module.PLAIN_EVERY_S)
    left = period / (period + 1) * (100 - period - 1)  # the rate so far times the runs left
    assert lines[0] == f"tasks: {period + 1}/100 run ({period + 1} %), {period} s, about {left:.0f} s left"
    assert len(lines) == 99 // period + 2 and lines[-2] == "a line of its own" and lines[-1].endswith(", done")


def test_short_work_in_a_log_says_nothing_and_a_terminal_gets_a_bar():
    log = io.StringIO()
    with progress(5, "tasks", "run", stream=log) as report:
        report.update(5)
    assert log.getvalue() == ""
    terminal = Terminal()
    with progress(5, "tasks", "run", stream=terminal) as bar:
        bar.update(5)
    assert "\r" in terminal.getvalue() and "5/5" in terminal.getvalue()
    quiet = io.StringIO()
    with progress(5, "tasks", "run", stream=quiet, enabled=False) as off:
        off.update(5)
    assert quiet.getvalue() == ""
