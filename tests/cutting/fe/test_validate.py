"""``robobore fe validate`` (robobore.cutting.fe.models.validate): the measured-forces reader and
its errors, the per-point config (only h and vc replaced), the --json contract, the resume of an
interrupted validation, and every input error found before the first FE run.

The runs use a tiny tool-frame config (20 um elements, 5 um round the edge, 20 um of tool
travel, one element: a few seconds a point); the measured values are made-up numbers in the
file format, so only the arithmetic of the comparison is checked here (the validation figures
of the validated model are in docs/fe.md)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.cutting.fe.models import validate as V
from robobore.cutting.fe.models.results import (
    MeasuredValues,
    PerQuantity,
    ValidationPoint,
    ValidationSummary,
)
from robobore.cutting.fe.models.validation_record import (
    _KINDS,
    ValidationRecord,
    bundled_validation_path,
    load_validation_record,
)
from robobore.errors import ConfigError, DataError

TINY = """\
[material]
name = "TC4"
[tool]
rake_deg = 15.0
clearance_deg = 2.0
edge_radius_um = 20.0
[cut]
uncut_chip_thickness_um = 60.0
cutting_speed_m_per_min = 30.0
length_mm = 0.02
[mesh]
element_size_um = 20.0
edge_element_um = 5.0
[solver]
n_samples = 20
"""

MEASURED = {
    "units": {"Fc": "N per mm of width", "Ff": "N per mm of width",
              "chip_ratio": "chip thickness / uncut chip thickness"},
    "measured": {"Fc": {"60": {"30": 118.0, "10": 130.0}, "80": {"30": 150.0}},
                 "Ff": {"60": {"30": 50.0, "10": 54.0}, "80": {"30": 53.0}},
                 "chip_ratio": {"60": {"30": 1.2}}},
}


def _files(tmp_path: Path, measured=None, config: str = TINY) -> tuple[Path, Path]:
    c = tmp_path / "tiny.toml"
    c.write_text(config)
    m = tmp_path / "meas.json"
    m.write_text(json.dumps(MEASURED if measured is None else measured))
    return c, m


def _no_run(*a, **k):
    raise AssertionError("an FE run started before the input error was found")


def test_reader_points_and_missing_quantities(tmp_path):
    _, m = _files(tmp_path)
    pts = V.read_measured(m)
    assert [(p.h_um, p.vc_m_per_min) for p in pts] == [(60.0, 10.0), (60.0, 30.0), (80.0, 30.0)]
    p = {(q.h_um, q.vc_m_per_min): q for q in pts}
    assert p[(60.0, 30.0)].chip_ratio == 1.2 and p[(80.0, 30.0)].chip_ratio is None
    assert p[(60.0, 10.0)].Fc == 130.0


@pytest.mark.parametrize("measured, field, words", [
    ({"measured": {"Fc": {"60": 118.0}}}, "measured.Fc.60", "missing cutting speed"),
    ({"measured": {"Fc": {"60": {}}}}, "measured.Fc.60", "missing cutting speed"),
    ({"measured": {"Fc": {"60": {"30": "abc"}}}}, "measured.Fc.60.30", "finite number"),
    ({"measured": {"Fc": {"60": {"30": True}}}}, "measured.Fc.60.30", "finite number"),
    ({"measured": {"Ff": {"60": {"fast": 50.0}}}}, "measured.Ff.60.fast", "number"),
    ({"measured": {"Fc": {"-60": {"30": 100.0}}}}, "measured.Fc.-60", "out of range"),
    ({"measured": {"Fz": {"60": {"30": 1.0}}}}, "measured.Fz", "unknown measured quantity"),
    ({"measured": {"Fc": {"60": {"30": 1e9}}}}, "measured.Fc.60.30", "finite number"),
    ({"units": {"Fc": "N"}, "measured": {"Fc": {"60": {"30": 100.0}}}}, "units.Fc", "unit"),
    # kN per mm of width is not N per mm ("n per mm" inside it); an inverted chip ratio
    ({"units": {"Fc": "kN per mm of width"}, "measured": {"Fc": {"60": {"30": 0.118}}}},
     "units.Fc", "kN: multiply"),
    ({"measured": {"Fc": {"60": {"30": 118.0}}, "chip_ratio": {"60": {"30": 0.55}}}},
     "measured.chip_ratio.60.30", "looks like the inverse"),
    ({"Fc": {}}, "measured", "no 'measured'"),
    ({"measured": {}}, "measured", "no measured point"),
    # Fc and Ff at different speeds: a speed missing under one of them
    ({"measured": {"Fc": {"60": {"30": 118.0, "10": 130.0}}, "Ff": {"60": {"30": 50.0}}}},
     "measured.Ff.60", "missing cutting speed: Ff has no value at h 60 um, vc 10"),
    ({"measured": {"Fc": {"60": {"30": 118.0}}, "Ff": {"60": {"30": 50.0}, "80": {"5": 9.0}}}},
     "measured.Fc.80", "missing cutting speed: Fc has no value at h 80 um, vc 5"),
    ({"measured": {"Fc": {"60": {"30": 118.0}}, "Ff": {"60": {"30": "50,3"}}}},
     "measured.Ff.60.30", "finite number"),
])
def test_bad_measured_file_names_file_key_value(tmp_path, measured, field, words):
    _, m = _files(tmp_path, measured)
    with pytest.raises(DataError, match=words) as e:
        V.read_measured(m)
    assert e.value.field == field and e.value.file == str(m)
    assert e.value.expected


def test_bad_json_and_missing_file(tmp_path):
    f = tmp_path / "x.json"
    f.write_text("{not json")
    with pytest.raises(DataError, match="not valid JSON"):
        V.read_measured(f)
    with pytest.raises(DataError, match="not found"):
        V.read_measured(tmp_path / "nope.json")


def test_point_config_replaces_only_h_and_vc():
    import tomllib

    base = tomllib.loads(TINY)
    d = V.point_config(base, 80.0, 10.0)
    assert d["cut"] == {**base["cut"], "uncut_chip_thickness_um": 80.0,
                        "cutting_speed_m_per_min": 10.0}
    assert {k: v for k, v in d.items() if k != "cut"} == \
        {k: v for k, v in base.items() if k != "cut"}
    assert base["cut"]["uncut_chip_thickness_um"] == 60.0  # the base is not changed


@pytest.mark.parametrize("text", ["60", "60:", "a:30", "60:-5", "60:30,60:30"])
def test_bad_points_option(text):
    with pytest.raises(ConfigError, match="--points"):
        V.parse_points(text)


def test_config_errors_before_any_run(tmp_path, monkeypatch):
    import tomllib

    monkeypatch.setattr("robobore.cutting.fe.models.orthogonal.simulate_orthogonal", _no_run)
    base = tomllib.loads(TINY)
    # a point whose chip is too thin for the element: found at planning, naming the point
    meas = V.read_measured(_files(tmp_path, {"measured": {"Fc": {"60": {"30": 1.0},
                                                                 "45": {"30": 1.0}}}})[1])
    with pytest.raises(ConfigError, match=r"element_size_um.*h 45 um.*at most") as e:
        V.run_validation(base, meas, source="tiny.toml", simulate=_no_run)
    assert e.value.field == "mesh.element_size_um"
    # an unknown key in the base config
    bad = {**base, "contact": {"frcition": 0.2}}
    with pytest.raises(ConfigError, match="contact.frcition"):
        V.run_validation(bad, meas[:1], source="tiny.toml", simulate=_no_run)


def test_cli_bad_inputs_exit_2_without_running(tmp_path, monkeypatch):
    monkeypatch.setattr("robobore.cutting.fe.models.validate.run_validation", _no_run)
    c, m = _files(tmp_path, {"measured": {"Fc": {"60": {"30": "abc"}}}})
    r = CliRunner().invoke(app, ["fe", "validate", str(c), "--measured", str(m), "--json"])
    assert r.exit_code == 2 and "measured.Fc.60.30" in r.output and "abc" in r.output
    assert "Traceback" not in r.output
    c2 = tmp_path / "bad.toml"
    c2.write_text(TINY + "bogus = 1\n")
    r = CliRunner().invoke(app, ["fe", "validate", str(c2), "--measured", str(m)])
    assert r.exit_code == 2 and "solver.bogus" in r.output


def test_cli_json_contract_and_resume(tmp_path):
    c, m = _files(tmp_path)
    out = tmp_path / "res"
    args = ["fe", "validate", str(c), "--measured", str(m), "--json", "--out", str(out),
            "--plot", str(tmp_path / "png")]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)
    assert len(res["points"]) == 3
    keys = {"uncut_chip_thickness_um", "cutting_speed_m_per_min", "cutting_force_N_per_mm",
            "feed_force_N_per_mm", "chip_ratio", "relative_error"}
    for p in res["points"]:
        assert keys <= set(p)
        assert set(p["relative_error"]) == {"cutting_force", "feed_force", "chip_ratio"}
        h, vc = f"{p['uncut_chip_thickness_um']:g}", f"{p['cutting_speed_m_per_min']:g}"
        fc_m = MEASURED["measured"]["Fc"][h][vc]
        assert p["relative_error"]["cutting_force"] == pytest.approx(
            p["cutting_force_N_per_mm"] / fc_m - 1.0, rel=1e-12)
        assert p["cutting_force_N_per_mm"] > 0 and not p["reused"]
        has_r = vc in MEASURED["measured"]["chip_ratio"].get(h, {})
        assert (p["relative_error"]["chip_ratio"] is None) == (not has_r)
    s = res["summary"]
    for q in ("cutting_force", "feed_force", "chip_ratio"):
        errs = [abs(p["relative_error"][q]) for p in res["points"]
                if p["relative_error"][q] is not None]
        assert s["max_abs_error"][q] == pytest.approx(max(errs))
        assert s["mean_abs_error"][q] == pytest.approx(sum(errs) / len(errs))
    assert (tmp_path / "png" / "fe_validation.png").is_file()
    assert len(list(out.glob("*.json"))) == 3
    # the --json output read back as a record: typed, and to_dict() is that JSON, key order too
    (tmp_path / "rec.json").write_text(r.stdout)
    rec = load_validation_record(tmp_path / "rec.json")
    assert rec.measured_file == str(m) and rec.identity["kind"] == "fe validate"
    assert rec.files == {"png_validation": str(tmp_path / "png" / "fe_validation.png")}
    assert json.dumps(rec.to_dict()) == json.dumps(res)
    # a rerun reuses every stored point: same numbers
    r2 = CliRunner().invoke(app, args[:-2])
    res2 = json.loads(r2.stdout)
    assert all(p["reused"] for p in res2["points"])
    assert [p["cutting_force_N_per_mm"] for p in res2["points"]] == \
        [p["cutting_force_N_per_mm"] for p in res["points"]]
    # the table view
    r3 = CliRunner().invoke(app, ["fe", "validate", str(c), "--measured", str(m), "--out",
                                  str(out)])
    assert r3.exit_code == 0 and "Summary" in r3.stdout and "FE validation" in r3.stdout


def test_interrupted_validation_resumes(tmp_path):
    import tomllib

    from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

    base = tomllib.loads(TINY)
    meas = V.read_measured(_files(tmp_path)[1])
    out = tmp_path / "res"
    calls = []

    def interrupted(cfg, **kw):
        if calls:
            raise KeyboardInterrupt
        calls.append(cfg.cut.uncut_chip_thickness_um)
        return simulate_orthogonal(cfg, **kw)

    with pytest.raises(KeyboardInterrupt):
        V.run_validation(base, meas, out_dir=out, simulate=interrupted)
    assert len(list(out.glob("*.json"))) == 1
    # a zero-byte file (a crash mid-write elsewhere) is not a result: it is run again
    (out / "h80_vc30.json").write_bytes(b"")
    ran = []

    def counting(cfg, **kw):
        ran.append((cfg.cut.uncut_chip_thickness_um, cfg.cut.cutting_speed_m_per_min))
        return simulate_orthogonal(cfg, **kw)

    res = V.run_validation(base, meas, out_dir=out, simulate=counting)
    assert len(ran) == 2 and sum(p.reused for p in res.points) == 1
    # another config (here the element round the edge) does not reuse the stored points
    base2 = {**base, "mesh": {**base["mesh"], "edge_element_um": 10.0}}
    ran.clear()
    V.run_validation(base2, meas[:1], out_dir=out, simulate=counting)
    assert len(ran) == 1


def test_points_option_runs_a_prediction(tmp_path):
    import tomllib

    from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

    base = tomllib.loads(TINY)
    meas = V.read_measured(_files(tmp_path)[1])
    res = V.run_validation(base, meas, points=[(60.0, 20.0)], simulate=simulate_orthogonal)
    (p,) = res.points
    assert p.cutting_speed_m_per_min == 20.0 and p.cutting_force_N_per_mm > 0
    assert p.relative_error == PerQuantity(cutting_force=None, feed_force=None,
                                           chip_ratio=None)
    assert res.summary.max_abs_error.cutting_force is None
    assert math.isfinite(p.feed_force_N_per_mm)
    # the JSON of the typed result
    d = res.to_dict()
    assert list(d) == ["points", "summary", "config", "device", "out_dir"]
    assert d["points"][0]["relative_error"] == {"cutting_force": None, "feed_force": None,
                                                "chip_ratio": None}
    assert d["points"][0]["measured"] == {"cutting_force_N_per_mm": None,
                                          "feed_force_N_per_mm": None, "chip_ratio": None}
    none = {"cutting_force": None, "feed_force": None, "chip_ratio": None}
    assert d["summary"] == {"max_abs_error": none, "mean_abs_error": none,
                            "n_measured": {"cutting_force": 0, "feed_force": 0,
                                           "chip_ratio": 0}}


def test_bundled_record_reads_back_typed_and_exactly():
    """The bundled record as a ValidationRecord: typed points and summary; ``to_dict()`` is the
    file's JSON, key for key and in order."""
    path = bundled_validation_path()
    raw = json.loads(path.read_text(encoding="utf-8"))
    rec = load_validation_record(path)
    assert isinstance(rec, ValidationRecord) and len(rec.points) == 9
    assert all(isinstance(p, ValidationPoint) for p in rec.points)
    assert isinstance(rec.summary, ValidationSummary)
    assert isinstance(rec.points[0].measured, MeasuredValues)
    assert rec.points[0].measured.cutting_force_N_per_mm == \
        raw["points"][0]["measured"]["cutting_force_N_per_mm"]
    assert rec.summary.n_measured.cutting_force == 9
    assert rec.measured_file == raw["measured_file"] and rec.identity is None
    assert json.dumps(rec.to_dict()) == json.dumps(raw)
    d = rec.to_dict()
    d["points"][0]["measured"]["chip_ratio"] = -1.0  # a copy: the record is not changed
    assert rec.to_dict() == raw


def test_the_record_reader_knows_every_field_of_the_contract():
    """The reader's kinds come from the result types' fields, in their order; a field of a
    type the reader cannot check is refused when the module loads, not read unchecked."""
    from dataclasses import fields

    from robobore.cutting.fe.models.results import PerQuantity, ValidationPoint
    from robobore.cutting.fe.models.validation_record import _kind

    for cls, kinds in _KINDS.items():
        assert list(kinds) == [f.name for f in fields(cls)], cls
    vp = _KINDS[ValidationPoint]
    assert (vp["uncut_chip_thickness_um"], vp["chip_ratio"], vp["reused"], vp["file"],
            vp["relative_error"]) == ("num", "num?", "bool", "str?", PerQuantity)
    assert _kind(float | int | None) == "num?"
    with pytest.raises(TypeError, match="no record kind"):
        _kind(list[float])


def _bad_record(tmp_path, change):
    raw = json.loads(bundled_validation_path().read_text(encoding="utf-8"))
    change(raw)
    f = tmp_path / "rec.json"
    f.write_text(json.dumps(raw))
    with pytest.raises(DataError) as e:
        load_validation_record(f)
    assert e.value.file == str(f)
    return e.value


def test_bad_validation_records_name_file_key_and_value(tmp_path):
    e = _bad_record(tmp_path, lambda r: r["points"][2].pop("reused"))
    assert "lacks a key" in e.message and e.field == "points[2].reused" and e.row == 2
    e = _bad_record(tmp_path, lambda r: r["points"][1]["measured"].update(extra=1.0))
    assert "unknown key" in e.message and e.field == "points[1].measured.extra"
    e = _bad_record(tmp_path, lambda r: r["points"][0].update(cutting_force_N_per_mm="105"))
    assert e.field == "points[0].cutting_force_N_per_mm" and e.value == "105"
    assert "a number or null" in e.expected
    e = _bad_record(tmp_path, lambda r: r["points"][0].update(uncut_chip_thickness_um=None))
    assert e.field == "points[0].uncut_chip_thickness_um" and e.expected == "a number"
    e = _bad_record(tmp_path, lambda r: r["points"][0].update(reused=1))
    assert e.field == "points[0].reused" and e.expected == "true or false"
    e = _bad_record(tmp_path, lambda r: r["summary"]["n_measured"].pop("chip_ratio"))
    assert e.field == "summary.n_measured.chip_ratio"
    e = _bad_record(tmp_path, lambda r: r.pop("device"))
    assert "lacks a key" in e.message and e.field == "device"
    e = _bad_record(tmp_path, lambda r: r.update(measured_file=None))
    assert e.field == "measured_file" and e.expected == "a string"
    e = _bad_record(tmp_path, lambda r: r.update(files={"png_validation": 3}))
    assert e.field == "files.png_validation"
    e = _bad_record(tmp_path, lambda r: r.update(note="hand-edited"))
    assert "unknown key" in e.message and e.field == "note"
    e = _bad_record(tmp_path, lambda r: r.update(points=[]))
    assert "no validation points" in e.message and e.field == "points"
