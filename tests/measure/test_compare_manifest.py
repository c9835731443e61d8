"""compare with a manifest of raw record files: the measured side computed by measure cut."""

from __future__ import annotations

import math

import pytest

from robobore.errors import DataError
from robobore.measure.cut import synthetic_force_record, write_dynoware_ascii
from robobore.measure.records import write_record_csv
from robobore.study.compare import compare, read_measured_csv


def _records(tmp_path):
    (tmp_path / "rec").mkdir()
    f = synthetic_force_record(speed_rpm=300.0, noise_N=0.0, feed_amplitude_um=None)
    write_dynoware_ascii(f, tmp_path / "rec" / "force1.txt")
    d = synthetic_force_record(speed_rpm=300.0, noise_N=0.0, feed_amplitude_um=4.0, seed=1)
    write_record_csv(d, tmp_path / "rec" / "disp1.csv")


def test_manifest_measures_its_records_and_compares(tmp_path):
    _records(tmp_path)
    m = tmp_path / "manifest.csv"
    m.write_text("speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa,stable,force_file,"
                 "displacement_file\n300,0.15,0.05,0,true,rec/force1.txt,rec/disp1.csv\n")
    table = read_measured_csv(m)
    vals = table.rows[0].values
    amp = math.hypot(120.0, 60.0)
    assert vals["force_amplitude_x_N"] == pytest.approx(amp, rel=2e-3)
    assert vals["feed_amplitude_um"] == pytest.approx(4.0, rel=2e-3)
    assert vals["stable"] is True
    assert table.records[0]["force_file"]["chatter"] is False
    sim = [({"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
             "pressure_MPa": 0.0}, {"force_amplitude_x_N": 1.1 * amp, "feed_amplitude_um": 4.0,
                                    "stable": True})]
    cmp = compare(table, sim)
    q = cmp.rows[0]["quantities"]
    assert q["force_amplitude_x_N"]["rel_error"] == pytest.approx(0.1, rel=5e-3)
    assert q["feed_amplitude_um"]["rel_error"] == pytest.approx(0.0, abs=3e-3)


def test_manifest_errors_name_row_and_column(tmp_path):
    _records(tmp_path)
    m = tmp_path / "manifest.csv"
    m.write_text("speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa,force_file\n"
                 "300,0.15,0.05,0,rec/force1.txt\n300,0.15,0.1,0,rec/missing.txt\n")
    with pytest.raises(DataError) as e:
        read_measured_csv(m)
    assert e.value.row == 2 and e.value.field == "force_file" and e.value.value == "rec/missing.txt"
    m.write_text("speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa,force_file,"
                 "feed_amplitude_um\n300,0.15,0.05,0,rec/force1.txt,3\n")
    with pytest.raises(DataError) as e:
        read_measured_csv(m)
    assert e.value.field == "feed_amplitude_um" and "computed" in str(e.value)
