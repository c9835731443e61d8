"""Campaign CSV reader/writer: round trip, garbage cells, every error path of the contract."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robobore.errors import ConfigError, DataError, IdentificationError, InputError
from robobore.robot.campaign import Campaign, CampaignSpec, TrackerNoise, simulate_campaign
from robobore.robot.campaign_io import (
    REQUIRED,
    format_campaign,
    parse_campaign_text,
    read_campaign,
    write_campaign,
)
from robobore.robot.identify import identify_joint_stiffness

ROBOT = "irb6600-175-2.55"
NUMERIC = [c for c in REQUIRED if c not in ("posture", "reflector")]


@pytest.fixture(scope="module")
def small_text():
    spec = CampaignSpec(postures_deg=CampaignSpec().postures_deg[:2],
                        load_levels_N=(0.0, 500.0, 1000.0), noise=TrackerNoise(sigma_m=5e-6))
    return format_campaign(simulate_campaign(spec))


def _rows(text):
    lines = text.strip().split("\n")
    return lines[0].split(","), [ln.split(",") for ln in lines[1:]]


def _join(header, rows):
    return "\n".join([",".join(header)] + [",".join(r) for r in rows]) + "\n"


# --- property tests ---------------------------------------------------------------------------

finite = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)
loaded = st.floats(10.0, 1e4, allow_nan=False, allow_infinity=False)
#: positions within the plausible range of robobore.io.ranges (|x| <= 50 m)
position = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


@st.composite
def campaigns(draw):
    n_p = draw(st.integers(1, 3))
    n_s = draw(st.integers(2, 3))
    n_r = draw(st.integers(3, 4))
    tri = np.array([[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.0, 0.2, 0.0], [0.1, 0.1, 0.15]])[:n_r]
    post, step, q, F, lp, refl, xyz = [], [], [], [], [], [], []
    with_p = draw(st.booleans())
    pr = []
    for p in range(n_p):
        qp = [draw(st.floats(-170, 170, allow_nan=False)) for _ in range(6)]
        lpp = [draw(position) for _ in range(3)]
        off = np.array([draw(position) for _ in range(3)])
        for s in range(n_s):
            # a loaded step's force reaches the campaign minimum (10 N, MIN_PEAK_FORCE_N)
            Fs = [0.0, 0.0, 0.0] if s == 0 else [draw(loaded), draw(finite), draw(finite)]
            ps = draw(st.floats(0, 1, allow_nan=False))
            for r in range(n_r):
                post.append(f"P{p}")
                step.append(s)
                q.append(qp)
                F.append(Fs)
                lp.append(lpp)
                refl.append(f"R{r}")
                xyz.append(tri[r] + off + np.array([draw(st.floats(-1e-3, 1e-3)) for _ in
                                                    range(3)]))
                pr.append(ps)
    return Campaign(tuple(post), np.asarray(step), np.asarray(q, float), np.asarray(F, float),
                    np.asarray(lp, float), tuple(refl), np.asarray(xyz, float),
                    np.asarray(pr, float) if with_p else None)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(campaigns())
def test_roundtrip_writer_reader(c):
    back = parse_campaign_text(format_campaign(c), source="mem.csv")
    assert back.posture == c.posture and back.reflector == c.reflector
    for name in ("load_step", "q_deg", "force_N", "load_point_m", "xyz_m"):
        assert np.array_equal(getattr(back, name), getattr(c, name)), name
    if c.pressure_MPa is None:
        assert back.pressure_MPa is None
    else:
        assert np.array_equal(back.pressure_MPa, c.pressure_MPa)


garbage = st.text(min_size=1, max_size=8).filter(
    lambda s: "," not in s and "\n" not in s and "\r" not in s and '"' not in s
    and not _is_float(s))


def _is_float(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_garbage_cell_is_rejected_with_row_and_column(small_text, data):
    header, rows = _rows(small_text)
    r = data.draw(st.integers(0, len(rows) - 1))
    col = data.draw(st.sampled_from(NUMERIC))
    bad = data.draw(garbage)
    rows = [list(x) for x in rows]
    rows[r][header.index(col)] = bad
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows), source="g.csv")
    assert ei.value.row == r + 1 and ei.value.field == col and ei.value.file == "g.csv"


# --- error paths (issue 2 acceptance: clear error naming file, row and column) --------------


def test_missing_column(small_text):
    header, rows = _rows(small_text)
    j = header.index("force_y_N")
    txt = _join([h for i, h in enumerate(header) if i != j],
                [[c for i, c in enumerate(r) if i != j] for r in rows])
    with pytest.raises(DataError) as ei:
        parse_campaign_text(txt, source="m.csv")
    assert ei.value.field == "force_y_N" and "m.csv" in str(ei.value)


def test_unknown_column_and_short_row(small_text):
    header, rows = _rows(small_text)
    with pytest.raises(DataError, match="unknown column"):
        parse_campaign_text(_join(header + ["temp_C"], [r + ["20"] for r in rows]))
    rows[3] = rows[3][:-1]
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows))
    assert ei.value.row == 4


def test_nonfinite_and_empty(small_text):
    header, rows = _rows(small_text)
    rows[2][header.index("x_m")] = "nan"
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows), source="n.csv")
    assert ei.value.row == 3 and ei.value.field == "x_m" and "finite" in str(ei.value)
    header, rows = _rows(small_text)
    rows[5][header.index("q3_deg")] = " "
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows))
    assert ei.value.row == 6 and ei.value.field == "q3_deg"


def test_posture_without_unloaded_step(small_text):
    header, rows = _rows(small_text)
    rows = [r for r in rows if not (r[0] == "2" and r[1] == "0")]
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows), source="u.csv")
    assert "posture '2'" in str(ei.value) and ei.value.field == "load_step"
    assert ei.value.row is not None


def test_force_at_step_zero(small_text):
    header, rows = _rows(small_text)
    for r in rows:
        if r[0] == "1" and r[1] == "0":
            r[header.index("force_x_N")] = "12.5"
    with pytest.raises(DataError, match="unloaded reference but has a force"):
        parse_campaign_text(_join(header, rows))


def test_collinear_reflectors(small_text):
    header, rows = _rows(small_text)
    ix = [header.index(c) for c in ("x_m", "y_m", "z_m")]
    k = 0
    for r in rows:
        if r[0] == "1":
            # put the reflectors on the x axis, 0.1 m apart
            base = {"R1": 0.0, "R2": 0.1, "R3": 0.2}[r[header.index("reflector")]]
            r[ix[0]], r[ix[1]], r[ix[2]] = str(1.0 + base), "0.5", "0.5"
            k += 1
    with pytest.raises(DataError, match="collinear") as ei:
        parse_campaign_text(_join(header, rows), source="c.csv")
    assert ei.value.row == 1 and "c.csv" in str(ei.value)


def test_joint_outside_limits_names_row_and_column(small_text):
    header, rows = _rows(small_text)
    for r in rows:
        if r[0] == "2":
            r[header.index("q2_deg")] = "85.0"
    parse_campaign_text(_join(header, rows))  # structurally fine without a robot
    with pytest.raises(InputError) as ei:
        parse_campaign_text(_join(header, rows), source="l.csv", robot=ROBOT)
    first_p2 = next(i for i, r in enumerate(rows) if r[0] == "2") + 1
    assert ei.value.row == first_p2 and ei.value.field == "q2_deg" and "85" in str(ei.value)


def test_unknown_robot(small_text):
    with pytest.raises(ConfigError, match="unknown robot"):
        parse_campaign_text(small_text, robot="abb-nonexistent")


def test_duplicate_and_inconsistent_rows(small_text):
    header, rows = _rows(small_text)
    with pytest.raises(DataError, match="duplicate row"):
        parse_campaign_text(_join(header, rows + [rows[0]]))
    header, rows = _rows(small_text)
    rows[1][header.index("q1_deg")] = "-48.0"  # second reflector row of posture 1 step 0
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows))
    assert ei.value.row == 2 and ei.value.field == "q1_deg"
    header, rows = _rows(small_text)
    for r in rows:
        if r[0] == "1" and r[1] == "2":
            r[header.index("q4_deg")] = "-50.0"
    with pytest.raises(DataError, match="joint angles change"):
        parse_campaign_text(_join(header, rows))
    header, rows = _rows(small_text)
    rows = [r for r in rows if not (r[0] == "1" and r[1] == "1" and r[14] == "R3")]
    with pytest.raises(DataError, match="reflectors"):
        parse_campaign_text(_join(header, rows))


def test_bad_load_step(small_text):
    header, rows = _rows(small_text)
    rows[4][1] = "1.5"
    with pytest.raises(DataError) as ei:
        parse_campaign_text(_join(header, rows))
    assert ei.value.row == 5 and ei.value.field == "load_step"


def test_too_few_equations(small_text):
    header, rows = _rows(small_text)
    rows = [r for r in rows if r[0] == "1" and r[1] in ("0", "1")]  # 6 equations, 6 unknowns
    with pytest.raises(IdentificationError, match="too few equations") as ei:
        identify_joint_stiffness(parse_campaign_text(_join(header, rows), source="f.csv"),
                                 ROBOT)
    assert "f.csv" in str(ei.value)


def test_file_errors_and_atomic_write(tmp_path, small_text):
    with pytest.raises(DataError, match="not found"):
        read_campaign(tmp_path / "nope.csv")
    (tmp_path / "e.csv").write_text("")
    with pytest.raises(DataError, match="empty"):
        read_campaign(tmp_path / "e.csv")
    c = parse_campaign_text(small_text)
    p = write_campaign(c, tmp_path / "out.csv")
    assert read_campaign(p, robot=ROBOT).n_rows == c.n_rows
    assert [f.name for f in tmp_path.iterdir() if f.name.endswith(".tmp")] == []
