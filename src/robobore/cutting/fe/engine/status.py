"""Run status of the explicit engines: what each instability code in ``ist[I_STATUS]`` means
and the error raised for it.

Shared by every chunk driver (2D and 3D, CPU and GPU:
:func:`robobore.cutting.fe.engine.chunk_driver. drive_chunks`,
:func:`robobore.cutting.fe.engine.gpu.backend2d.advance_gpu`,
:func:`robobore.cutting.fe.engine.gpu.backend3d.advance3_gpu`). The codes themselves are
:mod:`robobore.cutting.fe.engine.layout`' ``STATUS_*`` (the 3D kernels use the same ones).
"""

from __future__ import annotations

from typing import Any

from robobore.cutting.fe.engine import layout
from robobore.errors import NumericalError

__all__ = ["STATUS_TEXT", "instability_error"]

#: instability status code -> its cause, in words (a status in here stops a run)
STATUS_TEXT = {
    layout.STATUS_NONFINITE: "non-finite forces, velocities or time step",
    layout.STATUS_DT_COLLAPSE: "stable time step collapsed below 1/1000 of the initial one "
                          "(an element inverted or was crushed)",
    layout.STATUS_INVERTED: "an element turned inside out (negative area)",
    layout.STATUS_NO_ELEMENTS: "no element left (all eroded or inverted)",
}


def instability_error(st: Any, label: str, hint: str) -> NumericalError:
    """The error for a run stopped by an instability status (2D or 3D, CPU or GPU): step,
    time, cause (and the inverted element), what to change."""
    status = int(st.ist[layout.I_STATUS])
    return NumericalError(
        f"{label} unstable at step {int(st.ist[layout.I_STEP])}, time {st.time:.6g} s: "
        f"{STATUS_TEXT[status]}"
        + (f" (element {int(st.ist[layout.I_BADELEM])})"
           if status == layout.STATUS_INVERTED else "")
        + f"; try {hint}")
