"""Device versions of the 2D engine's scalar functions, for the GPU engine's kernels
(:mod:`robobore.cutting.fe.engine.gpu.kernels2d`).

The element, node, tool, conduction, energy, tool-frame ALE and end-of-step updates are the
plain-Python scalar functions the CPU engine compiles with ``njit``
(:mod:`robobore.cutting.fe.engine.kernels`, :mod:`robobore.cutting.fe.engine.history`,
:mod:`robobore.cutting.fe.ale.rezone`, :mod:`robobore.cutting.fe.physics.tool_contact`,
:mod:`robobore.material.johnson_cook`); :func:`device_functions2` makes each one that calls
others with its factory (``make_quad_element``, ``make_quad_node``, ...), given the device
versions of its callees, and compiles it with ``numba.cuda.jit(device=True)``.
"""

from __future__ import annotations

from types import SimpleNamespace

from robobore.cutting.fe.ale import rezone as RZ
from robobore.cutting.fe.engine import kernels as K
from robobore.cutting.fe.engine.gpu.shared import jc_device_functions

__all__ = ["device_functions2"]


def device_functions2(dev) -> SimpleNamespace:
    """The device functions of the 2D GPU kernels, by the names the kernels call them
    (``dev`` = ``numba.cuda.jit(device=True)``)."""
    from robobore.cutting.fe.physics.tool_contact import (
        make_contact_force,
        make_tool_gap,
        normal_force_py,
        tool_face_py,
        tool_support_step_py,
    )
    from robobore.material import johnson_cook as jc

    dmg, ret = jc_device_functions(dev)
    rret = dev(jc.make_radial_return(jc_return=ret))
    tface = dev(tool_face_py)
    tg = dev(make_tool_gap(tool_face=tface))
    csplit = dev(K.make_contact_split_node(tool_face=tface))
    tool_geometry = dev(K.tool_geometry_py)
    # the tool-frame ALE pass (rezone.py's scalar functions)
    lim = dev(RZ.limit_py)
    tplace = dev(RZ.make_tf_place(limit=lim, off_tool=dev(RZ.make_off_tool(tool_gap=tg))))
    tfacep = dev(RZ.tf_face_py)
    tsweep = dev(RZ.tf_sweep_py)
    tscopy = dev(RZ.tf_sweep_copy_py)
    tinter = dev(RZ.make_tf_interior(limit=lim))
    rflux = dev(RZ.make_rz_flux(swept=dev(RZ.swept_py)))
    rvel = dev(RZ.rz_velocity_py)
    rwrite = dev(RZ.rz_write_py)
    rmass = dev(RZ.rz_node_mass_py)
    SWEEPS = RZ.TF_SWEEPS
    cf = dev(make_contact_force(normal_force=dev(normal_force_py)))
    sup = dev(tool_support_step_py)
    retire = dev(K.quad_retire_py)
    elem = dev(K.make_quad_element(
        radial_return=rret, jc_damage_increment=dmg, quad_retire=retire,
        quad_area_corners=dev(K.quad_area_corners_py),
        quad_distorted=dev(K.make_quad_distorted(quad_retire=retire)),
        quad_bvectors=dev(K.quad_bvectors_py), quad_step=dev(K.quad_step_py),
        damage_erosion=dev(K.make_damage_erosion(tool_gap=tg))))
    node = dev(K.make_quad_node(tool_gap=tg, contact_force=cf,
                                friction_at=dev(K.friction_at_py)))
    kin = dev(K.tool_kinematics_py)
    tstep = dev(K.make_tool_step(tool_support_step=sup))
    cent = dev(K.quad_centroid_py)
    cond = dev(K.quad_conduct_py)
    pedge = dev(K.parting_edge_py)
    thnode = dev(K.tool_heat_node_py)
    thelem = dev(K.tool_heat_elem_py)
    lsum = dev(K.lane_sum_py)
    # the end of a step (robobore.cutting.fe.engine.history) bound to the 2D engine
    from robobore.cutting.fe.engine import chunk_loop as CL
    from robobore.cutting.fe.engine.history import make_end_step

    end_step = make_end_step(dev, CL.ENGINE2, dev(CL.tool_columns_py), dev(CL.sum_energies_py))
    return SimpleNamespace(
        csplit=csplit, tool_geometry=tool_geometry, tplace=tplace, tfacep=tfacep,
        tsweep=tsweep, tscopy=tscopy, tinter=tinter, rflux=rflux, rvel=rvel, rwrite=rwrite,
        rmass=rmass, SWEEPS=SWEEPS, elem=elem, node=node, kin=kin, tstep=tstep, cent=cent,
        cond=cond, pedge=pedge, thnode=thnode, thelem=thelem, end_step=end_step, lsum=lsum)
