"""The Python API (``robobore.api``) and the typed hand-offs between stages.

* The README's "Python API" example is extracted from README.md and run as written, so the
  README and the code cannot drift; its results are checked against the bundled SYNTHETIC
  data's documented ground truth (the campaign's joint stiffnesses
  ``IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD`` and the hammer test's modal model
  ``robot_boring_truth()``) and against physics (the pressure foot stiffens the robot and
  raises the critical depth; the time-domain run agrees with the lobes).
* Each stage takes the previous stage's object and its dict form with the same result, and
  anything else is an ``InputError`` naming the argument.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robobore import api
from robobore.equivalent import EquivalentModel
from robobore.errors import ConfigError, InputError
from robobore.io.config import dump_toml

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def readme_api_code() -> str:
    """The Python code blocks of the README's '## Python API' section, joined."""
    text = README.read_text()
    m = re.search(r"^## Python API\s*$(.*?)(?=^## )", text, flags=re.S | re.M)
    assert m, "README.md has no '## Python API' section"
    blocks = re.findall(r"```python\n(.*?)```", m.group(1), flags=re.S)
    assert blocks, "the README's Python API section has no python code block"
    return "\n".join(blocks)


@pytest.fixture(scope="module")
def readme_run():
    ns: dict = {"__name__": "readme_example"}
    exec(compile(readme_api_code(), str(README), "exec"), ns)  # noqa: S102
    return ns


@pytest.fixture(scope="module")
def chain():
    """The stage objects of the bundled example (what the README builds)."""
    joints = api.identify_joint_stiffness()
    pose = api.stiffness_at_pose(joints)
    modes = api.identify_modes()
    return {"joints": joints, "pose": pose, "modes": modes,
            "robot": api.equivalent_model(pose, modes)}


def _process(count: int = 8) -> dict:
    return {"insert": {"nose_radius_mm": 0.4}, "bore": {"diameter_mm": 40.0},
            "cutting": {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_mm": 0.05},
            "coefficients": api.bundled_coefficients(),
            "speed_rpm": {"min": 200.0, "max": 900.0, "count": count}}


# ----------------------------------------------------------------------------- README
def test_readme_example_identifies_the_bundled_ground_truth(readme_run):
    from robobore.modal.virtual import robot_boring_truth
    from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD as K_TRUE

    ns = readme_run
    # directional stiffness at the posture within 5 % of the campaign's ground truth
    k_true = api.directional_stiffness(list(K_TRUE))
    k_id = ns["pose"].directional_stiffness_N_per_m
    for a in "xyz":
        assert k_id[a] == pytest.approx(k_true[a], rel=0.05), a
    # the five modes of the hammer test's modal model, in the band
    truth = robot_boring_truth()
    f = ns["modes"].result.frequencies_Hz
    assert f.shape == (5,)
    assert np.all((f >= 3.0) & (f <= 60.0))
    np.testing.assert_allclose(f, np.sort(truth.frequencies_Hz), rtol=0.01)
    z_true = np.asarray(truth.damping_ratios)[np.argsort(truth.frequencies_Hz)]
    np.testing.assert_allclose(ns["modes"].result.damping_ratios, z_true, rtol=0.10)
    # equivalent model: k from the pose, f of the mode assigned by direction, m = k / w^2
    robot = ns["robot"]
    for a, f_a in zip("xyz", (6.9, 16.8, 24.6), strict=True):
        assert robot.stiffness_N_per_m[a] == k_id[a]
        assert robot.frequency_Hz[a] == pytest.approx(f_a, rel=0.01)
        assert robot.mass_kg[a] == pytest.approx(
            k_id[a] / (2 * np.pi * robot.frequency_Hz[a]) ** 2, rel=1e-12)


def test_readme_example_foot_raises_the_lobes_and_the_run_agrees(readme_run):
    ns = readme_run
    lb, lf = ns["lobes"], ns["lobes_foot"]
    speeds = np.asarray(lb.speed_rpm)
    assert speeds[0] == 150.0 and speeds[-1] == 1100.0 and speeds.size == 39
    d, df = np.asarray(lb.critical_depth_mm), np.asarray(lf.critical_depth_mm)
    assert np.all(d >= 0) and np.all(df >= 0)
    # a robot: chatter within a few tenths of a mm at most speeds, never above the scan;
    # no chatter-free depth near the forced resonances (425-475 r/min: the 6.9 Hz mode;
    # 750-800 r/min: twice the spindle frequency at the 24.6 Hz mode; above 975 r/min), where
    # the steady forced vibration takes the tool out of the cut or the bar's parametric
    # instability needs no cut (27 of 39 speeds finite)
    assert np.mean((d > 0) & np.isfinite(d)) >= 0.6
    assert np.median(d) < 1.0
    below = np.asarray(lb.interrupted_below_mm)
    assert below.shape == d.shape and np.all(below >= 0)
    assert np.all(d[d > 0] > below[d > 0])  # chatter-free window between the two
    # the pressure foot adds stiffness and damping: every axis stiffer, lobes higher
    for a in "xyz":
        assert ns["robot_foot"].stiffness_N_per_m[a] > ns["robot"].stiffness_N_per_m[a]
    assert df.min() > np.median(d)
    assert np.median(df) > 2 * np.median(d)
    assert lb.mode_coupling_limit_mm is None or lb.mode_coupling_limit_mm > 0
    # time domain at the cutting condition (300 r/min, 0.05 mm) vs the lobes there
    i = int(np.argmin(np.abs(speeds - 300.0)))
    assert speeds[i] == 300.0
    run = ns["run"]
    assert run.speed_rpm == 300.0 and run.depth_mm == 0.05
    assert (d[i] > 0.05) == (not run.chatter)
    assert not run.diverged
    assert 0.0 < run.roughness_Ra_um < 10.0
    assert ns["share"]["with foot"] >= ns["share"]["without foot"]


def test_docs_api_examples_run(tmp_path, monkeypatch, readme_run):
    """The Python blocks of docs/api.md run as written (in a scratch folder)."""
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "api.md").read_text(),
                        flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    for code in blocks:
        ns: dict = {}
        exec(compile(code, "docs/api.md", "exec"), ns)  # noqa: S102
    # the JSON round trip gives the README's model
    assert ns["robot"].frequency_Hz == readme_run["robot"].frequency_Hz
    assert ns["robot"].stiffness_N_per_m == readme_run["robot"].stiffness_N_per_m


def test_import_of_the_api_is_cheap():
    code = ("import sys, robobore.api; "
            "print(sorted(m for m in ('numpy', 'scipy', 'numba', 'pydantic', 'xarray') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert json.loads(out.stdout.replace("'", '"')) == []
    # import robobore loads no API (nor any stage); its attributes load the API on use
    code = ("import sys, robobore; a = 'robobore.api' in sys.modules; "
            "f = robobore.stability_lobes; from robobore import api; "
            "print(a, f is api.stability_lobes, 'identify_modes' in dir(robobore))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["False", "True", "True"]
    import robobore

    for name in api.__all__:
        assert getattr(robobore, name) is getattr(api, name)
    with pytest.raises(AttributeError):
        robobore.no_such_function  # noqa: B018


# ----------------------------------------------------------------------------- robot
def test_joint_stiffness_forms_give_the_same_stiffness(chain):
    j = chain["joints"]
    ref = api.directional_stiffness(j)
    for form in (j.joint, j.to_dict(), j.joint.to_dict(), list(j.joint.k_Nm_per_rad)):
        assert api.directional_stiffness(form) == ref
        r = api.stiffness_at_pose(form)
        assert r.directional_stiffness_N_per_m == pytest.approx(ref, rel=1e-12)
        assert r.cartesian_stiffness == chain["pose"].cartesian_stiffness
    # the campaign's first posture is the paper posture: the identification's directional
    # stiffness is the one at the pose
    assert j.directional["directional_stiffness_N_per_m"] == pytest.approx(ref, rel=1e-12)


@pytest.mark.parametrize("bad", ["stiff", None, {1, 2}, object()])
def test_joint_stiffness_of_a_wrong_type_is_an_input_error(bad):
    with pytest.raises(InputError) as e:
        api.directional_stiffness(bad)
    assert e.value.field == "joint_stiffness"
    with pytest.raises(InputError) as e:
        api.stiffness_at_pose(bad)
    assert e.value.field == "joint_stiffness"


def test_identification_takes_a_campaign_or_a_path_or_nothing(chain):
    ref = chain["joints"].joint.k_Nm_per_rad
    assert api.identify_joint_stiffness(api.load_campaign()).joint.k_Nm_per_rad == ref
    assert api.identify_joint_stiffness(str(api.bundled_campaign_path())).joint.k_Nm_per_rad \
        == ref
    with pytest.raises(InputError) as e:
        api.identify_joint_stiffness(42)
    assert e.value.field == "campaign"


# ----------------------------------------------------------------------------- modal
def test_modal_stage_takes_records_estimate_or_frf(chain):
    from robobore.modal.frf import estimate_frf
    from robobore.modal.identify import identify_modes

    rec = api.load_hammer_test()
    est = estimate_frf(rec)
    ref = chain["modes"].result.to_dict()
    for data in (est, est.frf):
        got = identify_modes(data, band_Hz=api.PAPER_BAND_HZ, n_modes=5).result.to_dict()
        assert [m["frequency_Hz"] for m in got["modes"]] == \
            [m["frequency_Hz"] for m in ref["modes"]]
        assert [m["damping_ratio"] for m in got["modes"]] == \
            [m["damping_ratio"] for m in ref["modes"]]
    assert api.cmif(rec).peaks_Hz.tolist() == api.cmif(est.frf).peaks_Hz.tolist()
    with pytest.raises(InputError) as e:
        identify_modes(rec, n_modes=5)
    assert e.value.field == "data" and "estimate the FRFs" in str(e.value)
    with pytest.raises(InputError) as e:
        api.frf(np.zeros((3, 3)))
    assert e.value.field == "records"


# ----------------------------------------------------------------------------- equivalent
def test_equivalent_model_takes_objects_and_their_dict_forms(chain):
    j, pose, an = chain["joints"], chain["pose"], chain["modes"]
    ref = EquivalentModel.from_stiffness_and_modes(j.to_dict(), an.result.to_dict())
    for st in (j, pose, j.to_dict(), dict(pose.directional_stiffness_N_per_m),
               {"directional_stiffness_N_per_m": pose.directional_stiffness_N_per_m}):
        for md in (an, an.result, an.result.to_dict()):
            got = EquivalentModel.from_stiffness_and_modes(st, md)
            assert _same_model(got, ref), (type(st).__name__, type(md).__name__)
    # the foot and the damping coefficient act the same on both forms
    a = api.equivalent_model(pose, an, foot_pressure_MPa=0.3, damping_N_s_per_m=23.7)
    b = api.equivalent_model(pose.to_dict(), an.result.to_dict(), foot_pressure_MPa=0.3,
                             damping_N_s_per_m=23.7)
    assert _same_model(a, b)
    assert a.foot is not None and a.stiffness_N_per_m["z"] > ref.stiffness_N_per_m["z"]


def _same_model(a: EquivalentModel, b: EquivalentModel) -> bool:
    return all(getattr(a, f)[ax] == pytest.approx(getattr(b, f)[ax], rel=1e-12)
               for f in ("stiffness_N_per_m", "frequency_Hz", "damping_ratio") for ax in "xyz")


@pytest.mark.parametrize(("stiffness", "modes", "field"), [
    (42.0, None, "stiffness"),
    ("s.json", None, "stiffness"),
    (None, [6.9, 16.8, 24.6], "modes"),
    (None, "m.json", "modes"),
])
def test_equivalent_model_of_a_wrong_type_is_an_input_error(chain, stiffness, modes, field):
    st = chain["pose"] if stiffness is None else stiffness
    md = chain["modes"] if modes is None else modes
    with pytest.raises(InputError) as e:
        EquivalentModel.from_stiffness_and_modes(st, md)
    assert e.value.field == field


def test_joint_stiffness_alone_is_not_a_tool_point_stiffness(chain):
    with pytest.raises(InputError) as e:
        EquivalentModel.from_stiffness_and_modes(chain["joints"].joint, chain["modes"])
    assert e.value.field == "stiffness" and "need a posture" in str(e.value)


def test_equivalent_dict_path_errors_are_unchanged():
    with pytest.raises(ConfigError) as e:
        EquivalentModel.from_stiffness_and_modes({"x": 1e6, "y": 1e6}, {"modes": []})
    assert e.value.field == "directional_stiffness_N_per_m"


# ----------------------------------------------------------------------------- dynamics
def test_lobes_take_the_model_or_its_dict_form_like_the_equivalent_section(chain, tmp_path):
    em = chain["robot"]
    proc = _process()
    # reference: the [equivalent] section written by hand from the model's values
    ref = api.stability_lobes({**proc, "equivalent": _section(em)}, method="frequency")
    assert np.all(np.asarray(ref.critical_depth_mm) > 0)
    for eq in (em, em.to_dict(), json.loads(json.dumps(em.to_dict()))):
        got = api.stability_lobes(proc, eq, method="frequency")
        np.testing.assert_array_equal(got.critical_depth_mm, ref.critical_depth_mm)
        assert got.mode_coupling_limit_mm == ref.mode_coupling_limit_mm
    # a TOML process config, and the CLI's --equivalent-file route, give the same lobes
    toml = tmp_path / "process.toml"
    toml.write_text(dump_toml(proc))
    got = api.stability_lobes(toml, em, method="frequency")
    np.testing.assert_array_equal(got.critical_depth_mm, ref.critical_depth_mm)
    (tmp_path / "eq.json").write_text(json.dumps(em.to_dict()))
    (tmp_path / "files.toml").write_text('[model]\nequivalent_file = "eq.json"\n' + dump_toml(proc))
    got = api.stability_lobes(tmp_path / "files.toml", method="frequency")
    np.testing.assert_array_equal(got.critical_depth_mm, ref.critical_depth_mm)
    # a validated DynamicsConfig with the model given separately
    from robobore.dynamics.config import DynamicsConfig
    from robobore.io.config import validate_model

    cfg = validate_model(DynamicsConfig, {**proc, "equivalent": _section(em)})
    cfg_proc = cfg.model_copy(update={"equivalent": None})
    got = api.stability_lobes(cfg_proc, em, method="frequency")
    np.testing.assert_array_equal(got.critical_depth_mm, ref.critical_depth_mm)


def _section(em: EquivalentModel) -> dict:
    return {"stiffness_N_per_m": dict(em.stiffness_N_per_m),
            "frequency_Hz": dict(em.frequency_Hz), "damping_ratio": dict(em.damping_ratio)}


def test_boring_run_takes_the_model_or_its_dict_form(chain):
    em = chain["robot"]
    a = api.simulate_boring(_process(), em, revolutions=12)
    b = api.simulate_boring(_process(), em.to_dict(), revolutions=12)
    assert a == b
    assert a.force_amplitude_N.x > 0


def test_dynamics_refuses_a_wrong_model_or_a_model_given_twice(chain):
    em = chain["robot"]
    with pytest.raises(InputError) as e:
        api.stability_lobes(_process(), 42, method="frequency")
    assert e.value.field == "equivalent"
    with pytest.raises(ConfigError) as e:  # the config-section form is not the model's dict
        api.stability_lobes(_process(), {**em.to_dict(), "pressure_foot": {}},
                            method="frequency")
    assert e.value.field == "equivalent.pressure_foot"
    with pytest.raises(ConfigError) as e:
        api.stability_lobes({**_process(), "equivalent": _section(em)}, em,
                            method="frequency")
    assert e.value.field == "equivalent"
    with pytest.raises(InputError) as e:
        api.stability_lobes(42, em, method="frequency")
    assert e.value.field == "config"


def test_config_foot_applies_to_a_model_without_one(chain):
    em = chain["robot"]
    proc = {**_process(), "equivalent": {"pressure_foot": {"pressure_MPa": 0.3}}}
    with_foot = api.stability_lobes(proc, em, method="frequency")
    ref = api.stability_lobes(_process(), api.equivalent_model(
        chain["pose"], chain["modes"], foot_pressure_MPa=0.3), method="frequency")
    np.testing.assert_allclose(with_foot.critical_depth_mm, ref.critical_depth_mm,
                               rtol=1e-12)
    bare = api.stability_lobes(_process(), em, method="frequency")
    assert np.median(with_foot.critical_depth_mm) > np.median(bare.critical_depth_mm)
    with pytest.raises(ConfigError):  # a model that includes a foot gets no second one
        api.stability_lobes(proc, api.equivalent_model(chain["pose"], chain["modes"],
                                                       foot_pressure_MPa=0.3),
                            method="frequency")


def test_process_takes_the_cutting_stage_objects(chain):
    from robobore.cutting.coefficient_files import read_coefficients_file

    em = chain["robot"]
    ref = api.stability_lobes({**_process(), "coefficients": api.bundled_fe_coefficients()}, em,
                              method="frequency")
    # one calibrated speed: the file's content, its set at any speed and the table agree
    for coef in (read_coefficients_file(api.bundled_coefficients_path()),
                 api.cutting_coefficients(37.7, api.bundled_coefficients_path())):
        got = api.stability_lobes({**_process(), "coefficients": coef}, em, method="frequency")
        np.testing.assert_array_equal(got.critical_depth_mm, ref.critical_depth_mm)
    # a different set gives different lobes (the coefficients are used)
    k = api.cutting_coefficients(37.7)
    from dataclasses import replace

    got = api.stability_lobes({**_process(), "coefficients": replace(k, Ktc=2 * k.Ktc)}, em,
                              method="frequency")
    assert np.median(got.critical_depth_mm) < np.median(ref.critical_depth_mm)
    with pytest.raises(ConfigError):
        api.stability_lobes({**_process(), "coefficients": 3.0}, em, method="frequency")


def test_bundled_coefficients_are_the_measured_default_and_fe_is_opt_in():
    assert api.bundled_coefficients() == {"material": "TC4"}
    k = api.cutting_coefficients(37.7)
    assert k.Ktc > 0 and k.Kte > 0 and "measured orthogonal forces" in k.provenance
    assert api.bundled_fe_coefficients() == {"material": "TC4-FE"}
    fe = api.cutting_coefficients(37.7, api.bundled_coefficients_path())
    assert "FE-calibrated" in fe.provenance and fe.warnings == ()
