"""The 3D boring model on the tool-frame mesh (``[mesh] frame = "tool"``): config keys and
their refusals, the state it builds (boundary conditions, ALE arrays, parameter slots) and a
short run of the tool-frame loop (the mesh stays on its places in the insert's frame, nothing
erodes, the energy balances)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from robobore.cutting.fe.ale.remap3d import VEL_TAYLOR
from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.config.spec import ToolFrame
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine.chunk_driver import energy_error
from robobore.cutting.fe.engine.state3d import advance3
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.mesh.toolframe3d import FK_SIDE
from robobore.cutting.fe.models.boring3d import setup_boring, simulate_boring
from robobore.errors import ConfigError
from robobore.io.config import load_toml

EX = Path(__file__).parents[3] / "examples"


def _cfg(**mesh) -> dict:
    d = load_toml(EX / "fe_boring_paper.toml")
    d["mesh"].update({"frame": "tool", "element_size_um": 16.6, **mesh})
    return d


def _workpiece() -> dict:
    """The paper example on the workpiece frame."""
    d = load_toml(EX / "fe_boring_paper.toml")
    d["mesh"]["frame"] = "workpiece"
    return d


@pytest.mark.parametrize("section, key, value", [
    ("mesh", "separation", "node_split"), ("mesh", "separation_height_um", 5.0),
    ("mesh", "chip_rows", 4), ("mesh", "depth_factor", 2.0), ("mesh", "ahead_mm", 0.1),
    ("mesh", "side_margin_um", 10.0), ("solver", "erosion", "none"),
    ("solver", "separation_gate_um", 1.0), ("solver", "erode_time_step_fraction", 0.2)])
def test_tool_frame_refuses_workpiece_keys(section, key, value):
    d = _cfg()
    d.setdefault(section, {})[key] = value
    with pytest.raises(ConfigError, match=f"{section}.{key}"):
        parse_boring_config(d)


@pytest.mark.parametrize("section, key, value", [
    ("mesh", "t_min_um", 8.0), ("mesh", "margin_slices", 2), ("mesh", "initial_chip_ratio", 1.8),
    ("mesh", "edge_element_um", 4.0), ("mesh", "slice_spacing_um", 10.0),
    ("solver", "ale_interval", 5)])
def test_workpiece_frame_refuses_tool_frame_keys(section, key, value):
    d = _workpiece()
    d.setdefault(section, {})[key] = value
    with pytest.raises(ConfigError, match=f"{section}.{key}"):
        parse_boring_config(d)


def test_tool_frame_range_checks():
    with pytest.raises(ConfigError, match="mesh.t_min_um"):
        parse_boring_config(_cfg(t_min_um=60.0))
    with pytest.raises(ConfigError, match="mesh.edge_element_um"):
        parse_boring_config(_cfg(edge_element_um=20.0))
    d = _cfg()
    d["insert"]["edge_radius_um"] = 0.0
    with pytest.raises(ConfigError, match="insert.edge_radius_um"):
        parse_boring_config(d)


def test_a_cut_outside_the_tool_frame_mesh_names_the_way_out():
    """The default frame's mesh needs the chip below the nose's centre in every slice: a deep
    cut is a ConfigError at setup naming mesh.frame and the workpiece frame, not a fallback."""
    d = load_toml(EX / "fe_boring_paper.toml")
    del d["mesh"]["frame"]
    d["mesh"]["element_size_um"] = 16.6
    d["cut"]["depth_of_cut_mm"] = 0.1
    with pytest.raises(ConfigError) as ei:
        setup_boring(parse_boring_config(d, "deep.toml"), "deep.toml")
    msg = str(ei.value)
    assert ei.value.field == "mesh.frame" and "deep.toml" in msg
    assert "reaches past the nose" in msg and 'frame = "workpiece"' in msg
    d["mesh"]["frame"] = "workpiece"
    assert not setup_boring(parse_boring_config(d)).spec.frame.tool_frame


def test_tool_frame_is_cpu_only():
    cfg = parse_boring_config(_cfg())
    with pytest.raises(ConfigError, match="CPU only"):
        simulate_boring(cfg, device="gpu")


def test_tool_frame_state():
    cfg = parse_boring_config(_cfg(t_min_um=8.0))
    s = setup_boring(cfg)
    st, m = s.state, s.mesh
    n, ne = st.x.shape[0], st.n_elements
    assert st.tool_frame and s.t_contact == 0.0
    assert (n, ne) == (m.n_nodes, m.n_elements)
    np.testing.assert_array_equal(st.x0, m.nodes[:, 0])
    assert st.acls.shape == (n, 7) and st.aflt.shape == (n, 6) and st.bflag.shape == (ne, 6)
    assert st.buf.shape[0] == ne and st.vbuf.shape == (n, 3) and st.scratch.shape == (n, 3)
    # rigid nodes held in every component, the side planes' nodes in z, nothing else
    assert np.all(st.fixed[m.rigid] == 7)
    side = np.zeros(n, bool)
    side[m.node_slice == 0] = True
    side[m.node_slice == m.z_slices.size - 1] = True
    assert np.all(st.fixed[side] & scalar3d.FIX_Z)
    assert np.all(st.fixed[~side & ~m.rigid] == 0)
    assert np.any(m.fkind == FK_SIDE)
    p = st.prm
    assert p[layout3d.P_RZ_EVERY] == 10 and p[layout3d.P_RZ_MAXMOVE] == ToolFrame.MAX_MOVE
    assert p[layout3d.P_RZ_VEL] == VEL_TAYLOR
    assert p[layout3d.P_EROSION] == layout3d.ERODE_NONE and p[layout3d.P_DT_ERODE] == 0.0
    assert p[layout3d.P_ALE_X0] == 0.0 and p[layout3d.P_ALE_Z0] == 0.0 and p[layout3d.P_VC] > 0.0


def test_workpiece_state_has_empty_ale_arrays():
    d = _workpiece()
    d["mesh"]["element_size_um"] = 16.6
    d["cut"]["cut_length_mm"] = 0.02
    st = setup_boring(parse_boring_config(d)).state
    assert not st.tool_frame
    assert st.x0.shape == (0,) and st.acls.shape == (0, 7) and st.bflag.shape == (0, 6)
    assert st.prm[layout3d.P_RZ_EVERY] == 0


def test_tool_frame_short_run():
    # 200 steps (20 ALE passes): the mesh travels with the insert, nothing erodes, the
    # insert pushes the material (tangential force on the tool > 0), energy balanced
    cfg = parse_boring_config(_cfg(t_min_um=8.0))
    cfg.solver.mass_scaling = 400.0
    s = setup_boring(cfg)
    st = s.state
    dt = float(st.clock[1])
    steps = advance3(st, 200.5 * dt, chunk_steps=50, adaptive_threads=False)
    assert 150 <= steps <= 260
    travel = st.tool[scalar3d.T_GX]
    assert travel == pytest.approx(st.time * s.vc, rel=1e-9)
    # last pass at a multiple of ale_interval: every node within a few steps' travel of
    # its place (rigid nodes on it)
    lag = st.x - st.x0 - travel
    assert np.max(np.abs(lag[s.mesh.rigid])) < 11 * dt * s.vc
    assert np.all(st.alive == 1)
    assert np.all(np.isfinite(st.sd))
    assert -st.tool[scalar3d.T_FX] > 0.0
    assert energy_error(st.en) < 0.05


def test_tool_frame_summary_has_the_mesh_facts():
    cfg = parse_boring_config(_cfg(t_min_um=8.0))
    cfg.solver.mass_scaling = 400.0
    s = setup_boring(cfg)
    cfg.cut.cut_length_mm = 150 * float(s.state.clock[1]) * s.vc * 1e3
    r = simulate_boring(cfg).summary
    tf = r.toolframe_mesh
    assert r.frame == "tool" and r.separation is None and r.mesh_shape is None
    assert (tf.nodes, tf.hexahedra) == (s.mesh.n_nodes, s.mesh.n_elements)
    assert tf.t_min_um == pytest.approx(8.0)
    assert tf.chip_area_mm2 == pytest.approx(r.chip_area_mm2, rel=1e-12)
    assert 0.0 < tf.clamp_area_fraction < 0.1
    # a few passes of a short travel: the inflow and outflow change the mass by far less
    # than a percent
    assert tf.mass_ratio == pytest.approx(1.0, abs=1e-2)
    assert r.eroded_damage == 0 and r.eroded_distortion == 0
    # the pre-shaped chip stands above the pre-bore surface (y = ap)
    assert r.chip_max_height_um > 10.0


def test_a_radial_deflection_the_mesh_does_not_follow_is_reported():
    """On a support the insert deflects along the wall normal, which the tool-frame mesh's
    placement does not follow: the run reports the largest deflection (from the tool's
    boring-frame history and the bar angle) beside the edge element, and warns above a
    tenth of it."""
    from robobore.cutting.fe.cli_boring import RADIAL_DEFLECTION_LIMIT, boring_warnings

    d = _cfg(t_min_um=8.0)
    d["tool_support"] = {"stiffness_N_per_m": 1.0e4, "damping_N_s_per_m": 0.0,
                         "mass_kg": 1.0e-7}
    cfg = parse_boring_config(d)
    s = setup_boring(cfg)
    cfg.cut.cut_length_mm = 150 * float(s.state.clock[1]) * s.vc * 1e3
    res = simulate_boring(cfg)
    r, h = res.summary, res.history
    th = h["bar_angle_rad"]
    uy = -np.cos(th) * h["tool_dX_um"] - np.sin(th) * h["tool_dY_um"]
    tf = r.toolframe_mesh
    assert tf.edge_element_um == pytest.approx(16.6 / 4)
    assert tf.radial_deflection_max_um == pytest.approx(np.max(np.abs(uy)), rel=1e-9)
    assert tf.radial_deflection_max_um > 0.0
    status = boring_warnings(cfg)
    for frac, warned in ((0.5, False), (2.0, True)):
        d = frac * RADIAL_DEFLECTION_LIMIT * tf.edge_element_um
        w = boring_warnings(cfg, replace(
            r, toolframe_mesh=replace(tf, radial_deflection_max_um=d)))
        assert w[0] == status[0] and len(w) == 1 + warned
        if warned:
            assert "radial deflection" in w[1] and "edge element" in w[1]


def test_the_tool_frame_loop_is_the_one_step_loop():
    import types

    from robobore.cutting.fe.engine import step_loop as SL

    code = next(c for c in SL.make_chunk_loop.__code__.co_consts
                if isinstance(c, types.CodeType) and c.co_name == "chunk_loop")
    assert K3._loop3_ale.py_func.__code__ is code
    assert K3._loop3_ale.__qualname__ != K3._loop3.__qualname__


def test_a_tool_frame_state_needs_its_interval():
    s = setup_boring(parse_boring_config(_cfg(t_min_um=8.0)))
    s.state.prm[layout3d.P_RZ_EVERY] = 0
    with pytest.raises(ConfigError, match="P_RZ_EVERY"):
        advance3(s.state, 1e-9)


def test_the_spec_chooses_the_loop():
    # conduction (the default): the loops with the heat pass
    s = setup_boring(parse_boring_config(_cfg(t_min_um=8.0)))
    assert K3.run_chunk3_for(s.spec) is K3.run_chunk3_ale_heat
    d = _workpiece()
    d["mesh"]["element_size_um"] = 16.6
    d["cut"]["cut_length_mm"] = 0.02
    w = setup_boring(parse_boring_config(d))
    assert K3.run_chunk3_for(w.spec) is K3.run_chunk3_heat
    # a loop that does not match the state's frame is refused
    with pytest.raises(ConfigError, match="frame"):
        advance3(w.state, 1e-9, step=K3.run_chunk3_ale_heat)
    with pytest.raises(ConfigError, match="frame"):
        advance3(s.state, 1e-9, step=K3.run_chunk3_heat)
    # adiabatic: the loops without it; a loop of the other thermal model is refused
    d["solver"]["heat_conduction"] = False
    a = setup_boring(parse_boring_config(d))
    assert K3.run_chunk3_for(a.spec) is K3.run_chunk3
    with pytest.raises(ConfigError, match="thermal model"):
        advance3(a.state, 1e-9, step=K3.run_chunk3_heat)
    with pytest.raises(ConfigError, match="thermal model"):
        advance3(w.state, 1e-9, step=K3.run_chunk3)
    dt = _cfg(t_min_um=8.0)
    dt["solver"]["heat_conduction"] = False
    assert K3.run_chunk3_for(setup_boring(parse_boring_config(dt)).spec) is K3.run_chunk3_ale
    # an interval below one step is neither adiabatic nor a heat pass
    w.state.prm[layout3d.P_COND_EVERY] = 0.5
    with pytest.raises(ConfigError, match="P_COND_EVERY"):
        advance3(w.state, 1e-9)


def test_cli_refuses_the_gpu_with_the_tool_frame(tmp_path):
    from typer.testing import CliRunner

    from robobore.cli import app
    from robobore.io.config import dump_toml

    cfg = tmp_path / "tf.toml"
    cfg.write_text(dump_toml(_cfg()))
    res = CliRunner().invoke(app, ["fe", "boring", str(cfg), "--device", "gpu"])
    assert res.exit_code == 2
    assert "CPU only" in res.output and "--device" in res.output
    # the default frame: the message names the way to the GPU
    d = _cfg()
    del d["mesh"]["frame"]
    cfg.write_text(dump_toml(d))
    res = CliRunner().invoke(app, ["fe", "boring", str(cfg), "--device", "gpu"])
    assert res.exit_code == 2
    assert "default mesh.frame" in res.output and 'frame = "workpiece"' in res.output


def test_contact_normal_damping_as_in_2d():
    """``contact.normal_damping``: default 1 (critical) in the tool frame, 0 in the workpiece
    frame (the 2D engine's defaults); a given value in either."""
    assert setup_boring(parse_boring_config(_cfg(t_min_um=8.0))).state.prm[layout3d.P_CDAMP] == 1.0
    d = _workpiece()
    d["mesh"]["element_size_um"] = 16.6
    d["cut"]["cut_length_mm"] = 0.02
    assert setup_boring(parse_boring_config(d)).state.prm[layout3d.P_CDAMP] == 0.0
    d["contact"] = {**d.get("contact", {}), "normal_damping": 0.4}
    assert setup_boring(parse_boring_config(d)).state.prm[layout3d.P_CDAMP] == 0.4
    t = _cfg(t_min_um=8.0)
    t["contact"] = {**t.get("contact", {}), "normal_damping": 0.0}
    assert setup_boring(parse_boring_config(t)).state.prm[layout3d.P_CDAMP] == 0.0
