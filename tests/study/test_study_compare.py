"""Comparison with measurements: relative errors by hand, group statistics, agreement,
strict CSV validation (row and column named) and a property test of the CSV reader."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import DataError
from robobore.study.compare import compare, parse_measured_csv, read_measured_csv
from robobore.study.conditions import CONDITION_FIELDS

HEAD = "speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa"


def _sim(n, f, a, p, **summary):
    return ({"speed_rpm": n, "feed_mm_per_rev": f, "depth_of_cut_mm": a, "pressure_MPa": p,
             "posture": "paper"}, summary)


def test_relative_errors_groups_and_agreement_by_hand():
    text = (f"{HEAD},force_amplitude_x_N,feed_amplitude_um,stable\n"
            "300,0.15,0.05,0,100,10,true\n"      # stable
            "300,0.3,0.05,0,200,,true\n"         # stable, feed amplitude not measured
            "300,0.15,0.2,0,400,50,false\n"      # vibratory
            "300,0.15,0.3,0,500,80,false\n")     # vibratory; simulation says stable
    sims = [
        _sim(300, 0.15, 0.05, 0, force_amplitude_x_N=110.0, feed_amplitude_um=9.0, stable=True),
        _sim(300, 0.3, 0.05, 0, force_amplitude_x_N=190.0, feed_amplitude_um=1.0, stable=True),
        _sim(300, 0.15, 0.2, 0, force_amplitude_x_N=300.0, feed_amplitude_um=55.0,
             stable=False),
        _sim(300, 0.15, 0.3, 0, force_amplitude_x_N=500.0, feed_amplitude_um=100.0,
             stable=True),
        _sim(999, 0.15, 0.3, 0, force_amplitude_x_N=1.0, stable=True),  # not measured
    ]
    c = compare(parse_measured_csv(text), sims)
    r = {row["row"]: row["quantities"] for row in c.rows}
    # |110-100|/100 = 0.10; |9-10|/10 = 0.10; |190-200|/200 = 0.05
    assert r[1]["force_amplitude_x_N"]["rel_error"] == pytest.approx(0.10)
    assert r[1]["feed_amplitude_um"]["rel_error"] == pytest.approx(0.10)
    assert r[2]["force_amplitude_x_N"]["rel_error"] == pytest.approx(0.05)
    assert "feed_amplitude_um" not in r[2]
    # vibratory: |300-400|/400 = 0.25, |55-50|/50 = 0.10, 0/500 = 0, |100-80|/80 = 0.25
    assert r[3]["force_amplitude_x_N"]["rel_error"] == pytest.approx(0.25)
    assert r[4]["force_amplitude_x_N"]["rel_error"] == 0.0
    g = c.groups
    assert c.group_source == "measured"
    assert g["stable"]["n_conditions"] == 2 and g["stable"]["n"] == 3
    assert g["stable"]["min_rel_error"] == pytest.approx(0.05)
    assert g["stable"]["max_rel_error"] == pytest.approx(0.10)
    assert g["stable"]["mean_rel_error"] == pytest.approx(0.25 / 3)
    assert g["vibratory"]["min_rel_error"] == 0.0
    assert g["vibratory"]["max_rel_error"] == pytest.approx(0.25)
    assert g["vibratory"]["per_quantity"]["feed_amplitude_um"]["max_rel_error"] == \
        pytest.approx(0.25)
    a = c.agreement
    assert (a["n"], a["agree"], a["measured_vibratory_simulated_stable"]) == (4, 3, 1)
    assert a["rate"] == pytest.approx(0.75)
    assert c.unmatched_measured == () and c.undefined == ()


def test_groups_from_simulation_when_not_measured_and_undefined_errors_are_listed():
    text = f"{HEAD},force_amplitude_z_N\n300,0.15,0.05,0,0\n400,0.15,0.05,0,50\n500,0.1,0.1,0,1\n"
    sims = [_sim(300, 0.15, 0.05, 0, force_amplitude_z_N=3.0, stable=True),
            _sim(400, 0.15, 0.05, 0, force_amplitude_z_N=60.0, stable=False)]
    c = compare(parse_measured_csv(text), sims)
    assert c.group_source == "simulated"
    assert c.groups["vibratory"]["max_rel_error"] == pytest.approx(0.2)
    assert c.groups["stable"]["n"] == 0 and c.groups["stable"]["max_rel_error"] is None
    assert c.undefined[0]["row"] == 1 and "measured value is 0" in c.undefined[0]["reason"]
    assert c.unmatched_measured[0]["row"] == 3
    assert c.agreement["n"] == 0 and c.agreement["rate"] is None


def test_no_match_and_ambiguous_simulation_are_errors():
    t = parse_measured_csv(f"{HEAD},stable\n300,0.15,0.05,0,true\n")
    with pytest.raises(DataError, match="no measured condition matches"):
        compare(t, [_sim(301, 0.15, 0.05, 0, stable=True)])
    two = [_sim(300, 0.15, 0.05, 0, stable=True), _sim(300, 0.15, 0.05, 0, stable=False)]
    two[1][0]["posture"] = "other"
    with pytest.raises(DataError, match="two simulated results"):
        compare(t, two)
    # with a posture column the two are told apart
    t2 = parse_measured_csv(f"{HEAD},posture,stable\n300,0.15,0.05,0,other,false\n")
    assert compare(t2, two).agreement["rate"] == 1.0


@pytest.mark.parametrize("text, row, field, words", [
    ("speed_rpm,feed_mm_per_rev,depth_of_cut_mm,stable\n300,0.1,0.1,true\n", None,
     "pressure_MPa", "missing column"),
    (f"{HEAD}\n300,0.1,0.1,0\n", None, None, "no measured quantity"),
    (f"{HEAD},stable,force_x\n300,0.1,0.1,0,true,1\n", None, "force_x", "unknown column"),
    (f"{HEAD},stable,stable\n300,0.1,0.1,0,true,true\n", None, "stable", "twice"),
    (f"{HEAD},stable\n300,0.1,0.1,0,true\n300,abc,0.1,0,true\n", 2, "feed_mm_per_rev",
     "not a number"),
    (f"{HEAD},stable\n300,0.1,0.1,0,true\n300,0.2,0.1,0,maybe\n", 2, "stable",
     "not a boolean"),
    (f"{HEAD},feed_amplitude_um\n300,0.1,0.1,0,-2\n", 1, "feed_amplitude_um", "out of range"),
    (f"{HEAD},feed_amplitude_um\n300,0.1,0.1,0,nan\n", 1, "feed_amplitude_um", "out of range"),
    (f"{HEAD},stable\n0,0.1,0.1,0,true\n", 1, "speed_rpm", "out of range"),
    (f"{HEAD},stable\n300,0.1,0.1,,true\n", 1, "pressure_MPa", "empty cell"),
    (f"{HEAD},stable\n300,0.1,0.1,0,true,7\n", 1, None, "cells"),
    (f"{HEAD},stable\n300,0.1,0.1,0,true\n\n500,0.1,0.1,0,true\n300.0,0.10,0.1,0,false\n", 4,
     ",".join(CONDITION_FIELDS), "same condition as row 1"),
    ("", None, None, "no header"),
    (f"{HEAD},stable\n", None, None, "no data rows"),
])
def test_bad_csv_names_row_and_column(tmp_path, text, row, field, words):
    p = tmp_path / "m.csv"
    p.write_text(text)
    with pytest.raises(DataError, match=words) as ei:
        read_measured_csv(p)
    e = ei.value
    assert e.file == str(p) and str(p) in str(e)
    assert e.row == row
    if field is not None:
        assert e.field == field and field in str(e)
    if field in ("feed_mm_per_rev", "feed_amplitude_um", "speed_rpm"):
        assert any(u in str(e) for u in ("mm", "um", "r/min"))  # unit in the message


def test_comments_bom_and_blank_lines():
    t = parse_measured_csv(f"\ufeff# measured 2024-05-01\n{HEAD},stable\n\n"
                           "300,0.1,0.1,0,TRUE\n# repeated later\n400,0.1,0.1,0.3,0\n")
    assert [r.row for r in t.rows] == [2, 4]
    assert [r.values["stable"] for r in t.rows] == [True, False]


def test_missing_file_and_non_utf8(tmp_path):
    with pytest.raises(DataError, match="file not found"):
        read_measured_csv(tmp_path / "none.csv")
    p = tmp_path / "latin.csv"
    p.write_bytes(f"{HEAD},stable\n300,0.1,0.1,0,true\xe9\n".encode("latin-1"))
    with pytest.raises(DataError, match="UTF-8"):
        read_measured_csv(p)


finite_pos = st.floats(min_value=1e-6, max_value=1e6, allow_nan=False, allow_infinity=False)
finite_nonneg = st.floats(min_value=0, max_value=1e6, allow_nan=False, allow_infinity=False)


def _upto(hi, lo=1e-6):  # within the plausible range of robobore.io.ranges
    return st.floats(min_value=lo, max_value=hi, allow_nan=False, allow_infinity=False)


QUANTS = ["force_amplitude_x_N", "force_amplitude_y_N", "force_amplitude_z_N",
          "feed_amplitude_um", "stable"]


@st.composite
def tables(draw):
    quants = draw(st.lists(st.sampled_from(QUANTS), min_size=1, max_size=5, unique=True))
    n = draw(st.integers(1, 8))
    conds = draw(st.lists(st.tuples(_upto(1e5), _upto(5.0, 1e-3), _upto(20.0, 1e-3),
                                    _upto(50.0, 0.0)),
                          min_size=n, max_size=n,
                          unique_by=lambda t: tuple(float(f"{v:.9g}") for v in t)))
    rows = []
    for c in conds:
        vals = {}
        for q in quants:
            if draw(st.booleans()):  # some cells left empty (= not measured)
                vals[q] = draw(st.booleans()) if q == "stable" else draw(_upto(1e5, 0.0))
        rows.append((c, vals))
    return quants, rows


def _csv(quants, rows):
    lines = [",".join([*CONDITION_FIELDS, *quants])]
    for c, vals in rows:
        cells = [repr(v) for v in c]
        for q in quants:
            v = vals.get(q)
            cells.append("" if v is None else (("true" if v else "false") if q == "stable"
                                               else repr(v)))
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


@settings(max_examples=60, deadline=None)
@given(tables())
def test_reader_round_trips_every_valid_table(tab):
    quants, rows = tab
    t = parse_measured_csv(_csv(quants, rows))
    assert t.quantities == tuple(q for q in QUANTS if q in quants)
    assert len(t.rows) == len(rows)
    for got, (c, vals) in zip(t.rows, rows, strict=True):
        assert tuple(got.condition[f] for f in CONDITION_FIELDS) == c
        assert got.values == vals


@settings(max_examples=60, deadline=None)
@given(tables(), st.data())
def test_reader_names_the_corrupted_cell(tab, data):
    quants, rows = tab
    cols = [*CONDITION_FIELDS, *quants]
    r = data.draw(st.integers(0, len(rows) - 1))
    col = data.draw(st.sampled_from(cols))
    junk = data.draw(st.sampled_from(["abc", "1,5e", "nan", "inf", "-1", "--", "yes please"]))
    lines = _csv(quants, rows).splitlines()
    cells = lines[r + 1].split(",")
    cells[cols.index(col)] = junk
    lines[r + 1] = ",".join(cells)
    if junk == "1,5e":  # a comma: one cell too many, the row is named without a column
        with pytest.raises(DataError, match="cells") as ei:
            parse_measured_csv("\n".join(lines))
        assert ei.value.row == r + 1
        return
    with pytest.raises(DataError) as ei:
        parse_measured_csv("\n".join(lines))
    assert ei.value.row == r + 1 and ei.value.field == col


def test_cli_compare_json_and_report(tmp_path, sweep_toml):
    runner = CliRunner()
    res = runner.invoke(app, ["sweep", str(sweep_toml), "--out", str(tmp_path / "s"),
                              "--workers", "0", "--json"])
    assert res.exit_code == 0, res.output
    # "measured" = simulated summary perturbed by known factors (synthetic, for the test)
    lines = (tmp_path / "s" / "summary.csv").read_text().splitlines()
    head = lines[0].split(",")
    rows = [dict(zip(head, ln.split(","), strict=True)) for ln in lines[1:]]
    out = [f"{HEAD},force_amplitude_x_N,feed_amplitude_um,stable"]
    for i, r in enumerate(rows):
        fac = 1.0 + 0.02 * (i % 5)  # measured = simulated * fac -> error = 1 - 1/fac
        out.append(",".join([r["speed_rpm"], r["feed_mm_per_rev"], r["depth_of_cut_mm"],
                             r["pressure_MPa"], repr(float(r["force_amplitude_x_N"]) * fac),
                             repr(float(r["feed_amplitude_um"]) * fac), r["stable"]]))
    (tmp_path / "m.csv").write_text("\n".join(out) + "\n")
    res = runner.invoke(app, ["compare", str(tmp_path / "m.csv"), str(tmp_path / "s"),
                              "--json", "--report", str(tmp_path / "cmp.html")])
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    # the JSON keeps to the stored contract; before measured and results it is the
    # Comparison's to_dict() (the same comparison in-process)
    from pathlib import Path

    from robobore.io.records import json_mismatches
    from robobore.io.results import to_jsonable
    from robobore.study.compare import compare_results

    spec = json.loads((Path(__file__).parent / "contract" / "compare.json").read_text())
    assert json_mismatches(d, spec["keys"]) == []
    mine = json.loads(json.dumps(to_jsonable(
        compare_results(tmp_path / "m.csv", tmp_path / "s").to_dict())))
    assert mine == {k: v for k, v in d.items() if k not in ("measured", "results", "report")}
    errs = [e["rel_error"] for r in d["conditions"] for e in r["quantities"].values()]
    assert max(errs) == pytest.approx(1 - 1 / 1.08, rel=1e-9)
    assert min(errs) == pytest.approx(0.0, abs=1e-12)
    assert d["agreement"]["rate"] == 1.0
    assert (tmp_path / "cmp.html").read_text().count("data:image/png;base64,") == 1
    # table output works too
    res = runner.invoke(app, ["compare", str(tmp_path / "m.csv"), str(tmp_path / "s")])
    assert res.exit_code == 0 and "agreement" in res.output


def test_cli_compare_bad_csv_is_one_line_exit_2(tmp_path, sweep_toml):
    (tmp_path / "m.csv").write_text(f"{HEAD},stable\n300,0.1,x,0,true\n")
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "store.json").write_text('{"store_format": 1}')
    res = CliRunner().invoke(app, ["compare", str(tmp_path / "m.csv"), str(tmp_path / "s")])
    assert res.exit_code == 2
    text = " ".join(res.output.split())  # rich wraps long lines
    assert "m.csv, row 1, field 'depth_of_cut_mm': not a number (got 'x')" in text
    assert "in mm" in text and "Traceback" not in text


def test_synthetic_measurements_round_trip_through_the_comparison(tmp_path):
    """Virtual experiment with known noise: the comparison recovers it (ground truth:
    measured = simulated x (1 + e), |e| <= 3 * 0.05, so rel. error = |e| / (1 + e))."""
    import numpy as np

    from robobore.study.synthetic import synthetic_measured_csv

    rng = np.random.default_rng(5)
    sims = [_sim(float(n), 0.1 * f, 0.05 * a, 0.0, force_amplitude_x_N=float(rng.uniform(50, 500)),
                 feed_amplitude_um=float(rng.uniform(1, 50)), stable=bool(a < 3))
            for n in (200, 400, 600) for f in (1, 2, 3) for a in (1, 2, 4, 6)]
    p = synthetic_measured_csv(sims, tmp_path / "m.csv", rel_noise=0.05, seed=1)
    assert p.read_text().startswith("# SYNTHETIC")
    c = compare(read_measured_csv(p), sims)
    errs = [e["rel_error"] for r in c.rows for e in r["quantities"].values()]
    assert len(errs) == 2 * len(sims)
    assert max(errs) <= 0.15 / 0.85 + 1e-12  # |e| <= 0.15 -> |e|/(1+e) <= 0.15/0.85
    assert 0.02 < float(np.mean(errs)) < 0.06  # E|e|/(1+e) ~ 0.05*sqrt(2/pi) ~ 0.04
    assert c.agreement["rate"] == 1.0  # no flips asked
    again = synthetic_measured_csv(sims, tmp_path / "m2.csv", rel_noise=0.05, seed=1)
    assert again.read_text() == p.read_text()  # deterministic for a seed
    flipped = synthetic_measured_csv(sims, tmp_path / "m3.csv", flip_stable=1.0, seed=1)
    assert compare(read_measured_csv(flipped), sims).agreement["rate"] == 0.0


def _system_store(root, systems):
    """A store like the paper job's: the same condition simulated for several systems, each
    result labelled by ``runner_options.system`` in its stored config."""
    import numpy as np
    import xarray as xr

    from robobore.study.store import ResultsStore

    st = ResultsStore(root)
    cond = {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
            "pressure_MPa": 0.0, "posture": "paper"}
    for i, (name, fx) in enumerate(systems.items()):
        ds = xr.Dataset({"x": ("t", np.arange(5.0)), "force_amplitude_x_N": ((), fx),
                         "stable": ((), True)})
        st.write_result(f"k{i}", cond, ds, runner="boring",
                        config={"runner_options": {"system": name}} if name else None)
    return st


def test_compare_tells_systems_apart_in_one_store(tmp_path):
    """The paper's store holds robot and machine-tool results for the same condition: compare
    takes the robot by default, the other with ``--system``, and reads the paper's output
    folder (its ``sweep`` store) as well as the store itself."""
    from typer.testing import CliRunner

    from robobore.cli import app
    from robobore.study.compare import compare_results

    _system_store(tmp_path / "out" / "sweep", {"robot": 110.0, "machine_tool": 50.0})
    csv = tmp_path / "m.csv"
    csv.write_text(f"{HEAD},force_amplitude_x_N,stable\n300,0.15,0.05,0,100,true\n")
    c = compare_results(csv, tmp_path / "out")
    assert c.system == "robot" and c.systems == ("machine_tool", "robot")
    assert c.groups["stable"]["max_rel_error"] == pytest.approx(0.1)
    c = compare_results(csv, tmp_path / "out" / "sweep", system="machine_tool")
    assert c.groups["stable"]["max_rel_error"] == pytest.approx(0.5)
    with pytest.raises(DataError, match="no results of this system"):
        compare_results(csv, tmp_path / "out", system="lathe")
    r = CliRunner().invoke(app, ["compare", str(csv), str(tmp_path / "out"), "--system",
                                 "machine_tool", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["system"] == "machine_tool"


def test_unlabelled_duplicates_name_the_choices(tmp_path):
    """Two unlabelled results for one condition (no system to choose): the error asks for one
    system, a posture column or one sweep per folder, naming no wrong cause."""
    from robobore.study.compare import compare_results

    st = _system_store(tmp_path / "s", {"": 110.0})
    import numpy as np
    import xarray as xr

    st.write_result("k9", {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15,
                           "depth_of_cut_mm": 0.05, "pressure_MPa": 0.0, "posture": "other"},
                    xr.Dataset({"x": ("t", np.arange(5.0)), "force_amplitude_x_N": ((), 1.0),
                                "stable": ((), True)}), runner="boring")
    csv = tmp_path / "m.csv"
    csv.write_text(f"{HEAD},force_amplitude_x_N\n300,0.15,0.05,0,100\n")
    with pytest.raises(DataError, match="more than one model or posture"):
        compare_results(csv, tmp_path / "s")


def test_a_unit_slip_in_a_measured_column_is_warned():
    """Feed amplitudes given in mm in the um column: every relative error near 1e5 %; the
    comparison says which column looks slipped (and no warning on the right units)."""
    rows = [(0.05, 10.0), (0.1, 20.0), (0.2, 50.0), (0.3, 80.0)]
    sims = [_sim(300, 0.15, ap, 0, feed_amplitude_um=a * 1.1, stable=True) for ap, a in rows]
    good = f"{HEAD},feed_amplitude_um\n" + "".join(f"300,0.15,{ap},0,{a}\n" for ap, a in rows)
    assert compare(parse_measured_csv(good), sims).warnings == ()
    slip = f"{HEAD},feed_amplitude_um\n" + "".join(f"300,0.15,{ap},0,{a / 1000}\n"
                                                   for ap, a in rows)
    c = compare(parse_measured_csv(slip, "m.csv"), sims)
    assert len(c.warnings) == 1 and "m.csv" in c.warnings[0]
    assert "feed_amplitude_um" in c.warnings[0] and "unit slip" in c.warnings[0]
    assert c.to_dict()["warnings"] == list(c.warnings)
