"""Bad input to the measure stage: each refused with file, row/column, value, expectation."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.errors import DataError, InputError
from robobore.measure.cut import (
    cut_quantities,
    read_cut_record,
    synthetic_force_record,
    write_dynoware_ascii,
)
from robobore.measure.detect import DetectSettings, detect_chatter
from robobore.measure.records import read_record


def _csv(tmp_path, t, x, name="r.csv"):
    p = tmp_path / name
    rows = "\n".join(f"{float(a)!r},{float(b)!r}" for a, b in zip(t, x, strict=True))
    p.write_text("time_s,acc\n" + rows + "\n")
    return p


def test_decreasing_time(tmp_path):
    t = np.arange(200) / 1000.0
    t[50] = t[48]
    with pytest.raises(DataError) as e:
        read_record(_csv(tmp_path, t, np.zeros(200)))
    assert e.value.row == 51 and e.value.field == "time_s" and "increase" in str(e.value)


def test_non_uniform_time(tmp_path):
    t = np.arange(200) / 1000.0
    t[100:] += 0.0005  # a step of 1.5 ms among 1 ms steps
    with pytest.raises(DataError) as e:
        read_record(_csv(tmp_path, t, np.zeros(200)))
    assert e.value.row == 101 and "uniformly" in str(e.value) and "s" in e.value.expected


def test_nan_sample(tmp_path):
    x = np.zeros(200)
    x[17] = np.nan
    with pytest.raises(DataError) as e:
        read_record(_csv(tmp_path, np.arange(200) / 1000.0, x))
    assert e.value.row == 18 and e.value.field == "acc"


def test_one_sample(tmp_path):
    with pytest.raises(DataError) as e:
        read_record(_csv(tmp_path, [0.0], [1.0]))
    assert "samples" in e.value.expected


def test_not_a_number(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("time_s,acc\n0,1\n0.001,abc\n")
    with pytest.raises(DataError) as e:
        read_record(p)
    assert e.value.row == 2 and e.value.field == "acc" and e.value.value == "abc"


def test_sample_rate_below_twice_the_first_harmonic(tmp_path):
    rec = read_record(_csv(tmp_path, np.arange(200) / 100.0, np.sin(np.arange(200.0))))
    with pytest.raises(DataError) as e:
        detect_chatter(rec, DetectSettings(speed_rpm=6000.0))  # 100 Hz > fs / 2 = 50 Hz
    assert e.value.field == "sample_rate_Hz" and "200" in e.value.expected


def test_dynoware_missing_channel(tmp_path):
    p = write_dynoware_ascii(synthetic_force_record(duration_s=3.0), tmp_path / "d.txt")
    text = p.read_text().splitlines()
    i = next(k for k, ln in enumerate(text) if ln.startswith("Time [s]"))
    text[i] = "Time [s]\tFx [N]\tFy [N]\tMz [Nm]"
    p.write_text("\n".join(text) + "\n")
    with pytest.raises(DataError) as e:
        read_cut_record(p)
    assert e.value.field == "Fz" and str(p) in str(e.value) and "Fz [N]" in e.value.expected


def test_unknown_force_unit(tmp_path):
    p = tmp_path / "f.csv"
    p.write_text("time_s,Fx [lb],Fy [N]\n" + "\n".join(f"{i / 1000},1,2" for i in range(100)))
    with pytest.raises(DataError) as e:
        read_cut_record(p)
    assert e.value.field == "Fx [lb]" and "kN" in e.value.expected


def test_huge_record_refused_before_loading(tmp_path, monkeypatch):
    p = _csv(tmp_path, np.arange(2000) / 1000.0, np.zeros(2000))
    monkeypatch.setenv("ROBOBORE_MEMORY_LIMIT_BYTES", "10000")
    with pytest.raises(InputError) as e:
        read_record(p)
    assert "would need about" in str(e.value) and "MiB on disk" in str(e.value)


def test_unknown_format_and_bad_options(tmp_path):
    p = tmp_path / "r.xyz"
    p.write_text("1")
    with pytest.raises(DataError):
        read_record(p)
    rec = read_record(_csv(tmp_path, np.arange(500) / 1000.0, np.sin(np.arange(500.0))))
    with pytest.raises(InputError) as e:
        detect_chatter(rec, DetectSettings(window_s=100.0))
    assert e.value.field == "--window-s"
    with pytest.raises(DataError) as e:
        rec.channel("nope")
    assert "acc" in e.value.expected


def test_cut_record_too_short(tmp_path):
    rec = synthetic_force_record(duration_s=0.5, air_s=0.0)
    with pytest.raises(DataError) as e:
        cut_quantities(rec, 100.0)
    assert "3 revolutions" in str(e.value)


def test_missing_sample_is_non_uniform(tmp_path):
    t = np.delete(np.arange(400) / 1000.0, 150)
    with pytest.raises(DataError) as e:
        read_record(_csv(tmp_path, t, np.zeros(t.size)))
    assert "uniformly" in str(e.value) and e.value.row is not None


def test_float32_time_rounding_is_accepted(tmp_path):
    t = (29.0 + np.arange(2000) / 10000.0).astype(np.float32).astype(float)
    rec = read_record(_csv(tmp_path, t, np.sin(np.arange(2000.0))))
    assert rec.sample_rate_Hz == pytest.approx(10000.0, rel=1e-3)
