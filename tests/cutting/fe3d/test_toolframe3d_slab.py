"""The 3D engine's tool-frame loop reproduces the 2D tool-frame engine on the same orthogonal
cut (plane-strain slab, :func:`robobore.cutting.fe.models.slab3d.simulate_slab3_toolframe`).

Reference: the 2D tool-frame ALE model (``robobore fe orthogonal``, ``mesh.frame = "tool"``,
the validated model's mesh and ALE pass); the 3D slab is its 2D mesh extruded over two
hexahedra across, z held on both faces, run by ``kernels3d.run_chunk3_ale`` (the 3D ALE pass
every ``solver.ale_interval`` steps) with a straight-edged insert. Short cut (h 40 um, 20 um
elements, 0.06 mm of travel, 80 m/min, rake 7, clearance 7, edge 20 um, adiabatic, the a-priori
friction table at the cutting speed) to stay cheap. Tolerances: those of the workpiece-frame
slab test (tests/cutting/fe3d/test_fe3d_planestrain.py), cutting force 10 %, feed force 25 %.
Both use the contact's default normal damping in the tool frame (critical, 1).
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.models.orthogonal import simulate_orthogonal
from robobore.cutting.fe.models.slab3d import setup_slab3_toolframe, simulate_slab3_toolframe
from robobore.errors import ConfigError

CFG = {"parameters": "a_priori", "material": {"name": "TC4"},
       "tool": {"rake_deg": 7.0, "clearance_deg": 7.0, "edge_radius_um": 20.0},
       "cut": {"uncut_chip_thickness_um": 40.0, "cutting_speed_m_per_min": 80.0,
               "length_mm": 0.06, "width_mm": 1.0},
       "contact": {"friction": "table"},
       "mesh": {"frame": "tool", "element_size_um": 13.0},
       "solver": {"mass_scaling": 100.0, "heat_conduction": False}}


def test_toolframe_slab_state():
    s = setup_slab3_toolframe(parse_config(CFG))
    st = s.state
    assert st.tool_frame
    n = st.x.shape[0]
    assert st.x0.shape == (n,) and st.acls.shape == (n, 7) and st.aflt.shape == (n, 6)
    assert st.bflag.shape == (st.n_elements, 6)
    # every node is held in z (both faces of a two-element slab carry all but the middle
    # plane's nodes); the middle plane's free nodes are not
    assert np.any(st.fixed == 0)
    assert np.all(st.alive == 1) and not st.layer.any()


def test_toolframe_slab_forces_match_2d_engine():
    cfg = parse_config(CFG)
    r2 = simulate_orthogonal(cfg).summary
    r3 = simulate_slab3_toolframe(cfg)
    assert r3.eroded == 0
    assert r3.energy_error < 0.05
    assert abs(r3.out_of_plane_force_N_per_mm) < 1e-3 * r3.cutting_force_N_per_mm
    assert r3.cutting_force_N_per_mm == pytest.approx(r2.cutting_force_N_per_mm, rel=0.10)
    assert r3.feed_force_N_per_mm == pytest.approx(r2.feed_force_N_per_mm, rel=0.25)


def test_toolframe_slab_needs_the_tool_frame():
    d = {**CFG, "mesh": {"frame": "workpiece", "element_size_um": 10.0},
         "contact": {"friction": "table"}}
    with pytest.raises(ConfigError, match="mesh.frame"):
        setup_slab3_toolframe(parse_config(d))
