"""UFF files as commercial systems write them: every variant pyuff can produce (ASCII 58 and
binary 58b, real/complex, single/double precision, even/uneven abscissa; 55, 151, 164),
units, coherence and other function types, truncated and mixed-endian records."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from robobore.errors import DataError
from robobore.modal.io import UFFWarning, read_uff, read_uff_modes


def _write(path, sets, force_double=True):
    import pyuff

    path.unlink(missing_ok=True)
    uff = pyuff.UFF(str(path))
    uff.write_sets(sets, mode="add", force_double=force_double)
    return path


def _units(length=1.0, force=1.0):
    return {"type": 164, "units_code": 1, "units_description": "user", "temp_mode": 2,
            "length": length, "force": force, "temp": 1.0, "temp_offset": 273.15}


def _header():
    return {"type": 151, "model_name": "tool point", "description": "SYNTHETIC test file",
            "db_app": "robobore", "date_db_created": "01-Jan-26", "time_db_created": "00:00:00",
            "version_db1": 1, "version_db2": 0, "file_type": 0, "date_db_saved": "01-Jan-26",
            "time_db_saved": "00:00:00", "program": "pytest", "date_file_written": "01-Jan-26",
            "time_file_written": "00:00:00"}


F = np.linspace(10.0, 200.0, 96)
H = np.array([[1.0 / (100.0**2 - F**2 + 2j * 0.02 * 100.0 * F) * (1 + k)] for k in range(2)])
COH = np.clip(0.9 + 0.1 * np.cos(F / 30.0), 0, 1)


def _frf_sets(binary, odt, spacing, func=4, exps=None, label="NONE", data=None, coh=False):
    sets = []
    for o in range(2):
        d = dict(type=58, binary=binary, id1="SYNTHETIC", id2=f"o{o + 1}/hammer", id3="NONE",
                 id4="NONE", id5="NONE", func_type=func, ver_num=0, load_case_id=0,
                 rsp_ent_name="rsp", rsp_node=o + 1, rsp_dir=1, ref_ent_name="ref",
                 ref_node=1, ref_dir=1, ord_data_type=odt, num_pts=F.size,
                 abscissa_spacing=spacing, abscissa_min=float(F[0]),
                 abscissa_inc=float(F[1] - F[0]), abscissa_spec_data_type=18,
                 ordinate_spec_data_type=8, orddenom_spec_data_type=13,
                 z_axis_spec_data_type=0, ordinate_axis_units_lab=label,
                 data=(H[o, 0] if data is None else data[o]).astype(complex), x=F.copy())
        if exps:
            d.update(exps)
        sets.append(d)
        if coh:
            c = dict(d, func_type=6, ord_data_type=4, data=COH.copy(), id2=f"coh o{o + 1}")
            sets.append(c)
    return sets


@pytest.mark.parametrize("binary", [0, 1])
@pytest.mark.parametrize("odt", [5, 6])
@pytest.mark.parametrize("spacing", [0, 1])
def test_frf_every_variant_reads_back(tmp_path, binary, odt, spacing):
    p = tmp_path / "frf.uff"
    _write(p, [_units()] + _frf_sets(binary, odt, spacing), force_double=False)
    if binary and odt == 5:
        # pyuff writes binary data in double precision whatever the header says
        with pytest.raises(DataError, match="single precision .* double-precision"):
            read_uff(p)
        return
    d = read_uff(p)
    tol = 1e-5 if odt == 5 and not binary else 1e-10
    np.testing.assert_allclose(d.frequency_Hz, F, rtol=tol)
    np.testing.assert_allclose(d.frf, H, rtol=tol * 10, atol=tol * np.abs(H).max())
    assert d.frf_type == "receptance" and d.driving_points() == [(0, 0)]


@pytest.mark.parametrize("binary", [0, 1])
@pytest.mark.parametrize("odt", [2, 4])
def test_time_records_ascii_and_binary(tmp_path, binary, odt):
    n, dt = 256, 1.0 / 512
    t = np.arange(n) * dt
    force = 100 * np.exp(-((t - 0.02) / 0.002) ** 2)
    acc = np.exp(-5 * t) * np.sin(2 * np.pi * 40 * t)

    def rec(data, sp, node, name):
        return dict(type=58, binary=binary, id1="SYNTHETIC", id2=name, id3="hit 1",
                    id4="NONE", id5="NONE", func_type=1, ver_num=0, load_case_id=1,
                    rsp_ent_name=name[:10], rsp_node=node, rsp_dir=3, ref_ent_name="hammer",
                    ref_node=1, ref_dir=3, ord_data_type=odt, num_pts=n, abscissa_spacing=1,
                    abscissa_min=0.0, abscissa_inc=dt, abscissa_spec_data_type=17,
                    ordinate_spec_data_type=sp, orddenom_spec_data_type=0,
                    z_axis_spec_data_type=0, data=data, x=t)

    p = _write(tmp_path / "t.uff", [_header(), _units(length=1000.0)]
               + [rec(force, 13, 1, "hammer_z"), rec(1000 * acc, 12, 2, "tip_z")],
               force_double=False)
    if binary and odt == 2:
        with pytest.raises(DataError, match="single precision"):
            read_uff(p)
        return
    r = read_uff(p)
    tol = 1e-5 if odt == 2 else 1e-10
    np.testing.assert_allclose(r.force[0, 0], force, rtol=tol, atol=tol * 100)
    # mm/s^2 in the file (164 length factor 1000) -> m/s^2
    np.testing.assert_allclose(r.response[0, 0, 0], acc, rtol=tol, atol=tol)
    assert r.meta["header"]["model_name"] == "tool point"


def test_units_exponents_g_label_and_coherence(tmp_path):
    # FRF in mm/N written with explicit exponents (length 1 over force 1), 164: mm, N
    exps = {"ordinate_len_unit_exp": 1, "orddenom_force_unit_exp": 1}
    p = _write(tmp_path / "u.uff", [_units(length=1000.0)]
               + _frf_sets(1, 6, 1, exps=exps, data=1000 * H[:, 0], coh=True))
    d = read_uff(p)
    np.testing.assert_allclose(d.frf, H, rtol=1e-10)
    np.testing.assert_allclose(d.coherence[:, 0], np.vstack([COH, COH]), rtol=1e-10)
    # accelerance in g/N
    sets = _frf_sets(0, 6, 1, label="g/N", data=H[:, 0] / 9.80665)
    for s in sets:
        s["ordinate_spec_data_type"] = 12
    d = read_uff(_write(tmp_path / "g.uff", [_units()] + sets))
    assert d.frf_type == "accelerance"
    np.testing.assert_allclose(d.frf, H, rtol=1e-9)


def test_other_function_types_are_named(tmp_path):
    p = _write(tmp_path / "psd.uff", [_units()] + _frf_sets(1, 4, 1, func=9,
                                                          data=np.abs(H[:, 0])))
    with pytest.raises(DataError) as e:
        read_uff(p)
    msg = str(e.value)
    assert "function type 9 (power spectral density)" in msg and "robobore reads" in msg
    assert "dataset 164 (units)" in msg
    # FRFs beside a PSD and nodes: the FRFs are read, the rest named in a warning
    nodes = {"type": 15, "node_nums": [1, 2], "def_cs": [0, 0], "disp_cs": [0, 0],
             "color": [1, 1], "x": [0.0, 1.0], "y": [0.0, 0.0], "z": [0.0, 0.0]}
    p = _write(tmp_path / "mix.uff", [_units(), nodes] + _frf_sets(1, 6, 1)
               + _frf_sets(1, 4, 1, func=9, data=np.abs(H[:, 0])))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always", UFFWarning)
        d = read_uff(p)
    np.testing.assert_allclose(d.frf, H, rtol=1e-10)
    text = " ".join(str(x.message) for x in w)
    assert "power spectral density" in text and "dataset 15 (nodes)" in text


def test_dataset_55_mode_shapes(tmp_path):
    nodes = np.array([1, 2, 3])
    sets = [_units(length=1000.0)]
    for k, (f, z) in enumerate([(100.0, 0.02), (250.0, 0.05)]):
        shape = np.array([1.0, 0.5, -0.3]) * (k + 1) * 1000
        sets.append(dict(type=55, id1="SYNTHETIC", id2="NONE", id3="NONE", id4="NONE",
                         id5="NONE", model_type=1, analysis_type=2, data_ch=2,
                         spec_data_type=8, data_type=2, n_data_per_node=3, r1=shape,
                         r2=0 * shape, r3=0 * shape, load_case=1, mode_n=k + 1, freq=f,
                         modal_m=1.0, modal_damp_vis=z, modal_damp_his=0.0,
                         node_nums=nodes))
    modes = read_uff_modes(_write(tmp_path / "m.uff", sets))
    assert [m["mode"] for m in modes] == [1, 2]
    assert modes[1]["frequency_Hz"] == pytest.approx(250.0)
    assert modes[1]["damping_ratio"] == pytest.approx(0.05)
    np.testing.assert_allclose(modes[1]["shape"][:, 0], [2.0, 1.0, -0.6])
    with pytest.raises(DataError, match="no dataset 58") as e:
        read_uff(tmp_path / "m.uff")
    assert "dataset 55 (data at nodes (mode shapes))" in str(e.value)


def _binary_records(raw: bytes) -> list[tuple[int, int, int]]:
    """(header start, data start, data end) of each 58b record of ``raw``."""
    out = []
    pos = 0
    while True:
        h = raw.find(b"    58b", pos)
        if h < 0:
            return out
        s = h
        for _ in range(12):
            s = raw.index(b"\n", s) + 1
        e = raw.index(b"    -1\n", s)
        out.append((h, s, e))
        pos = e


def _big_endian(raw: bytes, k: int, relabel: bool) -> bytes:
    h, s, e = _binary_records(raw)[k]
    payload = np.frombuffer(raw[s:e], "<f8").astype(">f8").tobytes()
    head = raw[h:s]
    if relabel:
        head = head[:12] + b"2" + head[13:]
    return raw[:h] + head + payload + raw[e:]


def test_mixed_endian_records(tmp_path):
    p = _write(tmp_path / "le.uff", [_units()] + _frf_sets(1, 6, 1))
    raw = p.read_bytes()
    ok = tmp_path / "mixed.uff"
    ok.write_bytes(_big_endian(raw, 1, relabel=True))  # record 2 big-endian, says so
    np.testing.assert_allclose(read_uff(ok).frf, H, rtol=1e-12)
    bad = tmp_path / "lying.uff"
    bad.write_bytes(_big_endian(raw, 1, relabel=False))  # big-endian data, header says little
    with pytest.raises(DataError, match="byte order does not match its header") as e:
        read_uff(bad)
    assert "record 2" in str(e.value)


def test_truncated_record_inside_a_complete_file(tmp_path):
    p = _write(tmp_path / "a.uff", [_units()] + _frf_sets(0, 6, 1))
    lines = p.read_text().splitlines(keepends=True)
    # drop two data lines of the first record (the file still ends with "-1")
    first = next(i for i, ln in enumerate(lines) if ln.startswith("    58"))
    del lines[first + 14: first + 16]
    p.write_text("".join(lines))
    with pytest.raises(DataError, match="its header declares 96") as e:
        read_uff(p)
    assert "record 1" in str(e.value)
