"""Inertia factors of the 3D tool-frame mesh (``solver.thin_element_mass_scaling``): mass
scaling attached to the thin chip elements at the ends of the engaged edge so that the mesh
runs at the stable step of its nose-tip section; each ALE pass renews them from the elements'
current steps and the lumped masses carry them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.state3d import advance3, element_steps3
from robobore.cutting.fe.hex import layout3d
from robobore.cutting.fe.models.boring3d import setup_boring
from robobore.cutting.fe.models.toolframe3d import thin_element_factors, tip_section_step
from robobore.errors import ConfigError
from robobore.io.config import load_toml
from robobore.material.johnson_cook import RHO

EX = Path(__file__).parents[3] / "examples"


def _cfg(**solver) -> dict:
    d = load_toml(EX / "fe_boring_paper.toml")
    d["mesh"].update({"frame": "tool", "element_size_um": 16.6})
    d["solver"].update(solver)
    return d


def _lumped(st, msf):
    rho_s = st.mat[RHO] * st.prm[layout3d.P_MS]
    m = np.zeros_like(st.mass)
    np.add.at(m, st.conn.ravel(), np.repeat(st.vol0 * rho_s * msf / 8.0, 8))
    return m


@pytest.fixture(scope="module")
def setups():
    on = setup_boring(parse_boring_config(_cfg()))
    off = setup_boring(parse_boring_config(_cfg(thin_element_mass_scaling=False)))
    return on, off


def test_factors_only_on_elements_slower_than_the_tip_section(setups):
    on, off = setups
    st, mesh = on.state, on.mesh
    msf = st.msf
    dte = element_steps3(off.state)
    k0 = int(np.argmin(np.abs(mesh.z_slices)))
    tip = (mesh.elem_slice == k0) | (mesh.elem_slice == k0 - 1)
    dt_tip = dte[tip].min()
    assert np.all(msf >= 1.0)
    assert np.all(msf[tip] == 1.0)
    assert np.array_equal(msf > 1.0, dte < dt_tip)
    # with the factors every element's step is at least the tip section's smallest
    assert np.min(dte * np.sqrt(msf)) == pytest.approx(dt_tip, rel=1e-12)
    assert np.any(msf > 2.0)  # the thin ends do set the step without them
    assert np.array_equal(msf, thin_element_factors(off.state, mesh))
    # the initial step: the tip section's (the factors off: the thin ends')
    assert st.clock[1] == pytest.approx(st.prm[layout3d.P_CFL] * dt_tip, rel=1e-12)
    assert off.state.clock[1] < 0.5 * st.clock[1]
    assert off.state.msf.shape == (0,)
    # lumped masses carry the factors; the material's mass is the same
    assert np.allclose(st.mass, _lumped(st, msf), rtol=1e-13, atol=0)
    assert np.array_equal(st.vol0, off.state.vol0)


def test_masses_carry_the_renewed_factors_through_the_ale_pass(setups):
    on, off = setups
    st = on.state
    dt_tip = tip_section_step(off.state, on.mesh)
    assert st.prm[layout3d.P_MSF_DT] == dt_tip
    assert off.state.prm[layout3d.P_MSF_DT] == 0.0
    st.prm[layout3d.P_RZ_EVERY] = 5
    # a stale factor on the most thinned element: the next pass renews it from its step
    e = int(np.argmax(st.msf))
    st.msf[e] = 1.0
    advance3(st, t_end=40 * st.clock[1], chunk_steps=20, adaptive_threads=False)
    assert int(st.ist[layout.I_STEP]) >= 20
    assert st.msf[e] > 2.0
    assert np.allclose(st.mass, _lumped(st, st.msf), rtol=1e-12, atol=0)
    # every element at about the tip section's step (the running steps lie a few per cent
    # below the at-rest estimate the target is); the tip section's own elements take a
    # factor only where their running step dips below that estimate (1.13 at most here)
    assert np.min(st.dte * np.sqrt(st.msf)) > 0.9 * dt_tip
    k0 = int(np.argmin(np.abs(on.mesh.z_slices)))
    tip = (on.mesh.elem_slice == k0) | (on.mesh.elem_slice == k0 - 1)
    assert np.all(st.msf[tip] < 1.2) and np.mean(st.msf[tip] > 1.0) < 0.01


def test_renewal_follows_the_element_steps_both_ways():
    dte = np.array([1e-9, 4e-9, 2e-9, 0.5e-9, 1e30, 1e-9])
    alive = np.array([1, 1, 1, 1, 1, 0], np.int64)
    msf = np.array([1.0, 9.0, 1.0, 2.0, 3.0, 5.0])
    K3.renew_inertia_factors_py(msf, dte, alive, 2e-9)
    # slower than the target: factor (2/1)^2; faster: back to 1; the target itself: 1;
    # no step (no live geometry) or a dead element: unchanged
    assert msf.tolist() == [4.0, 1.0, 1.0, 16.0, 3.0, 5.0]


def test_workpiece_frame_refuses_the_key():
    d = load_toml(EX / "fe_boring_paper.toml")
    d["mesh"]["frame"] = "workpiece"
    d["solver"]["thin_element_mass_scaling"] = False
    with pytest.raises(ConfigError, match="solver.thin_element_mass_scaling"):
        parse_boring_config(d)
