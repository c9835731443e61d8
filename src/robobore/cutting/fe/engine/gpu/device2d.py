"""Device versions of the 2D engine's scalar functions, for the GPU engine's kernels
(:mod:`robobore.cutting.fe.engine.gpu.kernels2d`).

The element, node, tool, conduction, energy, tool-frame ALE and end-of-step updates are the
plain-Python scalar functions the CPU engine compiles with ``njit``
(:mod:`robobore.cutting.fe.quad`, :mod:`robobore.cutting.fe.engine.history`,
:mod:`robobore.cutting.fe.ale.rezone`, :mod:`robobore.cutting.fe.physics.tool_contact`,
:mod:`robobore.material.johnson_cook`); :func:`device_functions2` makes each one that calls
others with its factory (``make_quad_element``, ``make_quad_node``, ...), given the device
versions of its callees, and compiles it with ``numba.cuda.jit(device=True)``.
"""

from __future__ import annotations

from types import SimpleNamespace

from robobore.cutting.fe.ale import remap
from robobore.cutting.fe.ale import rezone as RZ
from robobore.cutting.fe.engine.gpu.shared import jc_device_functions
from robobore.cutting.fe.physics import thermal2d
from robobore.cutting.fe.quad import element as q_element
from robobore.cutting.fe.quad import node_contact, tool_motion

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
    csplit = dev(node_contact.make_contact_split_node(tool_face=tface))
    tool_geometry = dev(node_contact.tool_geometry_py)
    # the tool-frame ALE pass (rezone.py's scalar functions)
    lim = dev(RZ.limit_py)
    tplace = dev(RZ.make_tf_place(limit=lim, off_tool=dev(RZ.make_off_tool(tool_gap=tg))))
    tfacep = dev(RZ.tf_face_py)
    tsweep = dev(RZ.tf_sweep_py)
    tscopy = dev(RZ.tf_sweep_copy_py)
    tinter = dev(RZ.make_tf_interior(limit=lim))
    rflux = dev(remap.make_rz_flux(swept=dev(remap.swept_py)))
    rvel = dev(remap.rz_velocity_py)
    rwrite = dev(remap.rz_write_py)
    rmass = dev(remap.rz_node_mass_py)
    SWEEPS = RZ.TF_SWEEPS
    cf = dev(make_contact_force(normal_force=dev(normal_force_py)))
    sup = dev(tool_support_step_py)
    retire = dev(q_element.quad_retire_py)
    elem = dev(q_element.make_quad_element(
        radial_return=rret, jc_damage_increment=dmg, quad_retire=retire,
        quad_area_corners=dev(q_element.quad_area_corners_py),
        quad_distorted=dev(q_element.make_quad_distorted(quad_retire=retire)),
        quad_bvectors=dev(q_element.quad_bvectors_py), quad_step=dev(q_element.quad_step_py),
        damage_erosion=dev(q_element.make_damage_erosion(tool_gap=tg))))
    node = dev(node_contact.make_quad_node(tool_gap=tg, contact_force=cf,
                                friction_at=dev(node_contact.friction_at_py)))
    kin = dev(tool_motion.tool_kinematics_py)
    tstep = dev(tool_motion.make_tool_step(tool_support_step=sup))
    cent = dev(thermal2d.quad_centroid_py)
    cond = dev(thermal2d.quad_conduct_py)
    pedge = dev(thermal2d.parting_edge_py)
    thnode = dev(thermal2d.tool_heat_node_py)
    thelem = dev(thermal2d.tool_heat_elem_py)
    lsum = dev(node_contact.lane_sum_py)
    # the end of a step (robobore.cutting.fe.engine.history) bound to the 2D engine
    from robobore.cutting.fe.engine import chunk_loop as CL
    from robobore.cutting.fe.engine.history import make_end_step

    end_step = make_end_step(dev, CL.ENGINE2, dev(CL.tool_columns_py), dev(CL.sum_energies_py))
    return SimpleNamespace(
        csplit=csplit, tool_geometry=tool_geometry, tplace=tplace, tfacep=tfacep,
        tsweep=tsweep, tscopy=tscopy, tinter=tinter, rflux=rflux, rvel=rvel, rwrite=rwrite,
        rmass=rmass, SWEEPS=SWEEPS, elem=elem, node=node, kin=kin, tstep=tstep, cent=cent,
        cond=cond, pedge=pedge, thnode=thnode, thelem=thelem, end_step=end_step, lsum=lsum)
