"""Tool-frame ALE model (mesh.frame = "tool"): mesh, the open-boundary remap, a short cut,
config errors.

References: the ALE formulation of steady orthogonal cutting (Movahhedy, Gadala, Altintas
2000, J. Mater. Process. Technol. 103; Arrazola, Oezel 2010, Int. J. Mech. Sci. 52): an
Eulerian inflow and outflow, Lagrangian free surfaces, donor-cell transport (Benson 1992,
CMAME 99, sec. 4.2). Tolerances are stated per test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.ale.remap import BF_OPEN, BF_VIRGIN, swept_py
from robobore.cutting.fe.ale.rezone import TF_CHAIN, TF_INTERIOR, TF_LINE, TF_RIGID, rezone
from robobore.cutting.fe.ale.toolframe import build_toolframe_mesh
from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.groups2d import groups_of
from robobore.cutting.fe.models.orthogonal import setup_orthogonal, simulate_orthogonal
from robobore.cutting.fe.physics.tool_contact import tool_gap_py
from robobore.errors import ConfigError

RAKE, CLR, R = math.radians(15.0), math.radians(2.0), 20e-6


def _mesh(h=60e-6, le=10e-6, ee=2.5e-6):
    return build_toolframe_mesh(h, R, RAKE, CLR, element_size=le, edge_size=ee)


def _areas(x, y, c):
    return 0.5 * ((x[c[:, 2]] - x[c[:, 0]]) * (y[c[:, 3]] - y[c[:, 1]])
                  + (x[c[:, 1]] - x[c[:, 3]]) * (y[c[:, 2]] - y[c[:, 0]]))


@pytest.mark.parametrize("h", [40e-6, 60e-6, 80e-6])
def test_mesh_wraps_the_tool(h):
    m = _mesh(h)
    x, y = m.nodes[:, 0], m.nodes[:, 1]
    assert np.all(_areas(x, y, m.conn) > 0.0)  # counter-clockwise, not inverted
    cx, cy = m.tool_center
    nrx, nry = -math.cos(RAKE), math.sin(RAKE)
    nfx, nfy = math.sin(CLR), -math.cos(CLR)
    gaps = np.array([tool_gap_py(px, py, cx, cy, nrx, nry, nfx, nfy, R)[0]
                     for px, py in m.nodes])
    # no node inside the tool (1 nm); the surface chain under the arc and on the rake lies
    # on the tool surface (1 nm)
    assert gaps.min() > -1e-9
    on_tool = m.chip_under_nodes
    assert np.all(np.abs(gaps[on_tool]) < 1e-9)
    # the free surface ahead of the chip is y = 0, the machined surface behind the edge the
    # cut line y = -h, the bottom and the inflow face are rigid
    assert np.all(m.fixed == (m.acls[:, 0] == TF_RIGID))
    assert abs(y[m.chip_top_nodes[0]]) < 1e-15
    assert np.allclose(y[m.machined_nodes[-3:]], -h, atol=1e-15)
    # interior nodes have exactly four edge neighbours; every class is present
    inner = m.acls[:, 0] == TF_INTERIOR
    assert np.all(m.acls[inner, 3:7] >= 0)
    assert {TF_RIGID, TF_CHAIN, TF_LINE} <= set(m.acls[:, 0].tolist())
    # flux flags only on the inflow (virgin) and outflow (open) faces
    assert (m.bflag == BF_VIRGIN).sum() > 0 and (m.bflag == BF_OPEN).sum() > 0


def _tool_frame_state(h=60e-6):
    cfg = parse_config({"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
                        "cut": {"uncut_chip_thickness_um": h * 1e6,
                                "cutting_speed_m_per_min": 30, "length_mm": 0.01},
                        "mesh": {"element_size_um": 10, "frame": "tool",
                                 "edge_element_um": 5},
                        "solver": {"mass_scaling": 100}})
    return setup_orthogonal(cfg)


def _pass(st, off):
    rho_s = st.mat[15] * st.prm[layout.P_MS]
    tg = (st.prm[layout.P_ALE_X0] + off, st.prm[layout.P_TCY], st.prm[layout.P_NRX],
          st.prm[layout.P_NRY], st.prm[layout.P_NFX], st.prm[layout.P_NFY], st.prm[layout.P_R])
    nodes, quads, state, _, _, ale = groups_of(st)
    return rezone(nodes, quads, state, ale, rho_s, 0.2, tg, 293.0, off)


def test_remap_open_boundaries_balance_mass():
    """A tool travel ``off`` with the material at rest carries the mesh by ``off`` in x: the
    mass change is exactly what the inflow face sweeps in (virgin material) plus what the
    outflow faces sweep (negative: out; 1e-9 relative), and a uniform field stays uniform
    except where virgin material came in (1e-12)."""
    su = _tool_frame_state()
    st = su.state
    st.temp[:] = 293.0
    st.eps_p[:] = 0.4
    m0 = st.area0.sum()
    x_old, y_old = st.x.copy(), st.y.copy()
    off = -0.02e-6  # the tool moved 20 nm in -x
    _pass(st, off)
    rigid = st.fixed
    assert np.allclose(st.x[rigid] - x_old[rigid], off, atol=1e-15)
    # nodes on the horizontal surfaces (free surface ahead, machined surface behind) slide
    # along them by the tool's travel (a surface node moves only along its surface)
    flat = np.concatenate((su.mesh.machined_nodes[-5:-1], su.mesh.chip_top_nodes[1:4]))
    assert np.allclose(st.x[flat] - x_old[flat], off, atol=1e-15)
    swept_in = swept_out = 0.0
    for e in range(st.conn.shape[0]):
        for k in range(4):
            if st.enbr[e, k] >= 0 or st.bflag[e, k] == 0:
                continue
            a, b = st.conn[e, k], st.conn[e, (k + 1) % 4]
            sw = swept_py(x_old[a], y_old[a], x_old[b], y_old[b], st.x[a], st.y[a], st.x[b],
                          st.y[b])
            if st.bflag[e, k] == BF_VIRGIN and sw > 0:
                swept_in += sw
            else:
                swept_out += sw
    assert swept_in > 0 and swept_out < 0
    # inflow: the whole inflow face height (h + depth below the cut line) times the travel
    height = -st.y0[st.fixed].min()
    assert swept_in == pytest.approx(-off * height, rel=1e-9)
    assert st.area0.sum() - m0 == pytest.approx(swept_in + swept_out, rel=1e-9, abs=1e-22)
    assert np.allclose(st.temp, 293.0, atol=1e-9)
    # virgin material dilutes the plastic strain of the inflow elements only
    first = np.where(np.any(st.bflag == BF_VIRGIN, axis=1))[0]
    rest = np.setdiff1d(np.arange(st.conn.shape[0]), first)
    assert np.all(st.eps_p[first] < 0.4) and np.allclose(st.eps_p[rest], 0.4, atol=1e-12)


def test_short_tool_frame_cut():
    """20 um of tool travel (one element) from the pre-shaped chip: forces build up, nothing
    erodes, the mesh stays round the tool, the energy balance holds (5 %, the issue's limit)."""
    cfg = parse_config({"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
                        "cut": {"uncut_chip_thickness_um": 60,
                                "cutting_speed_m_per_min": 30, "length_mm": 0.02},
                        "mesh": {"element_size_um": 20, "frame": "tool",
                                 "edge_element_um": 5},
                        "solver": {"mass_scaling": 100, "n_samples": 20}})
    res = simulate_orthogonal(cfg)
    s = res.summary
    assert s.cutting_force_N_per_mm > 20.0 and s.feed_force_N_per_mm > 5.0
    assert s.eroded_damage == 0 and s.eroded_distortion == 0
    assert s.energy_error < 0.05
    assert s.averaging_window_mm[1] == pytest.approx(0.02, rel=0.05)
    f = res.final
    # the mesh travelled with the tool: the inflow face is 20 um further in -x
    assert np.isfinite(s.chip_ratio) and np.isfinite(s.chip_ratio_velocity)
    assert f["tool_center"][0] == pytest.approx(-20e-6, rel=1e-3)


@pytest.mark.parametrize("patch, field", [
    ({"tool": {"edge_radius_um": 0.0}}, "tool.edge_radius_um"),
    ({"mesh": {"edge_element_um": 20.0}}, "mesh.edge_element_um"),
    ({"mesh": {"join_height_um": 30.0}}, "mesh.join_height_um"),
    ({"mesh": {"chip_length_um": 100.0}}, "mesh.chip_length_um"),
    ({"mesh": {"depth_um": 50.0}}, "mesh.depth_um"),
    ({"mesh": {"inflow_length_um": 50.0}}, "mesh.inflow_length_um"),
    ({"mesh": {"back_length_um": 30.0}}, "mesh.back_length_um"),
    ({"solver": {"element": "q4_bbar"}}, "solver.element"),
])
def test_tool_frame_config_errors(patch, field):
    d = {"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
         "cut": {"uncut_chip_thickness_um": 60, "cutting_speed_m_per_min": 30,
                 "length_mm": 0.01},
         "mesh": {"element_size_um": 10, "frame": "tool"}, "solver": {}}
    for sec, kv in patch.items():
        d[sec].update(kv)
    with pytest.raises(ConfigError) as ei:
        parse_config(d, "cfg.toml")
    assert field in str(ei.value) and "cfg.toml" in str(ei.value)


def test_tool_frame_on_gpu_needs_a_gpu():
    """The tool-frame model runs on the GPU (the simulator test in
    test_fe2d_gpu.py); without a usable GPU --device gpu stops with the clear error."""
    from robobore.cutting.fe.engine.gpu.shared import cuda_available
    from robobore.cutting.fe.models.orthogonal import check_device

    cfg = parse_config({"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
                        "cut": {"uncut_chip_thickness_um": 60, "cutting_speed_m_per_min": 30,
                                "length_mm": 0.01},
                        "mesh": {"element_size_um": 10, "frame": "tool"}})
    if cuda_available():
        check_device("gpu", cfg)  # accepted
        return
    with pytest.raises(ConfigError, match="no usable NVIDIA GPU"):
        check_device("gpu", cfg)


def test_example_config_builds():
    """examples/fe_orthogonal_toolframe.toml: the tool-frame defaults land in the engine."""
    from pathlib import Path

    from robobore.cutting.fe.config.orthogonal import load_fe_config

    cfg = load_fe_config(Path(__file__).parents[3] / "examples" / "fe_orthogonal_toolframe.toml")
    su = setup_orthogonal(cfg)
    p = su.state.prm
    assert int(p[layout.P_RZ_EVERY]) == 10 and p[layout.P_RZ_MAXMOVE] == 0.2
    assert p[layout.P_CDAMP] == 1.0 and int(p[layout.P_EROSION]) == layout.ERODE_NONE
    assert su.t_contact == 0.0 and su.t_end == pytest.approx(0.3e-3 / 0.5)
    assert su.state.snodes.size == int((su.mesh.acls[:, 0] != TF_RIGID).sum())
    # a longer chip (mesh.chip_length_um) adds elements up the rake
    cfg2 = load_fe_config(Path(__file__).parents[3] / "examples" / "fe_orthogonal_toolframe.toml")
    cfg2.mesh.chip_length_um = 288.0
    n2 = setup_orthogonal(cfg2).state.conn.shape[0]
    assert n2 > su.state.conn.shape[0]


def test_domain_keys_move_the_tool_frame_boundaries():
    """mesh.depth_um / inflow_length_um / back_length_um place the fixed bottom, the inflow face
    and the back face where they say (coordinates of the workpiece frame: cut line y = -h,
    edge centre at x = 0 before the tool moves)."""
    from pathlib import Path

    from robobore.cutting.fe.config.orthogonal import load_fe_config

    path = Path(__file__).parents[3] / "examples" / "fe_orthogonal_toolframe.toml"
    base = setup_orthogonal(load_fe_config(path))
    h = load_fe_config(path).cut.uncut_chip_thickness_um * 1e-6
    cfg = load_fe_config(path)
    cfg.mesh.depth_um = 400.0
    cfg.mesh.back_length_um = 250.0
    cfg.mesh.inflow_length_um = 200.0
    su = setup_orthogonal(cfg)
    x, y = su.mesh.nodes[:, 0], su.mesh.nodes[:, 1]
    x0 = base.mesh.nodes[:, 0]
    assert y.min() == pytest.approx(-h - 400e-6, rel=1e-12)
    assert x.max() == pytest.approx(250e-6, rel=1e-12)
    # the inflow face moves out by the difference of the two lengths (default max(1.5 h, 60))
    assert x0.min() - x.min() == pytest.approx(200e-6 - max(1.5 * h, 60e-6), rel=1e-9)
    # the fixed nodes are the bottom and the inflow face, wherever they are
    fixed = su.mesh.fixed
    assert np.all(fixed[np.isclose(y, y.min(), rtol=0, atol=1e-12)])
    assert np.all(fixed[np.isclose(x, x.min(), rtol=0, atol=1e-12)])
    assert su.state.conn.shape[0] > base.state.conn.shape[0]
