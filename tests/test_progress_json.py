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
