"""Record readers: CSV, NPZ, WAV, UFF 58, DynoWare with decimal commas; one detection per format."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.measure.cut import read_cut_record
from robobore.measure.detect import detect_chatter
from robobore.measure.records import make_record, read_record, write_record_csv

FS = 8000.0


def _signal():
    t = np.arange(int(2 * FS)) / FS
    rng = np.random.default_rng(1)
    return (np.sin(2 * np.pi * 20 * t) + 0.5 * np.sin(2 * np.pi * 40 * t)
            + 2.0 * np.sin(2 * np.pi * 987.0 * t) + 0.01 * rng.standard_normal(t.size))


def _check(rec):
    d = detect_chatter(rec)
    assert d.chatter and d.chatter_frequency_Hz == pytest.approx(987.0, rel=1e-3)


def test_csv_roundtrip_and_sample_rate_option(tmp_path):
    rec = make_record(_signal(), FS, ["acc"], ["m/s^2"])
    p = write_record_csv(rec, tmp_path / "r.csv")
    back = read_record(p)
    assert back.sample_rate_Hz == pytest.approx(FS, rel=1e-9)
    assert back.channels == ("acc",) and back.units == ("m/s^2",)
    _check(back)
    q = tmp_path / "nt.csv"
    q.write_text("acc\n" + "\n".join(f"{v:.9g}" for v in _signal()))
    _check(read_record(q, sample_rate_Hz=FS))


def test_npz_and_wav(tmp_path):
    from scipy.io import wavfile

    x = _signal()
    np.savez(tmp_path / "r.npz", acc=x, sample_rate_Hz=FS)
    _check(read_record(tmp_path / "r.npz"))
    wavfile.write(tmp_path / "r.wav", int(FS), (x / 4 * 32767).astype(np.int16))
    rec = read_record(tmp_path / "r.wav")
    assert rec.sample_rate_Hz == FS and rec.n_channels == 1
    _check(rec)


def test_uff58_time_records(tmp_path):
    import pyuff

    x = _signal()
    p = tmp_path / "r.uff"
    u = pyuff.UFF(str(p))
    u.write_sets([dict(type=58, binary=0, id1="acc", id2="acc", id3="", id4="", id5="",
                       func_type=1, ver_num=0, load_case_id=0, rsp_ent_name="acc", rsp_node=1,
                       rsp_dir=1, ref_ent_name="ref", ref_node=1, ref_dir=1, ord_data_type=4,
                       num_pts=x.size, abscissa_spacing=1, abscissa_min=0.0,
                       abscissa_inc=1 / FS, abscissa_spec_data_type=17,
                       ordinate_spec_data_type=12, orddenom_spec_data_type=0,
                       z_axis_spec_data_type=0, data=x, x=np.arange(x.size) / FS)],
                 mode="overwrite", force_double=True)
    rec = read_record(p)
    assert rec.sample_rate_Hz == pytest.approx(FS, rel=1e-6)
    _check(rec)


def test_dynoware_semicolon_decimal_comma(tmp_path):
    t = np.arange(4000) / 2000.0
    fx = 100 * np.cos(2 * np.pi * 5 * t)
    lines = ["File:;test.dwd", "Sampling rate [Hz]:;2000", "",
             "Time [s];Fx [N];Fy [N];Fz [N]"]
    lines += [f"{a:.4f};{b:.3f};{-b:.3f};{30.0:.3f}".replace(".", ",")
              for a, b in zip(t, fx, strict=True)]
    p = tmp_path / "d.txt"
    p.write_text("\n".join(lines) + "\n", encoding="latin-1")
    rec = read_cut_record(p)
    assert rec.channels == ("Fx", "Fy", "Fz") and rec.sample_rate_Hz == pytest.approx(2000)
    assert rec.signals[2].mean() == pytest.approx(30.0)


def _write(path, header, rows):
    path.write_text(header + "".join(rows), encoding="utf-8")
    return path


@pytest.mark.parametrize("layout", ["quoted", "r_index", "pandas_index", "decimal_comma",
                                    "trailing_separator", "tab_quoted"])
def test_csv_as_data_frames_and_spreadsheets_write_it(tmp_path, layout):
    """The same record written as R (``write.csv``: quoted header, quoted row names),
    pandas (``to_csv`` with its index), a comma-decimal spreadsheet (``;``) and exports
    with a trailing separator: read as one ``acc`` channel at the same rate."""
    x = _signal()
    t = np.arange(x.size) / FS
    rows = {
        "quoted": ('"time_s","acc"\n', [f'"{a:.7f}","{b:.9g}"\n' for a, b in zip(t, x)]),
        "r_index": ('"","time_s","acc"\n',
                    [f'"{i + 1}",{a:.7f},{b:.9g}\n' for i, (a, b) in enumerate(zip(t, x))]),
        "pandas_index": (",time_s,acc\n",
                         [f"{i},{a:.7f},{b:.9g}\n" for i, (a, b) in enumerate(zip(t, x))]),
        "decimal_comma": ("time_s;acc\n",
                          [f"{a:.7f};{b:.9g}\n".replace(".", ",") for a, b in zip(t, x)]),
        "trailing_separator": ("time_s,acc,\n", [f"{a:.7f},{b:.9g},\n" for a, b in zip(t, x)]),
        "tab_quoted": ('"time_s"\t"acc"\n', [f"{a:.7f}\t{b:.9g}\n" for a, b in zip(t, x)]),
    }[layout]
    rec = read_record(_write(tmp_path / f"{layout}.csv", *rows))
    assert rec.channels == ("acc",)
    assert rec.sample_rate_Hz == pytest.approx(FS, rel=1e-9)
    np.testing.assert_allclose(rec.signals[0], x, rtol=1e-8, atol=1e-8)
    _check(rec)


def test_csv_unnamed_signal_column_is_kept_and_bad_quoted_cell_named(tmp_path):
    x = _signal()
    t = np.arange(x.size) / FS
    rec = read_record(_write(tmp_path / "u.csv", "time_s,\n",
                             [f"{a:.7f},{b:.9g}\n" for a, b in zip(t, x)]))
    assert rec.channels == ("column 2",)  # not a row index: its values do not count 0, 1, ..
    rows = [f'"{a:.7f}","{b:.9g}"\n' for a, b in zip(t, x)]
    rows[41] = f'"{t[41]:.7f}","1.2.3"\n'
    from robobore.errors import DataError

    with pytest.raises(DataError) as e:
        read_record(_write(tmp_path / "bad.csv", '"time_s","acc"\n', rows))
    assert e.value.row == 42 and e.value.field == "acc" and "1.2.3" in str(e.value)


def test_times_written_with_few_decimals(tmp_path):
    """25.6 kHz with the times written to 1e-5 s (steps of 3.9e-5 s off by up to 26 %): read
    at the rate the times say; a missing sample is still refused."""
    from robobore.errors import DataError

    fs = 25600.0
    x = np.sin(2 * np.pi * 987.0 * np.arange(int(fs)) / fs)
    t = np.arange(x.size) / fs
    rows = [f"{a:.5f},{b:.9g}\n" for a, b in zip(t, x)]
    rec = read_record(_write(tmp_path / "q.csv", "time_s,acc\n", rows))
    assert rec.sample_rate_Hz == pytest.approx(fs, rel=1e-6)
    del rows[5000]
    with pytest.raises(DataError, match="not uniformly sampled") as e:
        read_record(_write(tmp_path / "gap.csv", "time_s,acc\n", rows))
    assert e.value.row == 5001


def test_a_row_with_an_extra_cell_is_named(tmp_path):
    from robobore.errors import DataError

    x = _signal()
    t = np.arange(x.size) / FS
    rows = [f"{a:.7f},{b:.9g}\n" for a, b in zip(t, x)]
    rows[9] = rows[9].rstrip("\n") + ",\n"
    with pytest.raises(DataError, match="row has 3 cells") as e:
        read_record(_write(tmp_path / "x.csv", "time_s,acc\n", rows))
    assert e.value.row == 10


def test_time_in_an_unknown_unit_is_refused(tmp_path):
    from robobore.errors import DataError

    rows = [f"{i / 60.0 / FS:.9f},{v:.9g}\n" for i, v in enumerate(_signal())]
    with pytest.raises(DataError, match="unknown time unit") as e:
        read_record(_write(tmp_path / "min.csv", "time [min],acc\n", rows), sample_rate_Hz=FS)
    assert e.value.field == "time [min]" and e.value.value == "min"
