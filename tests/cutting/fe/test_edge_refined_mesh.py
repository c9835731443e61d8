"""Edge-refined node-splitting mesh (``mesh.edge_element_um``).

Checks the geometry of the conforming 2:1 transition rows without running a cut:
(1) the elements tile the workpiece rectangle exactly (areas sum to length x height, all
positive); (2) the mesh is conforming: every element edge is shared by two elements except
on the outline and on the doubled parting line (a hanging node would leave unmatched
edges inside); (3) the band round the parting line has the requested element size and
extent; (4) the parting line is doubled as in the uniform node-splitting mesh; (5) the
config checks; and a short cut on the refined mesh keeps its energy balance (5 %, the
issue's limit) and parts the material at the edge.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from conftest import edge_band_dict

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.mesh.orthogonal import build_edge_refined_mesh
from robobore.cutting.fe.models.orthogonal import setup_orthogonal, simulate_orthogonal
from robobore.errors import ConfigError

H, LE, SH = 30e-6, 10e-6, 5e-6


def _areas(m):
    p = m.nodes[m.conn]
    return 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, 1)
                        - np.roll(p[:, :, 0], -1, 1) * p[:, :, 1], axis=1)


@pytest.mark.parametrize("levels", [1, 2, 3])
def test_refined_mesh_tiles_and_conforms(levels):
    m = build_edge_refined_mesh(H, LE, 0.1e-3, split_height=SH, levels=levels,
                                band_above=8e-6, band_below=12e-6)
    a = _areas(m)
    assert a.min() > 0.0
    assert a.sum() == pytest.approx(m.length * m.height, rel=1e-12)
    # conformity: count edges on the unsplit mesh (map the upper copies back)
    base = np.where(m.twin >= 0, np.minimum(np.arange(m.n_nodes), m.twin), np.arange(m.n_nodes))
    conn = base[m.conn]
    edges = Counter()
    for q in conn:
        for k in range(4):
            i, j = q[k], q[(k + 1) % 4]
            edges[(min(i, j), max(i, j))] += 1
    assert max(edges.values()) == 2
    x, y = m.nodes[:, 0], m.nodes[:, 1]
    tol = 1e-9 * LE
    for (i, j), n in edges.items():
        if n == 1:  # a boundary edge must lie on the outline
            on = ((abs(x[i]) < tol and abs(x[j]) < tol)
                  or (abs(x[i] - m.length) < tol and abs(x[j] - m.length) < tol)
                  or (abs(y[i]) < tol and abs(y[j]) < tol)
                  or (abs(y[i] + m.height) < tol and abs(y[j] + m.height) < tol))
            assert on, (x[i], y[i], x[j], y[j])


def test_band_size_and_parting_line():
    levels, above, below = 2, 8e-6, 12e-6
    m = build_edge_refined_mesh(H, LE, 0.1e-3, split_height=SH, levels=levels,
                                band_above=above, band_below=below)
    af = LE / 2 ** levels
    y_p = -H + SH
    p = m.nodes[m.conn]
    cy = p[:, :, 1].mean(axis=1)
    w = p[:, :, 0].max(axis=1) - p[:, :, 0].min(axis=1)
    ht = p[:, :, 1].max(axis=1) - p[:, :, 1].min(axis=1)
    band = (cy > y_p - below) & (cy < y_p + above)
    over_cut = p[:, :, 0].min(axis=1) > 0.3e-3 - 3 * H  # uniform columns
    assert np.allclose(w[band & over_cut], af, rtol=1e-9)
    assert np.allclose(ht[band], af, rtol=1e-9)
    # nowhere else is finer, and the chip above keeps coarse elements at the top
    assert ht.min() == pytest.approx(af, rel=1e-9)
    assert w[(cy > -LE) & over_cut].max() == pytest.approx(LE, rel=1e-9)
    # the parting line: doubled finest nodes, chip elements on the upper copies only
    pairs = np.where(m.twin >= 0)[0]
    assert np.all(m.twin[m.twin[pairs]] == pairs)
    np.testing.assert_array_equal(m.nodes[pairs], m.nodes[m.twin[pairs]])
    assert np.allclose(m.nodes[pairs, 1], y_p)
    assert np.count_nonzero(m.upper) == np.count_nonzero(
        (np.abs(m.nodes[:, 1] - y_p) < 1e-9 * LE) & (m.nodes[:, 0] > 0)) // 2
    up = np.where(m.upper)[0]
    lo = pairs[~m.upper[pairs]]
    assert not np.isin(m.conn[~m.chip], up).any()
    assert not np.isin(m.conn[m.chip], lo).any()
    assert np.all(cy[m.chip] > y_p) and np.all(cy[~m.chip] < y_p)


def test_chip_too_thin_for_the_refinement():
    with pytest.raises(ValueError, match="too thin"):
        build_edge_refined_mesh(20e-6, 10e-6, 0.1e-3, split_height=5e-6, levels=3,
                                band_above=5e-6, band_below=5e-6)


def _cfg(**mesh):
    return parse_config(edge_band_dict(mesh=mesh), "t.toml")


@pytest.mark.parametrize("mesh, field", [
    ({"edge_element_um": 3.0}, "mesh.edge_element_um"),
    ({"separation": "erosion_layer"}, "mesh.edge_element_um"),
])
def test_bad_refinement_configs(mesh, field):
    with pytest.raises(ConfigError) as ei:
        _cfg(**mesh)
    assert ei.value.field == field


def test_band_extent_must_be_positive():
    with pytest.raises(ConfigError):
        _cfg(edge_band_um=[5.0, 0.0])


def test_short_cut_on_refined_mesh():
    res = simulate_orthogonal(_cfg())
    s = res.summary
    assert s.energy_error < 0.05
    assert np.isfinite(s.cutting_force_N_per_mm) and s.cutting_force_N_per_mm > 0
    # the tool parted the material at the edge: copies of released pairs moved apart
    twin = setup_orthogonal(_cfg()).mesh.twin
    f = res.final
    pairs = np.where(twin >= 0)[0]
    gap = np.hypot(f["x"][pairs] - f["x"][twin[pairs]], f["y"][pairs] - f["y"][twin[pairs]])
    assert np.count_nonzero(gap > 0.1 * 5e-6) >= 4


def test_chip_too_thin_is_a_config_error():
    d = edge_band_dict(cut={"uncut_chip_thickness_um": 15.0},
                       mesh={"element_size_um": 5.0, "edge_element_um": 2.5,
                             "separation_height_um": 9.0})
    with pytest.raises(ConfigError) as ei:
        setup_orthogonal(parse_config(d, "t.toml"), "t.toml")
    assert ei.value.field == "mesh.edge_element_um"
    assert "too thin" in str(ei.value)


def test_chip_ratio_uses_the_parting_line_as_the_underside():
    """Chip thickness from a known deformed shape: the chip material that has passed a tool
    at x = cx is stretched by s = 2.5 normal to the parting line (y_p), so the chip is
    (0 - y_p) s thick and the ratio is that over h (exact up to round-off; tolerance
    1e-9). The same with runs of underside band elements eroded (their parting-line nodes
    dead): the parting line is a material line, so the thickness is still measured from
    it, not from the lowest surviving node of each column (which lies inside the chip)."""
    from types import SimpleNamespace

    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.models.output import measure_chip

    h, sep, s = 60e-6, 5e-6, 2.5
    m = build_edge_refined_mesh(h, LE, 0.3e-3, split_height=sep, levels=2,
                                band_above=10e-6, band_below=10e-6, ahead=0.1e-3)
    y_p = m.layer_top
    x0, y0 = m.nodes[:, 0].copy(), m.nodes[:, 1].copy()
    cx, rake = 0.25e-3, np.radians(15.0)
    chip_nodes = (x0 > cx) & (y0 > y_p - 1e-12)
    chip_nodes &= ~((m.twin >= 0) & ~m.upper)  # the work's copies stay put
    y = y0.copy()
    y[chip_nodes] = y_p + (y0[chip_nodes] - y_p) * s
    tool = np.zeros(layout.N_TOOL)
    tool[layout.T_GX], tool[layout.T_GY] = cx, -h + 20e-6
    st = SimpleNamespace(x=x0.copy(), y=y, x0=x0, y0=y0, tool=tool,
                         ndead=np.zeros(x0.size, bool))
    want = (0.0 - y_p) * s / h
    assert measure_chip(st, m, h, rake, 0.5).ratio == pytest.approx(want, rel=1e-9)
    # erode the chip elements on the parting line in pairs of neighbouring elements: the
    # parting-line node between each pair loses all its elements
    cen = m.nodes[m.conn].mean(axis=1)
    on_line = np.isclose(y0[m.conn].min(axis=1), y_p) & m.chip & (cen[:, 0] > cx)
    idx = np.where(on_line)[0]
    idx = idx[np.argsort(cen[idx, 0])]
    gone = idx[(np.arange(idx.size) // 2) % 3 == 0]
    alive = np.ones(m.conn.shape[0], bool)
    alive[gone] = False
    live_nodes = np.zeros(x0.size, bool)
    live_nodes[m.conn[alive].ravel()] = True
    st.ndead = ~live_nodes
    assert st.ndead[(m.twin >= 0) & m.upper].sum() > 5
    assert measure_chip(st, m, h, rake, 0.5).ratio == pytest.approx(want, rel=1e-9)


def test_chip_ratio_from_the_chip_speed():
    """Continuity h vc = t_c v_chip (Merchant 1945): chip nodes sliding along the rake face
    at v_chip relative to the tool give r = vc / v_chip (exact, 1e-12); chip nodes outside
    the sampling window, nodes of the workpiece and dead nodes do not count; a speed that
    varies across the chip is averaged with the nodal masses."""
    from types import SimpleNamespace

    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.models.output import chip_ratio_from_velocity

    h, vc, r_true = 60e-6, 0.5, 1.37
    m = build_edge_refined_mesh(h, LE, 0.3e-3, split_height=SH, levels=2,
                                band_above=10e-6, band_below=10e-6, ahead=0.1e-3)
    rake = np.radians(15.0)
    cx, cy = 0.25e-3, -h + 20e-6
    tr = np.array([np.sin(rake), np.cos(rake)])
    nr = np.array([-np.cos(rake), np.sin(rake)])
    x0, y0 = m.nodes[:, 0].copy(), m.nodes[:, 1].copy()
    x, y = x0.copy(), y0.copy()
    vx = np.full(x0.size, 7.0)  # anything outside the window: must not count
    vy = np.full(x0.size, -3.0)
    chip = (x0 > cx) & (y0 > m.layer_top - 1e-12) & ~((m.twin >= 0) & ~m.upper)
    idx = np.where(chip)[0]
    rng = np.random.default_rng(3)
    inside = idx[: idx.size // 2]
    s_al = rng.uniform(1.05 * h, 2.95 * h, inside.size)
    q = rng.uniform(0.0, 2.0 * h, inside.size)
    x[inside] = cx + s_al * tr[0] + q * nr[0]
    y[inside] = cy + s_al * tr[1] + q * nr[1]
    tool = np.zeros(layout.N_TOOL)
    tool[layout.T_GX], tool[layout.T_GY] = cx, cy
    vchip = vc / r_true
    vx[inside] = -vc + vchip * tr[0]
    vy[inside] = vchip * tr[1]
    ndead = np.zeros(x0.size, bool)
    ndead[inside[:5]] = True
    vx[inside[:5]] = 100.0
    mass = rng.uniform(0.5, 2.0, x0.size)
    st = SimpleNamespace(x=x, y=y, x0=x0, y0=y0, vx=vx, vy=vy, tool=tool, ndead=ndead,
                         mass=mass)
    r, n = chip_ratio_from_velocity(st, m, h, rake, vc)
    assert n == inside.size - 5
    assert r == pytest.approx(r_true, rel=1e-12)
    # a workpiece node moved into the window is not chip material
    work = np.where(~chip & (x0 > cx))[0][:40]
    x[work] = cx + 2 * h * tr[0]
    y[work] = cy + 2 * h * tr[1]
    assert chip_ratio_from_velocity(st, m, h, rake, vc) == (r, n)
    # a sheared chip (speed rising across the thickness) gives the mass-weighted mean speed
    win = inside[5:]
    w = rng.uniform(0.6, 1.4, win.size)
    vx[win] = -vc + vchip * w * tr[0]
    vy[win] = vchip * w * tr[1]
    want = vc / (vchip * np.average(w, weights=mass[win]))
    assert chip_ratio_from_velocity(st, m, h, rake, vc)[0] == pytest.approx(want, rel=1e-12)
