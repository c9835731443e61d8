"""Campaign CSV (the contract of issue 2): reader with full validation, and writer.

Long format, one row per (posture, load step, reflector), positions in the robot base frame::

    posture, load_step, q1_deg .. q6_deg, force_x_N, force_y_N, force_z_N,
    load_point_x_m, load_point_y_m, load_point_z_m, reflector, x_m, y_m, z_m [, pressure_MPa]

Load step 0 of each posture is the unloaded reference (force 0). The force is the external
force applied to the robot at the load point (its position at the unloaded pose).

The reader rejects, naming file, row (1-based data row, header excluded) and column:
missing or unknown columns, empty or non-numeric or non-finite cells, negative or
non-integer load steps, duplicate (posture, load step, reflector) rows, joint angles / force /
load point that differ between the rows of one (posture, load step), joint angles that change
between load steps of a posture (> ``Q_TOL_DEG``), a non-zero force at step 0, a posture
without a step 0, a loaded step whose reflectors differ from its reference, fewer than 3 or
collinear reflectors, values outside the plausible range of their unit
(:mod:`robobore.io.ranges`: positions in mm in the ``*_m`` columns, ...), a largest test
force below ``MIN_PEAK_FORCE_N`` (forces in kN) and (when a robot is given) joints outside
their limits. Nothing is dropped silently.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

from robobore.errors import DataError
from robobore.io.ranges import check_value
from robobore.robot.campaign import Campaign, collinear

Q_COLS = tuple(f"q{i}_deg" for i in range(1, 7))
F_COLS = ("force_x_N", "force_y_N", "force_z_N")
LP_COLS = ("load_point_x_m", "load_point_y_m", "load_point_z_m")
XYZ_COLS = ("x_m", "y_m", "z_m")
REQUIRED = ("posture", "load_step", *Q_COLS, *F_COLS, *LP_COLS, "reflector", *XYZ_COLS)
OPTIONAL = ("pressure_MPa",)
UNITS = {**{c: "deg" for c in Q_COLS}, **{c: "N" for c in F_COLS},
         **{c: "m" for c in LP_COLS + XYZ_COLS}, "pressure_MPa": "MPa"}

#: Joint angles of one posture may differ between load steps by at most this (deg):
#: the controller holds the commanded angles; a larger change means a new posture.
Q_TOL_DEG = 0.01
#: The force of the unloaded reference step must be below this (N).
F0_TOL_N = 1e-6
#: The largest test force of a campaign must reach this (N): below it a robot (tool-point
#: stiffness 1e5 .. 1e8 N/m) deflects by less than a tracker's noise, and forces given in
#: kN where N is expected are caught (stiffness campaigns load 100 .. 5000 N).
MIN_PEAK_FORCE_N = 10.0


def _num(cell: str, *, file: str, row: int, col: str) -> float:
    s = cell.strip()
    if s == "":
        raise DataError("empty cell", file=file, row=row, field=col,
                        expected=f"a number in {UNITS.get(col, '')}".strip())
    try:
        v = float(s)
    except ValueError:
        raise DataError("not a number", file=file, row=row, field=col, value=cell,
                        expected=f"a number in {UNITS.get(col, '')}".strip()) from None
    if not math.isfinite(v):
        raise DataError("not a finite number", file=file, row=row, field=col, value=cell,
                        expected=f"a finite number in {UNITS.get(col, '')}".strip())
    return check_value(v, col, file=file, row=row)  # plausible range per unit (io.ranges)


def parse_campaign_text(text: str, source: str = "<campaign>", robot=None) -> Campaign:
    """Parse contract-CSV text; see the module docstring for what is checked."""
    reader = csv.reader(io.StringIO(text))
    try:
        header = next(reader)
    except StopIteration:
        raise DataError("file is empty", file=source, expected="a header row and data rows"
                        ) from None
    header = [h.strip() for h in header]
    missing = [c for c in REQUIRED if c not in header]
    if missing:
        seps = [s for s in (";", "\t", "|", " ") if len(header) == 1 and s in header[0]]
        if seps:
            raise DataError(f"the header is one cell separated by {seps[0]!r}, not by commas",
                            file=source, field=header[0][:40],
                            expected=f"comma-separated columns {list(REQUIRED)}")
        raise DataError(f"missing column(s) {missing}", file=source, field=missing[0],
                        expected=f"columns {list(REQUIRED)} (+ optional {list(OPTIONAL)})")
    unknown = [c for c in header if c not in REQUIRED and c not in OPTIONAL]
    if unknown:
        raise DataError(f"unknown column(s) {unknown}", file=source, field=unknown[0],
                        expected=f"only the contract columns {list(REQUIRED + OPTIONAL)}")
    dup = [c for c in header if header.count(c) > 1]
    if dup:
        raise DataError("duplicated column", file=source, field=dup[0])
    idx = {c: header.index(c) for c in header}
    has_p = "pressure_MPa" in idx

    postures: list[str] = []
    refl: list[str] = []
    steps: list[int] = []
    q, F, lp, xyz, pr, rows = [], [], [], [], [], []
    for r, cells in enumerate(reader, start=1):
        if not cells or all(not c.strip() for c in cells):
            continue  # blank line (not a data row)
        if len(cells) != len(header):
            raise DataError(f"row has {len(cells)} cells, header has {len(header)}",
                            file=source, row=r, expected=f"{len(header)} comma-separated cells")
        g = {c: cells[i] for c, i in idx.items()}
        lab = g["posture"].strip()
        if not lab:
            raise DataError("empty cell", file=source, row=r, field="posture",
                            expected="a posture label")
        rl = g["reflector"].strip()
        if not rl:
            raise DataError("empty cell", file=source, row=r, field="reflector",
                            expected="a reflector label")
        st = _num(g["load_step"], file=source, row=r, col="load_step")
        if st < 0 or st != int(st):
            raise DataError("load step must be a non-negative integer", file=source, row=r,
                            field="load_step", value=g["load_step"],
                            expected="0 (unloaded reference), 1, 2, ...")
        postures.append(lab)
        refl.append(rl)
        steps.append(int(st))
        q.append([_num(g[c], file=source, row=r, col=c) for c in Q_COLS])
        F.append([_num(g[c], file=source, row=r, col=c) for c in F_COLS])
        lp.append([_num(g[c], file=source, row=r, col=c) for c in LP_COLS])
        xyz.append([_num(g[c], file=source, row=r, col=c) for c in XYZ_COLS])
        if has_p:
            pr.append(_num(g["pressure_MPa"], file=source, row=r, col="pressure_MPa"))
        rows.append(r)
    if not rows:
        raise DataError("no data rows", file=source, expected="one row per (posture, load "
                        "step, reflector)")
    camp = Campaign(
        posture=tuple(postures),
        load_step=np.asarray(steps, np.int64),
        q_deg=np.asarray(q, float),
        force_N=np.asarray(F, float),
        load_point_m=np.asarray(lp, float),
        reflector=tuple(refl),
        xyz_m=np.asarray(xyz, float),
        pressure_MPa=np.asarray(pr, float) if has_p else None,
        source=source,
        rows=tuple(rows),
    )
    validate_campaign(camp, robot=robot)
    return camp


def truth_path(path: str | Path) -> Path:
    """The identity file written next to a campaign CSV (``<csv>.truth.json``): robot,
    robot hash, SYNTHETIC flag and, for a virtual campaign, its ground truth."""
    return Path(str(path) + ".truth.json")


def read_truth(path: str | Path) -> dict | None:
    """The campaign's identity file (:func:`truth_path`), or None when there is none."""
    from robobore.io.readers import load_json

    tp = truth_path(path)
    if not tp.is_file():
        return None
    data = load_json(tp, "campaign identity file",
                     "the JSON object `robobore robot campaign` writes next to its CSV")
    syn = data.get("synthetic")
    if not isinstance(syn, bool):
        raise DataError("missing or not a boolean", file=str(tp), field="synthetic", value=syn,
                        expected="true (virtual campaign) or false (measured)")
    for key in ("robot", "robot_hash"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise DataError("not a string", file=str(tp), field=key, value=data[key],
                            expected="the robot's library name / description hash")
    return data


def read_campaign(path: str | Path, robot=None) -> Campaign:
    """Read and validate a campaign CSV file (``robot``: name/Robot to check joint limits).

    A ``;``, tab or ``|`` separated file is read as well
    (:func:`robobore.io.readers.comma_separated`). The identity file next to it
    (:func:`truth_path`), if there is one, goes to ``Campaign.truth``: its ``synthetic``
    flag travels into the identification, and a ``robot`` other than ``robot`` is refused,
    naming both."""
    import dataclasses

    p = Path(path)
    if not p.is_file():
        raise DataError("campaign file not found", file=str(p), expected="an existing CSV file")
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=str(p),
                        expected="a UTF-8 CSV file") from None
    truth = read_truth(p)
    if truth is not None and robot is not None:
        from robobore.io.identity import check_robot
        from robobore.robot.description import get_robot

        rb = get_robot(robot)
        check_robot({"robot": truth.get("robot"), "robot_hash": truth.get("robot_hash")},
                    str(p), rb.name, rb.description_hash(), "the robot given")
    from robobore.io.readers import comma_separated

    camp = parse_campaign_text(comma_separated(text, REQUIRED), source=str(p), robot=robot)
    return camp if truth is None else dataclasses.replace(camp, truth=truth)


def validate_campaign(c: Campaign, robot=None) -> None:
    """Structural checks of a campaign (see module docstring); DataError on the first problem."""
    src = c.source
    seen: dict[tuple[str, int, str], int] = {}
    groups: dict[tuple[str, int], list[int]] = {}
    for i in range(c.n_rows):
        key = (c.posture[i], int(c.load_step[i]), c.reflector[i])
        if key in seen:
            raise DataError(
                f"duplicate row for posture {key[0]!r}, load step {key[1]}, reflector "
                f"{key[2]!r} (first at row {c.row_number(seen[key])})",
                file=src, row=c.row_number(i), field="reflector", value=key[2],
                expected="one row per (posture, load_step, reflector)")
        seen[key] = i
        groups.setdefault((c.posture[i], int(c.load_step[i])), []).append(i)
    # constant q / force / load point within a (posture, step)
    for (_lab, _st), ids in groups.items():
        i0 = ids[0]
        for i in ids[1:]:
            for cols, arr, tol in ((Q_COLS, c.q_deg, 1e-9), (F_COLS, c.force_N, 1e-9),
                                   (LP_COLS, c.load_point_m, 1e-12)):
                diff = np.abs(arr[i] - arr[i0]) > tol * np.maximum(1.0, np.abs(arr[i0]))
                if diff.any():
                    j = int(np.argmax(diff))
                    raise DataError(
                        f"value differs from row {c.row_number(i0)} of the same posture and "
                        "load step", file=src, row=c.row_number(i), field=cols[j],
                        value=float(arr[i, j]),
                        expected=f"{float(arr[i0, j])!r} {UNITS[cols[j]]} (same for all "
                        "reflectors of one load step)")
        if c.pressure_MPa is not None:
            for i in ids[1:]:
                if c.pressure_MPa[i] != c.pressure_MPa[i0]:
                    raise DataError("pressure differs within one load step", file=src,
                                    row=c.row_number(i), field="pressure_MPa",
                                    value=float(c.pressure_MPa[i]),
                                    expected=f"{float(c.pressure_MPa[i0])} MPa")
    for lab in c.postures():
        if (lab, 0) not in groups:
            first = next(i for i in range(c.n_rows) if c.posture[i] == lab)
            raise DataError(f"posture {lab!r} has no unloaded reference (load step 0)",
                            file=src, row=c.row_number(first), field="load_step",
                            value=int(c.load_step[first]),
                            expected="a load step 0 (force 0) for every posture")
        ref = groups[(lab, 0)]
        i0 = ref[0]
        if np.linalg.norm(c.force_N[i0]) > F0_TOL_N:
            raise DataError("load step 0 is the unloaded reference but has a force",
                            file=src, row=c.row_number(i0), field="force_x_N",
                            value=c.force_N[i0].tolist(), expected="0 N")
        ref_refl = sorted(c.reflector[i] for i in ref)
        if len(ref_refl) < 3:
            raise DataError(f"posture {lab!r}: only {len(ref_refl)} reflector(s) at load step 0",
                            file=src, row=c.row_number(i0), field="reflector",
                            expected="3 or more non-collinear reflectors")
        if collinear(c.xyz_m[ref]):
            raise DataError(f"posture {lab!r}: reflectors {ref_refl} are collinear",
                            file=src, row=c.row_number(i0), field="x_m",
                            expected="3 or more non-collinear reflectors (m)")
        steps = sorted(st for (lb, st) in groups if lb == lab)
        for st in steps[1:]:
            ids = groups[(lab, st)]
            got = sorted(c.reflector[i] for i in ids)
            if got != ref_refl:
                raise DataError(
                    f"posture {lab!r} load step {st}: reflectors {got} differ from the "
                    f"reference step's {ref_refl}", file=src, row=c.row_number(ids[0]),
                    field="reflector", expected="the same reflectors at every load step")
            dq = np.abs(c.q_deg[ids[0]] - c.q_deg[i0])
            if dq.max() > Q_TOL_DEG:
                j = int(np.argmax(dq))
                raise DataError(
                    f"posture {lab!r}: joint angles change between load step 0 and {st}",
                    file=src, row=c.row_number(ids[0]), field=Q_COLS[j],
                    value=float(c.q_deg[ids[0], j]),
                    expected=f"{float(c.q_deg[i0, j])} deg (within {Q_TOL_DEG} deg; the "
                    "commanded posture is held while loading)")
    fnorm = np.linalg.norm(c.force_N, axis=1)
    if c.n_rows and float(fnorm.max()) < MIN_PEAK_FORCE_N:
        i = int(np.argmax(fnorm))
        raise DataError("the largest test force is too small to deflect a robot measurably "
                        "(looks like kN; expected N)", file=src, row=c.row_number(i),
                        field="force_x_N", value=float(fnorm[i]),
                        expected=f"a largest force of at least {MIN_PEAK_FORCE_N:g} N "
                        "(stiffness campaigns load 100 .. 5000 N)")
    if robot is not None:
        from robobore.robot.description import check_joint_limits, get_robot

        rb = get_robot(robot)
        for i in range(c.n_rows):
            check_joint_limits(rb, np.radians(c.q_deg[i]), file=src, rows=[c.row_number(i)])


def format_campaign(c: Campaign) -> str:
    """Contract-CSV text of a campaign (floats written with ``repr``: exact round trip)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    cols = list(REQUIRED) + (["pressure_MPa"] if c.pressure_MPa is not None else [])
    w.writerow(cols)
    for i in range(c.n_rows):
        row = [c.posture[i], str(int(c.load_step[i]))]
        row += [repr(float(x)) for x in c.q_deg[i]]
        row += [repr(float(x)) for x in c.force_N[i]]
        row += [repr(float(x)) for x in c.load_point_m[i]]
        row += [c.reflector[i]]
        row += [repr(float(x)) for x in c.xyz_m[i]]
        if c.pressure_MPa is not None:
            row.append(repr(float(c.pressure_MPa[i])))
        w.writerow(row)
    return buf.getvalue()


def write_campaign(c: Campaign, path: str | Path, identity: dict | None = None) -> Path:
    """Write the contract CSV atomically; with ``identity`` (robot, robot_hash, synthetic,
    ...), also its identity file (:func:`truth_path`)."""
    from robobore.io.results import atomic_write_text, write_json

    out = atomic_write_text(path, format_campaign(c))
    if identity is not None:
        write_json(truth_path(path), identity)
    return out


__all__ = [
    "REQUIRED",
    "OPTIONAL",
    "read_campaign",
    "parse_campaign_text",
    "validate_campaign",
    "format_campaign",
    "write_campaign",
    "truth_path",
    "read_truth",
]
