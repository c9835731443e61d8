"""Docs, sources and tests describe the product as it is, not how it came to be.

Scans ``docs/*.md``, ``src/**/*.py`` and ``tests/**/*.py`` (this file excepted) for phrases
that narrate the development history -- numbered work sessions, work sittings, "was X, now
Y", "before / after the change" -- and fails naming every file:line. History belongs in git
and in CHANGELOG.md (kept by release, not scanned).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: case-insensitive patterns of development narration
PATTERNS = [re.compile(p, re.IGNORECASE) for p in (
    r"\bsession \d",
    r"\bsitting\b",
    r"\bwas [^.]{0,40}, now\b",
    r"before the change",
    r"after the change",
)]


def _files() -> list[Path]:
    me = Path(__file__).resolve()
    files = sorted((ROOT / "docs").glob("*.md"))
    files += sorted((ROOT / "src").rglob("*.py"))
    files += sorted(p for p in (ROOT / "tests").rglob("*.py") if p.resolve() != me)
    return files


def narration_lines(text: str) -> list[tuple[int, str]]:
    """(line number, line) of every line of ``text`` that matches a narration pattern."""
    return [(i, line) for i, line in enumerate(text.splitlines(), start=1)
            if any(p.search(line) for p in PATTERNS)]


def narration_hits(files: list[Path]) -> list[str]:
    """``file:line: text`` for every narrating line of ``files``."""
    return [f"{path.relative_to(ROOT)}:{i}: {line.strip()[:120]}"
            for path in files
            for i, line in narration_lines(path.read_text(encoding="utf-8", errors="replace"))]


def test_the_scan_covers_docs_sources_and_tests():
    files = _files()
    names = {p.relative_to(ROOT).as_posix() for p in files}
    assert "docs/fe.md" in names and "docs/fe3d.md" in names
    assert any(n.startswith("src/robobore/") for n in names)
    assert any(n.startswith("tests/") for n in names)
    assert "tests/test_docs_no_narration.py" not in names


@pytest.mark.parametrize("line", [
    "Measured in session 12 on the H100.",
    "the work sitting of 2026-11-22",
    "the limit was ten elements, now it is five",
    "Fc before the change: 93 N/mm",
    "After the change the kernel is faster.",
])
def test_the_patterns_catch_narration(line):
    assert narration_lines(f"A product description.\n{line}\n") == [(2, line)]


@pytest.mark.parametrize("line", [
    "The session fixture is shared by the tests.",
    "This value was measured at 30 m/min; the model now gives 112.9 N/mm.",
    "Fc 93 N/mm, as before.",
])
def test_the_patterns_leave_plain_text(line):
    assert narration_lines(line + "\n") == []


def test_no_development_narration_in_docs_sources_and_tests():
    hits = narration_hits(_files())
    assert not hits, ("development narration (describe the product as it is; history "
                      "belongs in git and CHANGELOG.md):\n" + "\n".join(hits))
