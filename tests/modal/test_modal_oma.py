"""Operational (output-only) modal analysis, SSI-COV, on SYNTHETIC records (documented truth:
``robobore.modal.oma.simulate_operational`` of the modal truths of ``robobore.modal.virtual``
and ``robobore.plan.virtual_hammer``).

Acceptance: frequencies within 1 %, damping within 15 % of the truth under random and cutting
excitation of the multibody robot model (IRB 6600 at the paper's posture, 300 s at 2048 Hz,
band 3-40 Hz: its modes 8.15, 10.54, 27.68 Hz; cutting at the paper's 300 r/min, harmonics
RMS equal to the random part's), compared with the hammer-test identification of the same
model; on the bundled robot's cutting vibration at 300 r/min the first three modes within
2 %; a record shorter than ten periods of the band's low edge is refused with that number.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import InputError
from robobore.modal.frf import estimate_frf
from robobore.modal.identify import identify_modes
from robobore.modal.oma import (
    OperationalRecord,
    correlations,
    identify_operational,
    remove_harmonics,
    simulate_operational,
)
from robobore.modal.virtual import EXAMPLE_POSTURE_DEG, robot_boring_truth, simulate_hammer_test
from robobore.plan.virtual_hammer import robot_truth
from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD as K_IRB

runner = CliRunner()


@pytest.fixture(scope="module")
def irb():
    return robot_truth("irb6600-175-2.55", EXAMPLE_POSTURE_DEG, K_IRB)[0]


@pytest.mark.parametrize("rpm", [None, 300.0])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_multibody_robot_random_and_cutting(irb, rpm, seed):
    rec = simulate_operational(irb, 300.0, 2048.0, spindle_rpm=rpm, seed=seed)
    r = identify_operational(rec, (3.0, 40.0), spindle_rpm=rpm, uncertainty=False)
    ft, zt = irb.frequencies_Hz[:3], irb.damping_ratios[:3]
    assert len(r.modes) == 3, r.frequencies_Hz
    np.testing.assert_array_less(np.abs(r.frequencies_Hz / ft - 1), 0.01)
    np.testing.assert_array_less(np.abs(r.damping_ratios / zt - 1), 0.15)


def test_operational_agrees_with_the_hammer_test_of_the_same_model(irb):
    rec = simulate_operational(irb, 300.0, 2048.0, seed=3)
    oma = identify_operational(rec, (3.0, 40.0), uncertainty=False)
    ham = simulate_hammer_test(irb, n_hits=5, sample_rate_Hz=2048.0, duration_s=8.0,
                               noise_force=0.01, noise_response=0.01, seed=3)
    fr = dataclasses.replace(estimate_frf(ham).frf, output_dofs=(), input_dofs=())
    exp = identify_modes(fr, band_Hz=(2.0, 150.0)).result
    # the same three modes: frequencies within 1 %, damping within 15 % of each other
    near = [int(np.argmin(np.abs(exp.frequencies_Hz - f))) for f in oma.frequencies_Hz]
    np.testing.assert_array_less(np.abs(oma.frequencies_Hz / exp.frequencies_Hz[near] - 1),
                                 0.01)
    np.testing.assert_array_less(np.abs(oma.damping_ratios / exp.damping_ratios[near] - 1),
                                 0.15)


@pytest.mark.parametrize("seed", [0, 1])
def test_bundled_robot_cutting_vibration_first_three_modes(seed):
    truth = robot_boring_truth()
    rec = simulate_operational(truth, 300.0, 256.0, spindle_rpm=300.0, seed=seed)
    r = identify_operational(rec, (3.0, 60.0), spindle_rpm=300.0)
    for f in truth.frequencies_Hz[:3]:
        assert np.min(np.abs(r.frequencies_Hz / f - 1)) < 0.02
    assert abs(r.stabilisation["rotation_frequency_Hz"] - 5.0) < 1e-3
    for m in r.modes:  # jackknife over record segments: intervals around the estimate
        u = m.uncertainty
        assert u.frequency_ci_Hz[0] < m.frequency_Hz < u.frequency_ci_Hz[1]
        assert u.damping_std > 0 and u.dof == 5


def test_short_record_refused_with_the_number():
    rec = OperationalRecord(np.random.default_rng(0).standard_normal((3, 512)), 256.0)
    with pytest.raises(InputError, match="ten periods") as e:
        identify_operational(rec, (3.0, 60.0))
    assert "3.33333 s" in str(e.value)


def test_correlations_and_harmonic_removal_hand_checks():
    rng = np.random.default_rng(1)
    y = rng.standard_normal((2, 4000))
    R = correlations(y, 3)
    np.testing.assert_allclose(R[2], y[:, 2:] @ y[:, :-2].T / 3998, rtol=1e-10)
    t = np.arange(20000) / 200.0
    s = np.vstack([np.cos(2 * np.pi * 5.003 * t + 0.3), 0.5 * np.sin(2 * np.pi * 10.006 * t)])
    left, fr = remove_harmonics(s + 0.01 * rng.standard_normal(s.shape), 200.0, 300.0, 20.0)
    assert fr == pytest.approx(5.003, abs=2e-4)
    assert np.std(left) < 0.02


def test_cli_operational(tmp_path):
    rec = simulate_operational(robot_boring_truth(), 300.0, 256.0, spindle_rpm=300.0, seed=0)
    p = tmp_path / "cut.npz"
    np.savez(p, data=rec.data, sample_rate_Hz=rec.sample_rate_Hz,
             channel_names=np.array(rec.channel_names))
    r = runner.invoke(app, ["identify", "modes", "--operational", str(p), "--band-hz", "3",
                            "60", "--spindle-rpm", "300", "--modes", "3", "--json",
                            "--plot", str(tmp_path / "plots")])
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)
    assert len(res["modes"]) == 3 and res["method"].startswith("SSI-COV")
    assert (tmp_path / "plots" / "stabilisation_oma.png").is_file()
    r = runner.invoke(app, ["identify", "modes", "--operational", str(p)])
    assert r.exit_code == 2 and "--band-hz" in r.output


def test_operational_uff_records(tmp_path):
    """UFF 58 response records (no force channel) in mm/s^2 with a 164 length factor."""
    import pyuff

    rec = simulate_operational(robot_boring_truth(), 200.0, 256.0, seed=5)
    dt = 1.0 / rec.sample_rate_Hz
    sets = [{"type": 164, "units_code": 1, "units_description": "mm", "temp_mode": 2,
             "length": 1000.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}]
    for k, name in enumerate(rec.channel_names):
        sets.append(dict(type=58, binary=1, id1="SYNTHETIC", id2=name, id3="NONE",
                         id4="NONE", id5="NONE", func_type=1, ver_num=0, load_case_id=1,
                         rsp_ent_name=name[:10], rsp_node=k + 1, rsp_dir=1,
                         ref_ent_name="NONE", ref_node=0, ref_dir=0, ord_data_type=4,
                         num_pts=rec.data.shape[1], abscissa_spacing=1, abscissa_min=0.0,
                         abscissa_inc=dt, abscissa_spec_data_type=17,
                         ordinate_spec_data_type=12, orddenom_spec_data_type=0,
                         z_axis_spec_data_type=0, data=1000.0 * rec.data[k],
                         x=np.arange(rec.data.shape[1]) * dt))
    p = tmp_path / "amb.uff"
    pyuff.UFF(str(p)).write_sets(sets, mode="add")
    from robobore.modal.oma import load_operational

    back = load_operational(p)
    np.testing.assert_allclose(back.data, rec.data, rtol=1e-12)
    assert back.channel_names == rec.channel_names and back.sample_rate_Hz == 256.0


def test_no_stable_pole_names_the_file_channels_and_expectation(tmp_path):
    """A one-channel record of a pure tone in noise has no damped pole stable over the
    orders: the error names the file, the channel count, the record length and what is
    expected, and suggests more channels."""
    fs = 200.0
    t = np.arange(0.0, 60.0, 1.0 / fs)
    y = np.sin(2 * np.pi * 9.0 * t) + 0.3 * np.random.default_rng(0).standard_normal(t.size)
    p = tmp_path / "one.npz"
    np.savez(p, data=y[None, :], sample_rate_Hz=fs)
    r = runner.invoke(app, ["identify", "modes", "--operational", str(p), "--band-hz", "3",
                            "60"])
    assert r.exit_code == 2, r.output
    out = " ".join(r.output.split())
    assert "one.npz" in out and "1 response channel of 60 s" in out
    assert "expected at least one physical pole" in out and "more channels" in out
