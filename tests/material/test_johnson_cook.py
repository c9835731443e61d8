"""Johnson-Cook flow stress, damage and radial return against closed forms.

Reference: Johnson & Cook (1983, 1985); radial return: Simo & Hughes (1998) sec. 3.3 -- for
linear isotropic hardening the plastic multiplier is closed-form,
d(eps_p) = (q_trial - sigma_y0) / (3 G + H)   (their eq. 3.3.11 in von Mises form).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robobore.errors import ConfigError
from robobore.material import bundled_materials, load_material
from robobore.material import johnson_cook as jc

TC4 = load_material("TC4")


def _jc_hand(ep, rate, T, hold=math.inf):
    """Johnson-Cook by hand; the hardening term held beyond ``hold`` (default: the plain
    law)."""
    m = TC4
    ts = min(max((T - m.T_room) / (m.T_melt - m.T_room), 0.0), 1.0)
    r = 1.0 + m.C * math.log(rate / m.eps_dot0) if rate > m.eps_dot0 else 1.0
    return (m.A + m.B * min(ep, hold)**m.n) * r * (1.0 - ts**m.m)


def test_tc4_library_values():
    m = TC4
    assert m.A == pytest.approx(997.9e6) and m.B == pytest.approx(653.1e6)
    assert (m.n, m.C, m.m, m.eps_dot0) == (0.45, 0.0198, 0.7, 1.0)
    assert (m.T_room, m.T_melt) == (293.0, 1873.0)
    assert (m.D1, m.D2, m.D3, m.D4, m.D5) == (-0.09, 0.25, -0.5, 0.014, 3.87)
    assert m.E == pytest.approx(113.8e9) and m.nu == 0.34 and m.rho == 4430.0
    assert (m.cp, m.k, m.taylor_quinney) == (531.0, 6.3, 0.9)
    assert "TC4" in bundled_materials()


@pytest.mark.parametrize("ep,rate,T", [(0.0, 0.5, 293.0), (0.1, 1e3, 500.0), (1.0, 1e5, 900.0),
                                       (2.5, 1e6, 1500.0), (0.3, 10.0, 2000.0)])
def test_flow_stress_closed_form(ep, rate, T):
    # the bundled TC4 holds its hardening beyond its CALIBRATED hardening_strain_limit
    assert TC4.flow_stress(ep, rate, T) == pytest.approx(
        _jc_hand(ep, rate, T, TC4.hardening_strain_limit), rel=1e-12)
    assert jc.jc_flow_stress_py(ep, rate, T, TC4.A, TC4.B, TC4.n, TC4.C, TC4.m, 1.0, 293.0,
                                1873.0, math.inf) == pytest.approx(_jc_hand(ep, rate, T), rel=1e-12)


def test_failure_strain_closed_form():
    # JC 1985: eps_f = (D1 + D2 exp(D3 s*)) (1 + D4 ln rate*) (1 + D5 T*)
    s, rate, T = -0.4, 100.0, 600.0
    ts = (T - 293.0) / (1873.0 - 293.0)
    hand = (-0.09 + 0.25 * math.exp(-0.5 * s)) * (1 + 0.014 * math.log(rate)) * (1 + 3.87 * ts)
    assert TC4.failure_strain(s, rate, T) == pytest.approx(hand, rel=1e-12)
    d = jc.jc_damage_increment(0.01, s, rate, T, TC4.D1, TC4.D2, TC4.D3, TC4.D4, TC4.D5,
                               1.0, 293.0, 1873.0)
    assert d == pytest.approx(0.01 / hand, rel=1e-12)


def _trial(q, direction=(2.0, -1.0, -1.0, 0.5)):
    s = np.array(direction, float)
    s[:3] -= s[:3].mean()
    qs = math.sqrt(1.5 * (s[0] ** 2 + s[1] ** 2 + s[2] ** 2 + 2 * s[3] ** 2))
    return s * q / qs


def test_radial_return_linear_hardening_closed_form():
    """n = 1, C = 0, T = Troom: d = (q - A) / (3G + B) exactly."""
    G = TC4.G
    q = 3.0e9
    s = _trial(q)
    out = jc.radial_return(*s, 0.0, 293.0, 1e-8, G, 1e9, 5e9, 1.0, 0.0, 0.7, 1.0, 293.0,
                           1873.0, math.inf)
    d_exact = (q - 1e9) / (3 * G + 5e9)
    assert out[4] == pytest.approx(d_exact, rel=1e-10)
    assert out[5] == pytest.approx(1e9 + 5e9 * d_exact, rel=1e-10)


@settings(max_examples=60, deadline=None)
@given(q=st.floats(1.1e9, 2e10), ep=st.floats(0.0, 3.0), T=st.floats(293.0, 1700.0),
       dt=st.floats(1e-10, 1e-5))
def test_radial_return_consistency(q, ep, T, dt):
    """Returned stress lies on the JC surface at the solved rate and keeps its direction."""
    m = TC4
    s = _trial(q)
    sy0 = _jc_hand(ep, 0.0, T)  # the plain law, as the return below (limit inf)
    sx, sy, sz, sxy, d, syld = jc.radial_return(*s, ep, T, dt, m.G, m.A, m.B, m.n, m.C, m.m,
                                                1.0, 293.0, 1873.0, math.inf)
    qn = math.sqrt(1.5 * (sx * sx + sy * sy + sz * sz + 2 * sxy * sxy))
    if q <= sy0:
        assert d == 0.0
        return
    assert d > 0
    assert syld == pytest.approx(_jc_hand(ep + d, d / dt, T), rel=1e-9)
    assert qn == pytest.approx(syld, rel=1e-9)
    assert q - 3 * m.G * d == pytest.approx(qn, rel=1e-8, abs=1e-3)
    np.testing.assert_allclose(np.array([sx, sy, sz, sxy]) / qn, s / q, rtol=1e-9, atol=1e-12)


def test_elastic_state_unchanged():
    s = _trial(0.5e9)
    out = jc.radial_return(*s, 0.0, 293.0, 1e-8, TC4.G, TC4.A, TC4.B, TC4.n, TC4.C, TC4.m, 1.0,
                           293.0, 1873.0, math.inf)
    np.testing.assert_allclose(out[:4], s)
    assert out[4] == 0.0


def test_user_material_file(tmp_path):
    txt = (tmp_path / "x.toml")
    src = (load_material.__globals__["resources"].files("robobore.material") / "library"
           / "tc4.toml").read_text()
    txt.write_text(src.replace('name = "TC4"', 'name = "MINE"').replace("A_MPa = 997.9",
                                                                        "A_MPa = 500.0"))
    m = load_material(str(txt))
    assert m.name == "MINE" and m.A == pytest.approx(500e6)


def test_unknown_material_is_clear():
    with pytest.raises(ConfigError, match="unknown material.*'NOPE'.*TC4"):
        load_material("NOPE", source="cfg.toml")


def test_bad_material_file(tmp_path):
    f = tmp_path / "bad.toml"
    src = (load_material.__globals__["resources"].files("robobore.material") / "library"
           / "tc4.toml").read_text()
    f.write_text(src.replace("E_GPa = 113.8", "E_GPa = -1.0"))
    with pytest.raises(ConfigError, match="elastic.E_GPa"):
        load_material(str(f))


@settings(max_examples=80, deadline=None)
@given(ep=st.floats(0.0, 3.0), T=st.floats(293.0, 1500.0), log_rate=st.floats(0.0, 6.5),
       dt=st.floats(1e-10, 1e-7))
def test_radial_return_recovers_a_constructed_root(ep, T, log_rate, dt):
    """A trial stress built from a known increment d (q = 3 G d + sigma_y(ep + d, d / dt, T),
    plastic strain rates 1 to 3e6 1/s, the range of a cut) returns that d: the start of the
    Newton solve (the smaller of two upper bounds of the root) must not change the root.
    Tolerance 1e-9 relative (the solve stops at 1e-12 relative in d)."""
    m = TC4
    d_true = 10.0 ** log_rate * dt
    q = 3 * m.G * d_true + _jc_hand(ep + d_true, d_true / dt, T)
    out = jc.radial_return(*_trial(q), ep, T, dt, m.G, m.A, m.B, m.n, m.C, m.m, 1.0, 293.0,
                           1873.0, math.inf)
    assert out[4] == pytest.approx(d_true, rel=1e-9)


def test_hardening_strain_limit_holds_the_hardening_term():
    """With a hardening strain limit the flow stress is the plain law up to the limit and
    the law at the limit beyond it (closed form); inf gives the plain law bit for bit."""
    lim = 0.8
    for ep in (0.0, 0.3, 0.8, 1.5, 3.0):
        for rate, T in ((1.0, 293.0), (1e5, 600.0)):
            got = jc.jc_flow_stress_py(ep, rate, T, TC4.A, TC4.B, TC4.n, TC4.C, TC4.m, 1.0,
                                       293.0, 1873.0, lim)
            assert got == pytest.approx(_jc_hand(min(ep, lim), rate, T), rel=1e-12)
            plain = jc.jc_flow_stress_py(ep, rate, T, TC4.A, TC4.B, TC4.n, TC4.C, TC4.m, 1.0,
                                         293.0, 1873.0, math.inf)
            assert plain == pytest.approx(_jc_hand(ep, rate, T), rel=1e-12)


@pytest.mark.parametrize("ep,T,log_rate,dt", [(0.5, 400.0, 4.0, 1e-9), (2.0, 700.0, 5.0, 5e-9),
                                              (0.79, 300.0, 3.0, 1e-8)])
def test_radial_return_with_a_hardening_strain_limit_recovers_a_constructed_root(
        ep, T, log_rate, dt):
    """A trial stress built from a known increment d on the held curve,
    q = 3 G d + sigma_JC(min(ep + d, limit), d / dt, T), is returned to that d
    (the start below, across and beyond the limit 0.8). Tolerance 1e-9 relative."""
    m = TC4
    lim = 0.8
    d_true = 10.0 ** log_rate * dt
    q = 3 * m.G * d_true + _jc_hand(min(ep + d_true, lim), d_true / dt, T)
    out = jc.radial_return(*_trial(q), ep, T, dt, m.G, m.A, m.B, m.n, m.C, m.m, 1.0, 293.0,
                           1873.0, lim)
    assert out[4] == pytest.approx(d_true, rel=1e-9)
    assert out[5] == pytest.approx(_jc_hand(min(ep + d_true, lim), d_true / dt, T), rel=1e-9)


def test_hardening_strain_limit_from_files_and_configs(tmp_path):
    """The key in a material file, its override in an FE config, and a bad value."""
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.errors import ConfigError
    from robobore.material import load_material

    # the bundled TC4's CALIBRATED hold (docs/fe.md, "Model choice")
    assert load_material("TC4").hardening_strain_limit == 0.6
    src = (Path(jc.__file__).parent / "library" / "tc4.toml").read_text()
    f = tmp_path / "tc4_held.toml"
    key = "hardening_strain_limit = 0.6"
    assert key in src
    f.write_text(src.replace(key, "hardening_strain_limit = 1.5"))
    assert load_material(str(f)).hardening_strain_limit == 1.5
    assert load_material(str(f), hardening_strain_limit=0.7).hardening_strain_limit == 0.7
    assert load_material(str(f)).to_array()[jc.EPS_HMAX] == 1.5
    f.write_text(src.replace(key, "hardening_strain_limit = -1"))
    with pytest.raises(ConfigError, match="hardening_strain_limit"):
        load_material(str(f))
    base = {"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
            "cut": {"uncut_chip_thickness_um": 60, "cutting_speed_m_per_min": 30,
                    "length_mm": 0.01}, "mesh": {"element_size_um": 10}, "solver": {}}
    cfg = parse_config({**base, "material": {"name": "TC4", "hardening_strain_limit": 1.0}})
    assert cfg.material.hardening_strain_limit == 1.0
    with pytest.raises(ConfigError, match="material.hardening_strain_limit"):
        parse_config({**base, "material": {"name": "TC4", "hardening_strain_limit": 0.0}})


#: the compiled Johnson-Cook functions shared by the 2D, 3D and GPU engines
_SHARED = ("homologous_temperature", "jc_athermal", "jc_flow_stress", "jc_failure_strain",
           "jc_damage_increment", "jc_return", "radial_return")


def test_shared_functions_set_their_own_floating_point_flags():
    # numba compiles a callee with its caller's fastmath flags unless the callee sets them, and
    # keeps (and caches on disk) that one compilation for every later caller: each shared
    # function sets fastmath=False, so the 3D element's fastmath cannot leak into the 2D engine
    for name in _SHARED:
        assert getattr(jc, name).targetoptions.get("fastmath") is False, name


_FAST_FIRST = """
import sys
from numba import njit
from robobore.material import johnson_cook as jc
args = (9.4e-08, 2.572, 997900000.0, 653100000.0, 0.45, 0.0198, 1.0, 0.6)
if sys.argv[1] == "fast":
    @njit(fastmath={"contract", "reassoc", "arcp", "nsz"})
    def caller(a):
        return jc.jc_athermal(*a) + jc.jc_return(1.2e9, 9.1e-08, 294.05, 1.07e-09, 4.2e10, 997900000.0,
                                                653100000.0, 0.45, 0.0198, 0.7, 1.0, 293.0, 1873.0,
                                                0.6)[1]
    caller(args)
print(repr(jc.jc_athermal(*args)), repr(jc.jc_return(1.2e9, 9.1e-08, 294.05, 1.07e-09, 4.2e10,
      997900000.0, 653100000.0, 0.45, 0.0198, 0.7, 1.0, 293.0, 1873.0, 0.6)))
"""


def test_results_do_not_depend_on_a_fastmath_caller_compiled_first(tmp_path):
    # a fresh numba cache each: a process that compiled a fastmath caller of the shared
    # functions first (as the 3D element is) gets the digits of one that did not
    import os
    import subprocess
    import sys

    def run(mode, cache):
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / cache))
        return subprocess.run([sys.executable, "-c", _FAST_FIRST, mode], env=env, check=True,
                              capture_output=True, text=True).stdout

    plain = run("plain", "a")
    assert run("fast", "b") == plain
    assert run("plain", "b") == plain  # after the fastmath caller's process wrote the cache
