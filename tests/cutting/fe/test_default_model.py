"""The validated model is the engine's default: a config with only the contract keys lands in
the engine exactly as the CALIBRATED validation configuration
(examples/fe_orthogonal_toolframe_calibrated.toml, whose nine-point validation figures are in
docs/fe.md), and ``parameters = "a_priori"`` is the a-priori set of the same table."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from robobore.cutting.fe.config.contact import FRICTION_TABLE_MU
from robobore.cutting.fe.config.orthogonal import load_fe_config, parse_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.models.orthogonal import setup_orthogonal
from robobore.errors import ConfigError
from robobore.io.config import load_toml
from robobore.material import johnson_cook as jc
from robobore.material import load_material
from robobore.material.friction import friction_law, friction_laws

_EX = Path(__file__).parents[3] / "examples"


def _engine(cfg) -> dict:
    """Everything the engine is given: the parameter vector, the material vector, the mesh
    and every array and scalar of the initial state and the run's setup."""
    su = setup_orthogonal(cfg)
    out = {}
    for f in dataclasses.fields(su.state):
        out[f"state.{f.name}"] = getattr(su.state, f.name)
    for name in ("h", "vc", "rake", "t_end", "t_contact", "mu", "x_cut_start"):
        out[name] = getattr(su, name)
    out["mesh.nodes"] = su.mesh.nodes
    out["mesh.conn"] = su.mesh.conn
    return out


def _assert_same(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        va, vb = a[k], b[k]
        if isinstance(va, np.ndarray):
            assert va.shape == vb.shape and va.dtype == vb.dtype, k
            assert np.array_equal(va, vb, equal_nan=va.dtype.kind == "f"), k
        elif isinstance(va, float) and math.isnan(va):
            assert math.isnan(vb), k
        else:
            assert va == vb, k


def test_contract_keys_only_run_the_calibrated_validation_model():
    default = load_fe_config(_EX / "fe_orthogonal.toml")
    calibrated = load_fe_config(_EX / "fe_orthogonal_toolframe_calibrated.toml")
    # the contract example sets nothing beyond the contract keys
    d = load_toml(_EX / "fe_orthogonal.toml")
    assert set(d) == {"material", "tool", "cut", "mesh"}
    assert set(d["mesh"]) == {"element_size_um"}
    _assert_same(_engine(default), _engine(calibrated))


def test_default_choices_are_the_labelled_calibrated_data():
    cfg = parse_config({"tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
                        "cut": {"uncut_chip_thickness_um": 40.0, "cutting_speed_m_per_min": 10.0,
                                "length_mm": 0.3},
                        "mesh": {"element_size_um": 10.0}})
    assert cfg.mesh.frame == "tool" and cfg.solver.heat_conduction
    assert cfg.solver.mass_scaling == pytest.approx(100.0 * (30.0 / 10.0) ** 2)
    law = friction_law("rech2013_calibrated")
    assert law.status == "CALIBRATED" and "nine measured points" in law.calibrated_on
    np.testing.assert_allclose(law.mu, 1.5 * FRICTION_TABLE_MU, rtol=1e-12)
    assert cfg.contact.friction_velocity == "sliding" and cfg.contact.shear_limit_MPa == 5000.0
    assert "CALIBRATED" in cfg.friction_law()
    assert load_material("TC4").hardening_strain_limit == 0.6
    assert setup_orthogonal(cfg).state.mat[jc.EPS_HMAX] == 0.6


def test_a_priori_is_one_switch_away():
    base = load_toml(_EX / "fe_orthogonal.toml")
    cfg = parse_config({**base, "parameters": "a_priori"})
    assert friction_law("rech2013").status == "A-PRIORI"
    assert cfg.contact.friction_velocity == "cutting_speed"
    assert cfg.contact.shear_limit_MPa == 576.0
    np.testing.assert_allclose(cfg.contact.table()[1], FRICTION_TABLE_MU)
    p = setup_orthogonal(cfg).state
    assert p.mat[jc.EPS_HMAX] == math.inf
    assert p.prm[layout.P_MUTAB_N] == 0  # one coefficient for the run: the table at vc
    assert p.prm[layout.P_MU] == pytest.approx(0.18)
    # the same model otherwise: tool frame, conduction, the same mass scaling
    assert cfg.mesh.frame == "tool" and cfg.solver.heat_conduction
    assert cfg.solver.mass_scaling == 100.0
    # explicit keys win over the switch
    cfg2 = parse_config({**base, "parameters": "a_priori",
                         "material": {"name": "TC4", "hardening_strain_limit": 0.6}})
    assert setup_orthogonal(cfg2).state.mat[jc.EPS_HMAX] == 0.6


def test_friction_and_parameter_errors_name_the_key():
    base = load_toml(_EX / "fe_orthogonal.toml")
    with pytest.raises(ConfigError, match=r"contact\.friction.*rech2013"):
        parse_config({**base, "contact": {"friction": "rech2099"}}, "x.toml")
    with pytest.raises(ConfigError, match="parameters"):
        parse_config({**base, "parameters": "fitted"}, "x.toml")
    with pytest.raises(ConfigError, match="own table"):
        parse_config({**base, "contact": {"friction": "rech2013",
                                          "friction_table_velocity_m_per_min": [1.0, 2.0],
                                          "friction_table_mu": [0.1, 0.2]}}, "x.toml")
    with pytest.raises(ConfigError, match="hardening_strain_limit"):
        parse_config({**base, "material": {"name": "TC4", "hardening_strain_limit": 0.0}})
    assert set(friction_laws()) >= {"rech2013", "rech2013_calibrated"}
