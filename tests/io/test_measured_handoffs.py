"""Measured-signal and modal inputs the malformed corpus (benchmarks/
malformed_corpus_measured.py) found ending badly: SYNTHETIC records read back as measured,
a time column in ms, a broken WAV, a record of a constant signal, a manifest with another
separator or a row without records, the virtual hammer test's robot given twice, the API
given a hammer-test path."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import DataError, RoboboreError

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]
EX = REPO / "examples"


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp("rec")
    for kind, name in (("vibration", "vib.csv"), ("force", "force.csv")):
        r = runner.invoke(app, ["measure", "synthetic", str(d / name), "--kind", kind,
                                "--duration-s", "1"])
        assert r.exit_code == 0, r.output
    return d


def test_synthetic_records_are_read_back_as_synthetic(records):
    from robobore.measure.cut import read_cut_record
    from robobore.measure.records import read_record

    assert read_record(records / "vib.csv").kind == "SYNTHETIC"
    assert read_cut_record(records / "force.csv").kind == "SYNTHETIC"
    plain = records / "plain.csv"
    plain.write_text("\n".join(ln for ln in (records / "vib.csv").read_text().splitlines()
                               if not ln.startswith("#")) + "\n")
    assert read_record(plain).kind == "measured"


def test_time_column_in_ms_read_as_s_refused(records):
    from robobore.measure.records import read_record

    lines = (records / "vib.csv").read_text().splitlines()
    h = next(i for i, ln in enumerate(lines) if ln.startswith("time_s"))
    body = [f"{float(r.split(',')[0]) * 1e3:g},{r.split(',')[1]}" for r in lines[h + 1:]]
    f = records / "ms.csv"
    f.write_text("\n".join(lines[:h + 1] + body) + "\n")
    with pytest.raises(DataError, match="ms read as s") as ei:
        read_record(f)
    assert str(f) in str(ei.value)


def test_broken_wav_is_a_clear_error(tmp_path):
    from robobore.measure.records import read_record

    f = tmp_path / "x.wav"
    f.write_bytes(b"RIFF\x00\x00\x00\x00WAVEjunk")
    with pytest.raises(DataError, match="not a readable WAV"):
        read_record(f)


def test_cut_record_of_constant_channels_refused(records):
    from robobore.measure.cut import cut_quantities, read_cut_record

    rec = read_cut_record(records / "force.csv")
    import dataclasses

    flat = dataclasses.replace(rec, signals=np.ones_like(rec.signals) * 0.01)
    with pytest.raises(DataError, match="constant"):
        cut_quantities(flat, 300.0)


def _manifest(records: Path, name: str, text: str) -> Path:
    p = records / name
    p.write_text(text)
    return p


HDR = "speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa,stable,force_file"


def test_manifest_with_semicolons_is_read_and_a_row_without_records_refused(records):
    from robobore.study.compare import read_measured_csv

    ok = _manifest(records, "m_semi.csv", f"{HDR}\n300,0.15,0.05,0,true,force.csv\n"
                   .replace(",", ";"))
    t = read_measured_csv(ok)
    assert t.records and t.records[0]["force_file"]["kind"] == "SYNTHETIC"
    empty = _manifest(records, "m_empty.csv", f"{HDR}\n300,0.15,0.05,0,true,\n"
                      "400,0.15,0.05,0,true,force.csv\n")
    with pytest.raises(DataError, match="no record file in this row") as ei:
        read_measured_csv(empty)
    assert ei.value.row == 1


def test_virtual_hammer_test_robot_given_twice_refused(tmp_path):
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(tmp_path / "h.uff"),
                            "--robot", "irb6600-175-2.55", "--robot-file",
                            str(EX / "robots" / "kr240-r2900.toml"),
                            "--joints-deg", "20,20,10,0,-30,0"])
    assert r.exit_code == 2 and "--robot" in r.output and "not both" in r.output


def test_virtual_hammer_test_robot_without_links_names_the_file(tmp_path):
    kt = (EX / "robots" / "kr240-r2900.toml").read_text()
    f = tmp_path / "nolinks.toml"
    f.write_text(kt[:kt.find("\n[[links]]")])
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(tmp_path / "h.uff"),
                            "--robot-file", str(f), "--joints-deg", "20,20,10,0,-30,0",
                            "--joint-stiffness-Nm-per-rad", "3e6,4e6,2.5e6,5e5,4.5e5,3e5"])
    assert r.exit_code == 2
    assert "nolinks.toml" in " ".join(r.output.split())


def test_api_identify_modes_reads_a_path_and_names_a_missing_one(tmp_path):
    from robobore import api

    with pytest.raises(RoboboreError, match="nope.uff"):
        api.identify_modes(str(tmp_path / "nope.uff"))


def test_uff_with_a_comment_line_and_csv_body_named_csv(records, tmp_path):
    from robobore.modal.io import load_input

    f = tmp_path / "x.uff"
    f.write_text((records / "vib.csv").read_text())
    with pytest.raises(DataError, match="CSV"):
        load_input(f)
