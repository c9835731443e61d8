"""The 3D boring model on the tool-frame ALE mesh (``[mesh] frame = "tool"`` in a
``robobore fe boring`` config; docs/fe3d.md, "Tool-frame 3D model").

The mesh is :func:`robobore.cutting.fe.mesh.toolframe3d.build_toolframe3d_mesh` of the
config's insert, depth of cut and feed: the 2D tool-frame mesh stacked in z-slices under the
insert's nose, built round the insert with its tip at the origin of the local frame of
:mod:`robobore.cutting.fe.models.boring3d`. Everything but the mesh and the separation is the
workpiece-frame boring model's (:func:`~robobore.cutting.fe.models.boring_setup.boring_prm`:
material, hardening hold, friction, heat conduction, numerics, insert, kinematics, tool
support): the insert moves along +x at the cutting speed and along +z at the feed speed, the
material is at rest in the workpiece. Boundary conditions: the inflow face and the bottom
(``rigid``) held in every component, z held on the block's two side planes (the first and
last slice, faces ``FK_SIDE``). Every ``solver.ale_interval`` steps the compiled loop
(:func:`robobore.cutting.fe.engine.kernels3d.run_chunk3_ale`) moves the mesh back to its
place in the insert's frame -- the places ``x0, y0, z0`` shifted by the insert tip's travel
since the start -- and remaps the state (:func:`robobore.cutting.fe.ale.rezone3d.rezone3d`).
Thin elements: the clamped chip at both ends of the engaged edge is a few micrometres thick
in the rows of the nose-tip section, so its hexahedra have stable steps several times shorter
than any element of the nose-tip section, and they alone would set the explicit step.
With ``solver.thin_element_mass_scaling`` (default) those elements get inertia factors
(:func:`thin_element_factors`): mass scaling attached to the mesh -- to the place in the
insert's frame, not to the material flowing through it -- so that no element's stable step is
below the smallest of the nose-tip section. The factored elements lie at the chip's thin
ends, where the chip moves at about the cutting speed, far below their scaled wave speed (the
run's kinetic energy is reported). No damage or time-step erosion; the energy balance is the
2D tool frame's (the cumulative element accounts stay with their elements through the remap,
checked from the start of the run).
"""

from __future__ import annotations

import math

import numpy as np

from robobore.cutting.fe.ale.hexvolume3d import FACES_OUT
from robobore.cutting.fe.config.boring3d import BoringFEConfig
from robobore.cutting.fe.config.spec_build import build_boring_spec
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine.state3d import FEState3, element_steps3, make_state3
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.mesh.toolframe3d import FK_SIDE, ToolFrameMesh3D, build_toolframe3d_mesh
from robobore.cutting.fe.mesh.toolframe3d_layout import ToolFrame3DSizes
from robobore.cutting.fe.models.boring_setup import BoringSetup, boring_prm, check_support_step
from robobore.cutting.fe.models.results import ToolFrameMeshSummary
from robobore.errors import ConfigError
from robobore.material.library import Material, load_material

__all__ = ["toolframe_fixed", "attach_toolframe", "thin_element_factors", "tip_section_step",
           "setup_boring_toolframe", "toolframe_mesh_summary"]


def toolframe_fixed(mesh: ToolFrameMesh3D) -> np.ndarray:
    """The ``fixed`` bit mask (n,) of a tool-frame mesh: the rigid nodes (inflow face,
    bottom) in every component, z on the nodes of the ``FK_SIDE`` faces (the block's two
    side planes)."""
    fixed = np.zeros(mesh.n_nodes, np.int64)
    e, f = np.nonzero(mesh.fkind == FK_SIDE)
    side = np.unique(mesh.conn[e[:, None], FACES_OUT[f]])
    fixed[side] |= scalar3d.FIX_Z
    fixed[mesh.rigid] = scalar3d.FIX_X | scalar3d.FIX_Y | scalar3d.FIX_Z
    return fixed


def attach_toolframe(st: FEState3, mesh: ToolFrameMesh3D, tip: tuple[float, float, float]
                     ) -> None:
    """Give the state ``st`` of ``mesh`` its ALE arrays (node places, classes, placement
    data from :func:`robobore.cutting.fe.ale.rezone3d.toolframe3d_ale_data`, flux flags)
    and the insert tip's start ``tip`` [m] from which the mesh's travel is measured."""
    from robobore.cutting.fe.ale.rezone3d import toolframe3d_ale_data

    acls, aflt = toolframe3d_ale_data(mesh)
    st.attach_tool_frame(acls, aflt, mesh.bflag)
    st.prm[layout3d.P_ALE_X0] = tip[0]
    st.prm[layout3d.P_ALE_Z0] = tip[2]


def tip_section_step(st: FEState3, mesh: ToolFrameMesh3D, dte: np.ndarray | None = None) -> float:
    """``dt_tip`` [s]: the smallest material stable step ``dte`` (default
    :func:`robobore.cutting.fe.engine.state3d.element_steps3`, the mesh as built) of the
    hexahedra on either side of the nose-tip slice (z = 0, the 2D section the mesh is built
    from)."""
    dte = element_steps3(st) if dte is None else dte
    k0 = int(np.argmin(np.abs(mesh.z_slices)))
    tip = (mesh.elem_slice == k0) | (mesh.elem_slice == k0 - 1)
    return float(np.min(dte[tip]))


def thin_element_factors(st: FEState3, mesh: ToolFrameMesh3D,
                         dte: np.ndarray | None = None) -> np.ndarray:
    """Inertia factors (e,) >= 1 of the tool-frame mesh as built: ``(dt_tip / dt_e)^2`` for
    each element whose material stable step ``dt_e`` (``dte``, default
    :func:`~robobore.cutting.fe.engine.state3d.element_steps3`) is below
    :func:`tip_section_step`; 1 elsewhere. With them the mesh's stable step is the nose-tip
    section's. The rule is the one the ALE pass renews them by
    (:func:`robobore.cutting.fe.engine.kernels3d.renew_inertia_factors_py`,
    ``prm[P_MSF_DT] = dt_tip``)."""
    dte = element_steps3(st) if dte is None else dte
    msf = np.ones_like(dte)
    K3.renew_inertia_factors(msf, dte, st.alive, tip_section_step(st, mesh, dte))
    return msf


def setup_boring_toolframe(cfg: BoringFEConfig, source: str | None = None):
    """Mesh, insert, support and state of the boring config ``cfg`` with
    ``mesh.frame = "tool"`` (a :class:`robobore.cutting.fe.models.boring3d.BoringSetup`)."""

    mat: Material = load_material(cfg.material.name, source=source,
                                  hardening_strain_limit=cfg.material.strain_limit())
    ins = cfg.insert.to_insert()
    ap = cfg.cut.depth_of_cut_mm * 1e-3
    f = cfg.cut.feed_mm_per_rev * 1e-3
    L = cfg.cut.cut_length_mm * 1e-3
    R = 0.5 * cfg.cut.bore_diameter_mm * 1e-3
    vc = 2 * math.pi * R * cfg.cut.speed_rpm / 60.0
    m = cfg.mesh
    sizes = ToolFrame3DSizes.of_config(m)
    try:
        mesh = build_toolframe3d_mesh(ins, ap, f, sizes)
    except ValueError as exc:
        raise ConfigError(f"no tool-frame mesh for this insert and cut: {exc}", file=source,
                          field="mesh.frame", value=m.frame.value,
                          expected="an engaged edge that contains the nose tip and a chip that "
                          "stays below the nose's centre in every slice (the tool frame's "
                          "domain, docs/fe3d.md: with the paper's insert, 0.4 mm nose, ap up "
                          "to 0.07 mm at f 0.15 mm/r and 0.06 mm at 0.2-0.3 mm/r); or set "
                          '[mesh] frame = "workpiece" (the workpiece-frame model: '
                          "radial and feed forces 22-38 % low at the paper's condition)") from exc
    s = cfg.solver
    spec = build_boring_spec(cfg, mat, vc * 60.0, source)
    p = boring_prm(cfg, spec, ins, vc, f)
    t_end = L / vc
    p[layout3d.P_SAMPLE_DT] = t_end / s.n_samples
    tip = (0.0, 0.0, 0.0)
    st = make_state3(mesh.nodes, mesh.conn, toolframe_fixed(mesh), mat, prm=p,
                     n_samples=s.n_samples, tool_tip=tip)
    attach_toolframe(st, mesh, tip)
    if spec.frame.thin_element_mass_scaling:
        dte = element_steps3(st)  # the mesh as built, once for both
        st.set_inertia_factors(thin_element_factors(st, mesh, dte))
        st.prm[layout3d.P_MSF_DT] = tip_section_step(st, mesh, dte)
    check_support_step(cfg, st, source)
    return BoringSetup(cfg=cfg, material=mat, insert=ins, mesh=mesh, state=st, ap=ap, f=f,
                       vc=vc, t_end=t_end, t_contact=0.0, spec=spec, x_cut_start=tip[0])


def toolframe_mesh_summary(mesh: ToolFrameMesh3D) -> ToolFrameMeshSummary:
    """The mesh facts of a tool-frame run: nodes, hexahedra, slices (engaged, margin), the
    clamp ``t_min``, the shortest element edge and the chip areas of
    :attr:`ToolFrameMesh3D.areas` [mm^2] (a run adds ``mass_ratio``: the mass in the mesh
    at the end over that at the start)."""
    a = mesh.areas
    return ToolFrameMeshSummary(
        nodes=mesh.n_nodes,
        hexahedra=mesh.n_elements,
        slices=int(mesh.z_slices.size),
        engaged_slices=int(np.sum(mesh.engaged)),
        t_min_um=mesh.sizes.t_min * 1e6,
        min_element_edge_um=mesh.min_edge * 1e6,
        chip_area_mm2=a.get("chip", math.nan) * 1e6,
        mesh_chip_area_mm2=a.get("mesh_above_edge", math.nan) * 1e6,
        clamp_area_mm2=a.get("clamp", math.nan) * 1e6,
        clamp_area_fraction=a.get("clamp_mesh", math.nan) / a["chip"] if "chip" in a
        else math.nan,
    )
