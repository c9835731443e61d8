"""The mesh frame of an FE config (``[mesh] frame``), typed: :class:`Frame`.

The TOML value stays the string (``"tool"`` or ``"workpiece"``); the validated config holds
the member, which says what it is (:attr:`Frame.is_tool`) so that no code compares the
frame's string. The model of a frame is chosen in :mod:`robobore.cutting.fe.models.choose`.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["Frame"]


class Frame(StrEnum):
    """``[mesh] frame``: ``"workpiece"`` (Lagrangian: the mesh moves with the material) or
    ``"tool"`` (ALE: the mesh travels with the tool, material flows through it)."""

    WORKPIECE = "workpiece"
    TOOL = "tool"

    @property
    def is_tool(self) -> bool:
        """True for the tool frame (the ALE mesh round the edge)."""
        return self is Frame.TOOL
