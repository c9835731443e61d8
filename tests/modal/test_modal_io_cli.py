"""Files (UFF 58/164, NPZ) and the CLI of the modal stage."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import DataError
from robobore.modal.example import example_path
from robobore.modal.frf import HammerRecords, estimate_frf
from robobore.modal.frf_data import FRFData
from robobore.modal.io import (
    _write_sets,
    default_dofs,
    load_input,
    load_npz,
    read_uff,
    save_npz,
    write_uff_frf,
    write_uff_time,
)
from robobore.modal.virtual import robot_boring_truth, simulate_hammer_test

runner = CliRunner()


@pytest.fixture(scope="module")
def small_records() -> HammerRecords:
    return simulate_hammer_test(robot_boring_truth().with_inputs([0, 2]), n_hits=2,
                                sample_rate_Hz=256.0, duration_s=2.0, seed=0)


def test_uff_time_round_trip(tmp_path, small_records):
    p = write_uff_time(small_records, tmp_path / "t.uff")
    back = read_uff(p)
    assert isinstance(back, HammerRecords)
    assert back.output_names == small_records.output_names
    assert back.input_names == ("hammer_x", "hammer_z")
    assert back.sample_rate_Hz == pytest.approx(256.0)
    np.testing.assert_allclose(back.force, small_records.force, rtol=1e-12)
    np.testing.assert_allclose(back.response, small_records.response, rtol=1e-12)


def test_uff_frf_round_trip_and_npz(tmp_path, small_records):
    d = estimate_frf(small_records).frf.band(1.0, 60.0)
    back = read_uff(write_uff_frf(d, tmp_path / "f.uff"))
    assert isinstance(back, FRFData) and back.frf_type == "accelerance"
    assert back.output_names == d.output_names and back.input_names == d.input_names
    np.testing.assert_allclose(back.frf, d.frf, rtol=1e-12)
    np.testing.assert_allclose(back.frequency_Hz, d.frequency_Hz, rtol=1e-12)
    n = load_input(save_npz(d, tmp_path / "f.npz"))
    np.testing.assert_array_equal(n.frf, d.frf)
    assert d.input_dofs == () and len(back.input_dofs) == 2  # UFF records carry DOFs
    n2 = load_npz(save_npz(back, tmp_path / "g.npz"))
    assert n2.input_dofs == back.input_dofs and n2.output_dofs == back.output_dofs
    assert n.output_names == d.output_names and n.coherence is not None


def test_uff_164_units_are_converted(tmp_path, small_records):
    """UFF 164: SI = value / factor. A file in mm (length factor 1000) and kN (force 1e-3)."""
    p = write_uff_time(small_records, tmp_path / "si.uff")
    import pyuff

    sets = pyuff.UFF(str(p)).read_sets()
    sets[0].update({"units_code": 2, "length": 1000.0, "force": 1e-3})
    for s in sets[1:]:
        s["data"] = s["data"] * (1e-3 if s["ordinate_spec_data_type"] == 13 else 1000.0)
    back = read_uff(_write_sets(tmp_path / "mm.uff", sets))
    np.testing.assert_allclose(back.force, small_records.force, rtol=1e-9)
    np.testing.assert_allclose(back.response, small_records.response, rtol=1e-9)


def test_uff_bad_files(tmp_path, small_records):
    only_units = _write_sets(tmp_path / "u.uff", [
        {"type": 164, "units_code": 1, "units_description": "SI", "temp_mode": 2,
         "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}])
    with pytest.raises(DataError, match="no dataset 58") as e:
        read_uff(only_units)
    assert "u.uff" in str(e.value)
    junk = tmp_path / "junk.uff"
    junk.write_text("hello\nworld\n")
    with pytest.raises(DataError):
        read_uff(junk)
    with pytest.raises(DataError, match="file not found"):
        read_uff(tmp_path / "missing.uff")
    # time records without the force channel
    import pyuff

    p = write_uff_time(small_records, tmp_path / "t.uff")
    sets = [s for s in pyuff.UFF(str(p)).read_sets() if s.get("ordinate_spec_data_type") != 13]
    with pytest.raises(DataError, match="no force channel"):
        read_uff(_write_sets(tmp_path / "noforce.uff", sets))
    # a response missing for one hit
    sets = pyuff.UFF(str(p)).read_sets()
    del sets[3]
    with pytest.raises(DataError, match="missing response record"):
        read_uff(_write_sets(tmp_path / "hole.uff", sets))
    # a whole hit missing for one input (force + responses): that hit is marked invalid
    sets = pyuff.UFF(str(p)).read_sets()
    n_ch = 1 + small_records.n_outputs
    hit2_x = sets[1 + n_ch: 1 + 2 * n_ch]
    assert all(s["load_case_id"] == 2 and s["ref_dir"] == 1 for s in hit2_x)
    rec = read_uff(_write_sets(tmp_path / "fewer.uff", sets[: 1 + n_ch] + sets[1 + 2 * n_ch:]))
    assert rec.valid.tolist() == [[True, False], [True, True]]
    assert estimate_frf(rec).n_averages.tolist() == [1, 2]
    # a response whose hit has no force record
    sets = pyuff.UFF(str(p)).read_sets()
    del sets[1 + n_ch]
    with pytest.raises(DataError, match="without force record"):
        read_uff(_write_sets(tmp_path / "orphan.uff", sets))


def test_npz_bad_files(tmp_path):
    p = tmp_path / "a.npz"
    np.savez(p, frequency_Hz=np.linspace(1, 2, 10), frf=np.ones((1, 1, 10)))
    with pytest.raises(DataError, match="frf_type") as e:
        load_npz(p)
    assert "a.npz" in str(e.value)
    np.savez(p, frequency_Hz=np.linspace(2, 1, 10), frf=np.ones((1, 1, 10)),
             frf_type="accelerance")
    with pytest.raises(DataError, match="not strictly increasing"):
        load_npz(p)
    np.savez(p, frequency_Hz=np.linspace(1, 2, 10), frf=np.ones((2, 9)),
             frf_type="accelerance")
    with pytest.raises(DataError, match="wrong shape"):
        load_npz(p)
    bad = tmp_path / "b.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(DataError, match="not a readable NPZ"):
        load_npz(bad)


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 3), st.integers(1, 3), st.integers(2, 40),
       st.sampled_from(["accelerance", "mobility", "receptance"]))
def test_npz_round_trip_property(tmp_path_factory, no, ni, nf, typ):
    rng = np.random.default_rng(no * 100 + ni * 10 + nf)
    f = np.cumsum(rng.uniform(0.1, 1.0, nf))
    h = rng.standard_normal((no, ni, nf)) + 1j * rng.standard_normal((no, ni, nf))
    d = FRFData(f, h, typ)
    p = tmp_path_factory.mktemp("npz") / "x.npz"
    back = load_npz(save_npz(d, p))
    np.testing.assert_array_equal(back.frf, d.frf)
    assert back.frf_type == typ and back.input_names == d.input_names


def test_default_dofs():
    assert default_dofs(("tool_x", "tool_y", "wrist_z", "acc7")) == [(1, 1), (1, 2), (2, 3),
                                                                      (104, 1)]


def test_bundled_example_is_small_and_labelled():
    p = example_path()
    assert p.is_file() and p.stat().st_size < 3e6
    readme = (p.parent / "README.md").read_text()
    assert "SYNTHETIC" in readme


def test_cli_example_json_meets_truth(tmp_path):
    r = runner.invoke(app, ["identify", "modes", "--example", "--json", "--plot",
                            str(tmp_path / "plots")])
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)
    truth = robot_boring_truth()
    f = np.array([m["frequency_Hz"] for m in res["modes"]])
    z = np.array([m["damping_ratio"] for m in res["modes"]])
    assert f.size == 5 and res["synthetic"] is True
    np.testing.assert_array_less(np.abs(f / truth.frequencies_Hz - 1), 0.005)
    np.testing.assert_array_less(np.abs(z / truth.damping_ratios - 1), 0.10)
    assert {"mpc", "direction", "mode_shape"} <= set(res["modes"][0])
    # driving points known from the UFF DOFs: effective modal masses 1/phi^2 of the truth
    # (README table), within 2 % (2 % noise in the example)
    for k, inp in enumerate(("hammer_x", "hammer_y", "hammer_z")):
        phi = truth.phi_in[k, k]
        assert res["modes"][k]["modal_mass_kg"][inp] == pytest.approx(1 / phi**2, rel=0.02)
    assert res["stabilisation"]["n_poles"] > 0
    pngs = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert "stabilisation.png" in pngs and "cmif.png" in pngs and len(pngs) == 5


def test_cli_virtual_test_then_modes_table(tmp_path):
    out = tmp_path / "v.uff"
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(out), "--noise", "0.02",
                            "--hits", "3", "--directions", "x,y", "--duration-s", "4",
                            "--double-hit", "1,2", "--seed", "4"])
    assert r.exit_code == 0, r.output
    truth = json.loads((tmp_path / "v.uff.truth.json").read_text())
    assert truth["synthetic"] is True and len(truth["truth"]["input_names"]) == 2
    r = runner.invoke(app, ["identify", "modes", str(out), "--band-hz", "3", "60",
                            "--modes", "5", "--drop-flagged", "--out", str(tmp_path / "m.json")])
    assert r.exit_code == 0, r.output
    assert "double hit" in " ".join(r.stdout.split()) and "f (Hz)" in r.stdout
    res = json.loads((tmp_path / "m.json").read_text())
    assert res["hits"]["n_averages"] == [2, 3]
    assert len(res["modes"]) == 5


@pytest.mark.parametrize("args,msg", [
    (["--band-hz", "200", "300"], "outside the data"),
    (["--band-hz", "100", "200"], "extends beyond the data"),
    (["--max-order", "0"], "max order"),
    (["--approx-hz", "7,abc"], "--approx-hz"),
    (["--approx-hz", "40"], "no stable pole cluster"),
    (["--frf-type", "bogus"], "'--frf-type': unknown FRF type"),
])
def test_cli_bad_options_exit_2(args, msg):
    r = runner.invoke(app, ["identify", "modes", "--example", *args])
    assert r.exit_code == 2, r.output
    assert msg in " ".join(r.output.split())


def test_cli_input_errors_exit_2(tmp_path):
    def flat(r):  # rich wraps long lines
        return " ".join(r.output.split())

    r = runner.invoke(app, ["identify", "modes"])
    assert r.exit_code == 2 and "INPUT or --example" in flat(r)
    r = runner.invoke(app, ["identify", "modes", str(tmp_path / "nope.npz")])
    assert r.exit_code == 2 and "file not found" in flat(r)
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(tmp_path / "x.uff"),
                            "--directions", "x,w"])
    assert r.exit_code == 2 and "--directions" in flat(r)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 30000), st.lists(st.tuples(st.integers(0, 29999), st.integers(0, 255)),
                                        max_size=8))
def test_uff_reader_corrupt_or_truncated_gives_data_error(tmp_path_factory, cut, flips):
    """Truncated or corrupted UFF bytes: a DataError or a valid result, never another
    exception (property test over the bundled file's first 30 kB)."""
    raw = bytearray(example_path().read_bytes()[:30000])
    raw = raw[:cut]
    for pos, val in flips:
        if pos < len(raw):
            raw[pos] = val
    p = tmp_path_factory.mktemp("fuzz") / "x.uff"
    p.write_bytes(bytes(raw))
    try:
        out = read_uff(p)
    except DataError:
        return
    assert isinstance(out, HammerRecords | FRFData)


def test_cli_npz_input_and_exp_window(tmp_path):
    truth = robot_boring_truth()
    rec = simulate_hammer_test(truth, n_hits=3, duration_s=3.0, seed=2)
    d = estimate_frf(rec).frf
    save_npz(d, tmp_path / "f.npz")
    r = runner.invoke(app, ["identify", "modes", str(tmp_path / "f.npz"), "--band-hz", "3",
                            "60", "--json"])
    assert r.exit_code == 0, r.output
    assert len(json.loads(r.stdout)["modes"]) == 5
    r = runner.invoke(app, ["identify", "modes", str(tmp_path / "f.npz"),
                            "--exp-window-tau-s", "0.5"])
    assert r.exit_code == 2 and "time records only" in " ".join(r.output.split())
    write_uff_time(rec, tmp_path / "t.uff")
    r = runner.invoke(app, ["identify", "modes", str(tmp_path / "t.uff"), "--band-hz", "3",
                            "60", "--exp-window-tau-s", "1.0", "--estimator", "Hv", "--json"])
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)
    assert res["exp_window_tau_s"] == 1.0
    z = np.array([m["damping_ratio"] for m in res["modes"]])
    np.testing.assert_array_less(np.abs(z / truth.damping_ratios - 1), 0.10)


@pytest.mark.parametrize("change,words", [
    ("real", "the FRF array is real (magnitudes only?)"),
    ("zero", "every FRF value is zero"),
    ("two lines", "fewer than 8 frequency lines"),
])
def test_npz_frf_that_cannot_hold_modes_is_refused_naming_the_file(tmp_path, change, words):
    frf = estimate_frf(load_input(example_path())).frf
    f, h = frf.frequency_Hz, frf.frf
    if change == "real":
        h = np.abs(h)
    elif change == "zero":
        h = np.zeros_like(h)
    else:
        f, h = f[:2], h[..., :2]
    p = tmp_path / "frf.npz"
    np.savez(p, frequency_Hz=f, frf=h, frf_type=np.array(frf.frf_type))
    r = runner.invoke(app, ["identify", "modes", str(p)])
    assert r.exit_code == 2, r.output
    line = " ".join(r.output.split())
    assert str(p) in line and words in line, line
