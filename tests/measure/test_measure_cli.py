"""The measure stage's commands: JSON contract, table, plots, one-line errors."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from robobore.cli import app
from robobore.measure.cut import synthetic_force_record, write_dynoware_ascii
from robobore.measure.records import write_record_csv
from robobore.measure.synthetic import simulated_record

runner = CliRunner()


def test_detect_chatter_json_table_and_plot(tmp_path):
    rec = simulated_record(0, duration_s=2.0)
    p = write_record_csv(rec, tmp_path / "acc.csv")
    r = runner.invoke(app, ["detect", "chatter", str(p), "--json", "--plot", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["chatter"] == rec.truth["chatter"]
    assert {"chatter", "chatter_frequency_Hz", "onset_s", "windows"} <= set(d)
    assert {"t0_s", "t1_s", "chatter"} <= set(d["windows"][0])
    assert (tmp_path / "chatter_spectrogram.png").stat().st_size > 0
    r = runner.invoke(app, ["detect", "chatter", str(p), "--speed-rpm",
                            str(rec.truth["speed_rpm"])])
    assert r.exit_code == 0 and "verdict" in r.stdout


def test_detect_chatter_bad_file_is_one_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("time_s,acc\n" + "\n".join(f"{0.001 * i},{'nan' if i == 9 else 0}"
                                             for i in range(100)))
    r = runner.invoke(app, ["detect", "chatter", str(p)])
    assert r.exit_code == 2
    assert "row 10" in r.output and "acc" in r.output and "Traceback" not in r.output


def test_measure_cut_json(tmp_path):
    p = write_dynoware_ascii(synthetic_force_record(), tmp_path / "cut.txt")
    r = runner.invoke(app, ["measure", "cut", str(p), "--speed-rpm", "300", "--json",
                            "--plot", str(tmp_path / "figs")])
    assert r.exit_code == 0, r.output
    q = json.loads(r.stdout)["records"][0]
    assert {"force_mean_N", "force_amplitude_N", "force_amplitude_overall_N", "per_revolution",
            "chatter", "chatter_frequency_Hz", "cutting_time_s", "speed_rpm"} <= set(q)
    assert len(q["plots"]) == 2


def test_detect_chatter_with_modes_file(tmp_path):
    rec = simulated_record(0, duration_s=2.0)  # chatters near its mode
    p = write_record_csv(rec, tmp_path / "acc.csv")
    m = tmp_path / "m.json"
    m.write_text(json.dumps({"modes": [{"frequency_Hz": rec.truth["mode_Hz"]}]}))
    r = runner.invoke(app, ["detect", "chatter", str(p), "--modes-file", str(m), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["chatter"] is rec.truth["chatter"] is True
    assert d["nearest_mode_Hz"] == rec.truth["mode_Hz"]
    m.write_text(json.dumps({"modes": [{"frequency_Hz": "abc"}]}))
    r = runner.invoke(app, ["detect", "chatter", str(p), "--modes-file", str(m)])
    assert r.exit_code == 2 and "frequency_Hz" in r.output


def test_synthetic_low_speed_record_and_its_verdict(tmp_path):
    p = tmp_path / "low.csv"
    r = runner.invoke(app, ["measure", "synthetic", str(p), "--seed", "5003", "--low-speed",
                            "--json"])
    assert r.exit_code == 0, r.output
    truth = json.loads(r.stdout)["truth"]
    assert 150.0 <= truth["speed_rpm"] <= 1000.0 and truth["speed_range_rpm"] == [150.0, 1000.0]
    r = runner.invoke(app, ["detect", "chatter", str(p), "--json", "--speed-rpm",
                            str(truth["speed_rpm"])])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["chatter"] == truth["chatter"]


def test_detect_chatter_sends_a_dynoware_export_to_measure_cut(tmp_path):
    """A rotating bar's forces on a fixed dynamometer turn once per revolution (one line,
    no harmonics): `measure cut` finds the speed from them and judges the cut; `detect
    chatter` names that command instead of a verdict of its own."""
    p = write_dynoware_ascii(synthetic_force_record(), tmp_path / "cut.txt")
    r = runner.invoke(app, ["detect", "chatter", str(p)])
    assert r.exit_code != 0 and "measure cut" in r.output and "DynoWare" in r.output
    r = runner.invoke(app, ["measure", "cut", str(p), "--json"])
    assert r.exit_code == 0, r.output
