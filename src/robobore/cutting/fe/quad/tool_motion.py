"""The tool of the plane-strain engine over one step: its edge centre and velocity
(:func:`tool_kinematics_py`) and its advance under the contact force, with the optional
spring-damper support (:func:`tool_step_py`).
"""

from __future__ import annotations

from numba import njit

from robobore.cutting.fe.engine.layout import (
    P_CX,
    P_CY,
    P_KX,
    P_KY,
    P_MX,
    P_MY,
    P_SUPPORT,
    P_TCX,
    P_TCY,
    P_VC,
    P_WIDTH,
    T_FX,
    T_FY,
    T_GX,
    T_GY,
    T_UX,
    T_UY,
    T_VUX,
    T_VUY,
)
from robobore.cutting.fe.physics.tool_contact import (
    tool_support_step,
)


def tool_kinematics_py(tool, prm):
    """Tool edge centre (cx, cy) [m] and velocity (tvx, tvy) [m/s] at the start of a step."""
    return (tool[T_GX] + tool[T_UX], tool[T_GY] + tool[T_UY], -prm[P_VC] + tool[T_VUX],
            tool[T_VUY])


def make_tool_step(tool_support_step):
    """:func:`tool_step_py` with its callees ``tool_support_step`` given (the CPU's
    compiled functions here, a GPU engine's device functions in its port)."""

    def tool_step_py(tool, prm, fwx, fwy, dt):
        """Advance the tool over one step under the contact force (fwx, fwy) on the workpiece.

        Stores the force on the tool, integrates the support springs (when ``prm[P_SUPPORT]``),
        moves the guide point at -vc, records the new edge centre in ``prm[P_TCX]``/``[P_TCY]``
        (for the erosion gate) and returns the work of the tool on the workpiece over the step
        [J/m] (midpoint velocities).
        """
        vc = prm[P_VC]
        width = prm[P_WIDTH]
        tvx = -vc + tool[T_VUX]
        tvy = tool[T_VUY]
        # force on the tool = - force on the workpiece [N/m]
        tool[T_FX] = -fwx
        tool[T_FY] = -fwy
        if prm[P_SUPPORT] > 0.5:
            ux, vux = tool_support_step(tool[T_UX], tool[T_VUX], -fwx * width, prm[P_KX],
                                        prm[P_CX], prm[P_MX], dt)
            uy, vuy = tool_support_step(tool[T_UY], tool[T_VUY], -fwy * width, prm[P_KY],
                                        prm[P_CY], prm[P_MY], dt)
            tool[T_UX] = ux
            tool[T_VUX] = vux
            tool[T_UY] = uy
            tool[T_VUY] = vuy
        tool[T_GX] -= vc * dt
        tvx_new = -vc + tool[T_VUX]
        tvy_new = tool[T_VUY]
        prm[P_TCX] = tool[T_GX] + tool[T_UX]
        prm[P_TCY] = tool[T_GY] + tool[T_UY]
        return dt * (fwx * 0.5 * (tvx + tvx_new) + fwy * 0.5 * (tvy + tvy_new))

    return tool_step_py


tool_kinematics = njit(cache=True)(tool_kinematics_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
tool_step_py = make_tool_step(tool_support_step)
tool_step = njit(cache=False)(tool_step_py)
