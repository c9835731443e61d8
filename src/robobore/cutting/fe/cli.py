"""CLI commands of this stage (registered by ``robobore.cli``)."""

from __future__ import annotations

import typer


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
