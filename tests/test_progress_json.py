"""The progress bar goes to stderr: ``--json`` (commands pass ``enabled=not as_json``) keeps it
while stderr is a terminal and drops it when stderr is redirected."""

from __future__ import annotations

import io

from rich.console import Console

from robobore import clitools


def _run(monkeypatch, terminal: bool, enabled: bool) -> str:
    buf = io.StringIO()
    monkeypatch.setattr(clitools, "stderr", Console(file=buf, force_terminal=terminal,
                                                    width=80))
    with clitools.progress_bar("working", 3, enabled) as advance:
        for _ in range(3):
            advance(1)
    return buf.getvalue()


def test_json_keeps_the_bar_on_a_terminal(monkeypatch):
    assert "working" in _run(monkeypatch, terminal=True, enabled=False)


def test_json_to_a_pipe_prints_no_bar(monkeypatch):
    assert _run(monkeypatch, terminal=False, enabled=False) == ""


def test_table_output_keeps_the_bar(monkeypatch):
    assert "working" in _run(monkeypatch, terminal=True, enabled=True)


def test_fraction_progress_advances_to_the_fraction_and_never_back(monkeypatch):
    steps: list[int] = []

    class _Bar:
        def __enter__(self):
            return lambda n=1: steps.append(n)

        def __exit__(self, *exc):
            return False

    monkeypatch.setattr(clitools, "progress_bar", lambda desc, total, enabled: _Bar())
    with clitools.fraction_progress("FE", enabled=True) as prog:
        for frac in (0.1, 0.05, 0.5, 0.5, 1.0, 1.3):
            prog(frac)
    assert steps == [100, 400, 500]


def test_stage_progress_gives_each_task_its_own_bar_one_at_a_time(monkeypatch):
    """Library code reports ``progress(task, done, total)``; the CLI's adapter opens one bar
    per task, closes it when done reaches total or when the next task starts."""
    events: list[tuple] = []

    class _Bar:
        def __init__(self, desc, total):
            self.desc = desc
            events.append(("open", desc, total))

        def __enter__(self):
            return lambda n=1: events.append(("advance", self.desc, n))

        def __exit__(self, *exc):
            events.append(("close", self.desc))
            return False

    monkeypatch.setattr(clitools, "progress_bar", lambda desc, total, enabled: _Bar(desc, total))
    with clitools.stage_progress(enabled=True) as progress:
        progress("a", 0, 2)
        progress("a", 1, 2)
        progress("a", 2, 2)
        progress("a", 2, 2)  # a finished task does not reopen
        progress("b", 0, 5)
        progress("b", 3, 5)
        progress("c", 1, 1)
        progress("d", 0, 4)  # left open: closed when the context ends
    assert events == [("open", "a", 2), ("advance", "a", 1), ("advance", "a", 1),
                      ("close", "a"), ("open", "b", 5), ("advance", "b", 3), ("close", "b"),
                      ("open", "c", 1), ("advance", "c", 1), ("close", "c"),
                      ("open", "d", 4), ("close", "d")]


def test_stage_progress_draws_the_rich_bars_on_a_terminal(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(clitools, "stderr", Console(file=buf, force_terminal=True, width=80))
    with clitools.stage_progress(enabled=False) as progress:  # --json on a terminal
        for i in range(3):
            progress("identify robot and modes", i, 2)
        progress("sweep demo", 0, 1)
        progress("sweep demo", 1, 1)
    out = buf.getvalue()
    assert "identify robot and modes" in out and "sweep demo" in out
    buf.truncate(0)
    monkeypatch.setattr(clitools, "stderr", Console(file=buf, force_terminal=False, width=80))
    with clitools.stage_progress(enabled=False) as progress:  # --json to a pipe: no bar
        progress("sweep demo", 0, 1)
        progress("sweep demo", 1, 1)
    assert buf.getvalue() == ""
