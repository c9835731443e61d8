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
