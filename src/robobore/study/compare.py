"""Comparison of simulated results with measurements, per condition and quantity.

Measured CSV contract (one row per condition, header first)::

    speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa,force_amplitude_x_N,...,stable
    300,0.15,0.05,0,212.4,,,,true

* required columns: ``speed_rpm`` (r/min, > 0), ``feed_mm_per_rev`` (mm, > 0),
  ``depth_of_cut_mm`` (mm, > 0), ``pressure_MPa`` (MPa, >= 0);
* at least one of ``force_amplitude_x_N``, ``force_amplitude_y_N``, ``force_amplitude_z_N``
  (N, >= 0), ``feed_amplitude_um`` (um, >= 0), ``stable`` (true/false; 1/0 and yes/no are
  accepted too);
* optional ``posture`` (a posture name, matched against the simulated condition's);
* an empty quantity cell means "not measured"; every other cell must parse. Anything else
  (an unknown or repeated column, a non-numeric, negative or non-finite number, a bad
  boolean, a row with the wrong number of cells, the same condition twice) raises
  :class:`robobore.errors.DataError` naming the file, the row (data rows counted from 1 after
  the header; blank lines count) and the column. Lines starting with ``#`` are comments.

Manifest of raw records (a CSV with a ``force_file`` and/or ``displacement_file`` column):
one row per condition, the condition columns (and optional ``posture``, ``stable``, and
``n_inserts``) plus the record files, paths relative to the manifest's folder (an empty
cell: not measured). The measured side is computed from the records by
:func:`robobore.measure.cut.cut_quantities` (``robobore measure cut``): the force
amplitudes ``force_amplitude_{x,y,z}_N`` (per-revolution half peak-to-peak, averaged) from
the force file and ``feed_amplitude_um`` from the displacement file (else from a ``z``
channel of the force file), at the row's ``speed_rpm``. Quantity columns are not allowed in a
manifest (they are computed); a missing record file is refused naming the row and column.

Relative error of a quantity: ``|simulated - measured| / |measured|`` (a fraction; the
paper quotes it in %). A measured value of 0 has no relative error: that pair is listed in
``undefined`` with the reason, never silently dropped. Conditions are split into stable and
vibratory by the *measured* ``stable`` column when the CSV has it (as the paper does: the
surface quality of the experiment decides), else by the simulated flag; for each group the
minimum, maximum and mean relative error over all its quantities (and per quantity) are
reported (the paper: 3.22-15.54 % stable, 5.61-22.56 % vibratory). The stable/vibratory
agreement is the fraction of conditions where measured and simulated ``stable`` agree.
"""

from __future__ import annotations

import csv
import io
import re
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robobore.errors import DataError
from robobore.study.conditions import CONDITION_FIELDS, DEFAULT_POSTURE
from robobore.study.summary import AMPLITUDE_QUANTITIES, SUMMARY_QUANTITIES, parse_bool

_COND_UNITS = {
    "speed_rpm": ("r/min", False),
    "feed_mm_per_rev": ("mm", False),
    "depth_of_cut_mm": ("mm", False),
    "pressure_MPa": ("MPa", True),  # zero allowed
}
KNOWN_COLUMNS = (*CONDITION_FIELDS, "posture", *SUMMARY_QUANTITIES)


def _match_key(cond: dict[str, Any], with_posture: bool) -> tuple[Any, ...]:
    k: tuple[Any, ...] = tuple(float(f"{float(cond[f]):.9g}") for f in CONDITION_FIELDS)
    if with_posture:
        k = (*k, str(cond.get("posture", DEFAULT_POSTURE)))
    return k


@dataclass(frozen=True)
class MeasuredRow:
    """One measured condition: ``row`` (1-based data row), the condition, the values."""

    row: int
    condition: dict[str, Any]
    values: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        return {"row": self.row, "condition": self.condition, "values": self.values}


@dataclass(frozen=True)
class MeasuredTable:
    """A validated measured CSV."""

    source: str
    columns: tuple[str, ...]
    quantities: tuple[str, ...]
    has_posture: bool
    rows: tuple[MeasuredRow, ...]

    #: For a manifest: per row, the record files and what was computed from them.
    records: tuple[dict[str, Any], ...] = ()

    def to_dict(self) -> dict[str, Any]:
        d = {"source": self.source, "columns": list(self.columns),
             "quantities": list(self.quantities), "rows": [r.to_dict() for r in self.rows]}
        if self.records:
            d["records"] = list(self.records)
        return d


def _parse_number(cell: str, *, source: str, row: int, col: str, unit: str,
                  allow_zero: bool) -> float:
    expected = f"a finite number {'>= 0' if allow_zero else '> 0'} in {unit}"
    try:
        v = float(cell)
    except ValueError:
        raise DataError("not a number", file=source, row=row, field=col, value=cell,
                        expected=expected) from None
    if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise DataError("number out of range", file=source, row=row, field=col, value=cell,
                        expected=expected)
    from robobore.io.ranges import check_value

    return check_value(v, col, file=source, row=row)  # plausible range (unit slips)


def parse_measured_csv(text: str, source: str = "<measured>") -> MeasuredTable:
    """Parse and validate measured-CSV text (see module doc); ``;``, tab or ``|``
    separated text is read too (:func:`robobore.io.readers.comma_separated`)."""
    from robobore.io.readers import comma_separated

    if text.startswith("\ufeff"):
        text = text[1:]
    text = comma_separated(text, KNOWN_COLUMNS)
    reader = csv.reader(io.StringIO(text))
    header: list[str] | None = None
    header_line = 0
    rows: list[MeasuredRow] = []
    seen: dict[tuple[Any, ...], int] = {}
    for cells in reader:
        line = reader.line_num
        if not cells or all(not c.strip() for c in cells):
            continue
        if cells[0].lstrip().startswith("#"):
            continue
        if header is None:
            header = [c.strip() for c in cells]
            header_line = line
            _check_header(header, source)
            continue
        row = line - header_line
        if len(cells) != len(header):
            raise DataError(f"row has {len(cells)} cells, the header has {len(header)}",
                            file=source, row=row, expected=f"{len(header)} comma-separated cells")
        rec = {h: c.strip() for h, c in zip(header, cells, strict=True)}
        cond: dict[str, Any] = {}
        for col in CONDITION_FIELDS:
            unit, allow_zero = _COND_UNITS[col]
            if rec[col] == "":
                raise DataError("empty cell", file=source, row=row, field=col,
                                expected=f"a number in {unit}")
            cond[col] = _parse_number(rec[col], source=source, row=row, col=col, unit=unit,
                                      allow_zero=allow_zero)
        if "posture" in rec:
            if rec["posture"] == "":
                raise DataError("empty cell", file=source, row=row, field="posture",
                                expected="a posture name")
            cond["posture"] = rec["posture"]
        values: dict[str, Any] = {}
        for col, unit in AMPLITUDE_QUANTITIES.items():
            if col in rec and rec[col] != "":
                values[col] = _parse_number(rec[col], source=source, row=row, col=col,
                                            unit=unit, allow_zero=True)
        if "stable" in rec and rec["stable"] != "":
            b = parse_bool(rec["stable"])
            if b is None:
                raise DataError("not a boolean", file=source, row=row, field="stable",
                                value=rec["stable"], expected="true or false")
            values["stable"] = b
        key = _match_key(cond, "posture" in rec)
        if key in seen:
            raise DataError(f"the same condition as row {seen[key]}", file=source, row=row,
                            field=",".join(CONDITION_FIELDS),
                            expected="each condition once (average repeated measurements)")
        seen[key] = row
        rows.append(MeasuredRow(row=row, condition=cond, values=values))
    if header is None:
        raise DataError("no header line", file=source,
                        expected=f"a header with columns {', '.join(CONDITION_FIELDS)}, ...")
    if not rows:
        raise DataError("no data rows", file=source, expected="at least one measured condition")
    quantities = tuple(q for q in SUMMARY_QUANTITIES if q in header)
    return MeasuredTable(source=source, columns=tuple(header), quantities=quantities,
                         has_posture="posture" in header, rows=tuple(rows))


def _check_header(header: list[str], source: str) -> None:
    for i, h in enumerate(header):
        if h == "":
            raise DataError("empty column name", file=source, row=0, field=f"column {i + 1}",
                            expected="a column name")
        if h not in KNOWN_COLUMNS:
            seps = [s for s in (";", "\t", "|", " ") if s in h]
            hint = (f" (the header is separated by {seps[0]!r}: the file needs ',' between "
                    "columns)") if seps and len(header) == 1 else ""
            raise DataError("unknown column" + hint, file=source, field=h,
                            expected=f"one of {', '.join(KNOWN_COLUMNS)}")
        if header.count(h) > 1:
            raise DataError("column appears twice", file=source, field=h,
                            expected="each column once")
    for col in CONDITION_FIELDS:
        if col not in header:
            raise DataError("missing column", file=source, field=col,
                            expected=f"columns {', '.join(CONDITION_FIELDS)}")
    if not any(q in header for q in SUMMARY_QUANTITIES):
        raise DataError("no measured quantity column", file=source,
                        expected=f"at least one of {', '.join(SUMMARY_QUANTITIES)}")


def read_measured_csv(path: str | Path, progress=None) -> MeasuredTable:
    """Read and validate a measured CSV file, or a manifest of record files whose measured
    side is computed from the records (see module doc; ``progress(done, total)`` per row of
    a manifest)."""
    p = Path(path)
    if not p.is_file():
        raise DataError("file not found", file=str(p), expected="a measured-results CSV file")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise DataError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=str(p),
                        expected="a UTF-8 CSV file") from None
    if _is_manifest(text):
        return parse_manifest_csv(text, source=str(p), base=p.parent, progress=progress)
    return parse_measured_csv(text, source=str(p))


#: Record-file columns of a manifest.
RECORD_COLUMNS = ("force_file", "displacement_file")
MANIFEST_COLUMNS = (*CONDITION_FIELDS, "posture", "stable", "n_inserts", *RECORD_COLUMNS)


def _is_manifest(text: str) -> bool:
    for line in text.lstrip("\ufeff").splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        cells = re.split(r"[,;\t|]", line)  # any of the separators a measured CSV may use
        return any(c.strip() in RECORD_COLUMNS for c in cells)
    return False


def parse_manifest_csv(text: str, source: str = "<manifest>", base: str | Path = ".",
                       progress=None) -> MeasuredTable:
    """A manifest (module doc) -> the measured table, its quantities computed from the
    record files (paths relative to ``base``)."""
    from robobore.measure.cut import cut_quantities, read_cut_record

    from robobore.io.readers import comma_separated

    if text.startswith("\ufeff"):
        text = text[1:]
    text = comma_separated(text, MANIFEST_COLUMNS)  # ';', tab or '|' separated: read too
    lines = [(i + 1, c) for i, c in enumerate(csv.reader(io.StringIO(text)))
             if c and not all(not x.strip() for x in c) and not c[0].lstrip().startswith("#")]
    header_line, header = lines[0][0], [h.strip() for h in lines[0][1]]
    for h in header:
        if h not in MANIFEST_COLUMNS:
            extra = (" (a manifest's quantities are computed from its record files)"
                     if h in SUMMARY_QUANTITIES else "")
            raise DataError("unknown manifest column" + extra, file=source, field=h,
                            expected=f"one of {', '.join(MANIFEST_COLUMNS)}")
        if header.count(h) > 1:
            raise DataError("column appears twice", file=source, field=h,
                            expected="each column once")
    for col in CONDITION_FIELDS:
        if col not in header:
            raise DataError("missing column", file=source, field=col,
                            expected=f"columns {', '.join(CONDITION_FIELDS)}")
    rows: list[MeasuredRow] = []
    recs: list[dict[str, Any]] = []
    seen: dict[tuple[Any, ...], int] = {}
    found: set[str] = set()
    body = lines[1:]
    for n_done, (line, cells) in enumerate(body):
        row = line - header_line
        if len(cells) != len(header):
            raise DataError(f"row has {len(cells)} cells, the header has {len(header)}",
                            file=source, row=row, expected=f"{len(header)} comma-separated cells")
        rec = {h: c.strip() for h, c in zip(header, cells, strict=True)}
        cond: dict[str, Any] = {}
        for col in CONDITION_FIELDS:
            unit, allow_zero = _COND_UNITS[col]
            if rec[col] == "":
                raise DataError("empty cell", file=source, row=row, field=col,
                                expected=f"a number in {unit}")
            cond[col] = _parse_number(rec[col], source=source, row=row, col=col, unit=unit,
                                      allow_zero=allow_zero)
        if "posture" in rec:
            cond["posture"] = rec["posture"] or DEFAULT_POSTURE
        n_ins = 1
        if rec.get("n_inserts", ""):
            try:
                n_ins = int(rec["n_inserts"])
            except ValueError:
                n_ins = 0
            if not 1 <= n_ins <= 100:
                raise DataError("not a number of inserts", file=source, row=row,
                                field="n_inserts", value=rec["n_inserts"],
                                expected="an integer 1 .. 100")
        values: dict[str, Any] = {}
        info: dict[str, Any] = {"row": row}
        for col in RECORD_COLUMNS:
            name = rec.get(col, "")
            if not name:
                continue
            path = Path(base) / name
            if not path.is_file():
                raise DataError("record file not found", file=source, row=row, field=col,
                                value=name, expected="a record file, relative to the manifest")
            crec = read_cut_record(path)
            q = cut_quantities(crec, cond["speed_rpm"], n_ins)
            info[col] = {"file": str(path), "kind": crec.kind, "chatter": q["chatter"],
                         "chatter_frequency_Hz": q["chatter_frequency_Hz"],
                         "cutting_time_s": q["cutting_time_s"]}
            if col == "force_file":
                for ax, v in q.get("force_amplitude_N", {}).items():
                    values[f"force_amplitude_{ax}_N"] = v
                if q.get("feed_amplitude_um") is not None and "feed_amplitude_um" not in values:
                    values["feed_amplitude_um"] = q["feed_amplitude_um"]
            elif q.get("feed_amplitude_um") is not None:
                values["feed_amplitude_um"] = q["feed_amplitude_um"]
            else:
                raise DataError("no feed-direction (z) displacement in the record", file=source,
                                row=row, field=col, value=name,
                                expected="a z displacement column (z_um, z [mm], ...)")
        if "stable" in rec and rec["stable"] != "":
            b = parse_bool(rec["stable"])
            if b is None:
                raise DataError("not a boolean", file=source, row=row, field="stable",
                                value=rec["stable"], expected="true or false")
            values["stable"] = b
        key = _match_key(cond, "posture" in rec)
        if key in seen:
            raise DataError(f"the same condition as row {seen[key]}", file=source, row=row,
                            field=",".join(CONDITION_FIELDS),
                            expected="each condition once (one record set per condition)")
        seen[key] = row
        found.update(values)
        if not any(rec.get(col, "") for col in RECORD_COLUMNS):
            raise DataError("no record file in this row", file=source, row=row,
                            field=", ".join(c for c in RECORD_COLUMNS if c in header),
                            expected="a force_file and/or displacement_file to measure (a "
                                     "condition not measured: leave its row out)")
        rows.append(MeasuredRow(row=row, condition=cond, values=values))
        recs.append(info)
        if progress is not None:
            progress(n_done + 1, len(body))
    if not rows:
        raise DataError("no data rows", file=source, expected="at least one measured condition")
    if not found:
        raise DataError("no record file in any row", file=source,
                        field=", ".join(RECORD_COLUMNS), expected="record files to measure")
    quantities = tuple(q for q in SUMMARY_QUANTITIES if q in found)
    return MeasuredTable(source=source, columns=tuple(header), quantities=quantities,
                         has_posture="posture" in header, rows=tuple(rows),
                         records=tuple(recs))


@dataclass(frozen=True, slots=True)
class Comparison:
    """Result of :func:`compare` (all relative errors are fractions, not %). ``to_dict()``:
    the ``robobore compare --json`` keys before ``measured`` and ``results`` (contract in
    tests/study/contract/compare.json)."""

    #: one row per matched condition: condition, group, per-quantity measured / simulated /
    #: relative error (``conditions`` in the JSON)
    rows: tuple[dict[str, Any], ...]
    #: the relative-error statistics per group and quantity
    groups: dict[str, dict[str, Any]]
    #: the agreement over all rows per quantity
    agreement: dict[str, Any]
    #: where the groups come from ("measured" or "simulated")
    group_source: str
    #: measured rows without a simulated condition
    unmatched_measured: tuple[dict[str, Any], ...] = field(default_factory=tuple)
    #: quantities whose relative error is undefined (a zero measured value, no simulated
    #: value), with the reason
    undefined: tuple[dict[str, Any], ...] = field(default_factory=tuple)
    #: the compared quantities
    quantities: tuple[str, ...] = field(default_factory=tuple)
    #: the simulated system compared (e.g. "robot")
    system: str | None = None
    #: the systems in the results store (``systems_in_store`` in the JSON)
    systems: tuple[str, ...] = field(default_factory=tuple)
    #: likely unit slips: a measured column off the simulation by a power of ten in most
    #: rows; with :func:`compare_results` also the compared runs' coefficient warnings
    warnings: tuple[str, ...] = field(default_factory=tuple)
    #: a manifest's records (``measured_records`` in the JSON, with ``measured_synthetic``)
    records: tuple[dict[str, Any], ...] = field(default_factory=tuple)

    def to_dict(self) -> dict[str, Any]:
        return {
            "system": self.system, "systems_in_store": list(self.systems),
            "quantities": list(self.quantities), "group_source": self.group_source,
            "groups": self.groups, "agreement": self.agreement, "conditions": list(self.rows),
            "unmatched_measured": list(self.unmatched_measured), "undefined": list(self.undefined),
            "warnings": list(self.warnings),
            **({"measured_records": list(self.records),
                "measured_synthetic": any(isinstance(v, dict) and v.get("kind") == "SYNTHETIC"
                                          for r in self.records for v in r.values())}
               if self.records else {}),
        }

    def table_rows(self) -> list[dict[str, Any]]:
        """Flat rows (one per condition and amplitude quantity) for tables and CSV."""
        out = []
        for r in self.rows:
            for q, e in r["quantities"].items():
                out.append({**{f: r["condition"][f] for f in CONDITION_FIELDS},
                            "group": r["group"], "quantity": q, "measured": e["measured"],
                            "simulated": e["simulated"], "rel_error_pct":
                            None if e["rel_error"] is None else 100.0 * e["rel_error"]})
        return out


def _stats(errors: list[float]) -> dict[str, Any]:
    if not errors:
        return {"n": 0, "min_rel_error": None, "max_rel_error": None, "mean_rel_error": None}
    return {"n": len(errors), "min_rel_error": min(errors), "max_rel_error": max(errors),
            "mean_rel_error": sum(errors) / len(errors)}


def compare(measured: MeasuredTable,
            simulated: Iterable[tuple[dict[str, Any], dict[str, Any]]]) -> Comparison:
    """Compare measured rows with simulated ``(condition, summary)`` pairs.

    Matching is on the four condition values (to 9 significant digits) and, when the CSV
    has a ``posture`` column, the posture. Two simulated results for one measured condition
    (e.g. two model configs in one store) are an error: compare one sweep at a time.
    """
    sims: dict[tuple[Any, ...], tuple[dict[str, Any], dict[str, Any]]] = {}
    for cond, summ in simulated:
        k = _match_key(cond, measured.has_posture)
        if k in sims:
            raise DataError(
                "two simulated results for one condition "
                f"({', '.join(f'{f}={cond[f]}' for f in CONDITION_FIELDS)}): the results "
                "hold more than one model or posture for it",
                expected="one simulated result per condition: one system at a time "
                         "(robobore compare --system NAME), a posture column in the CSV when "
                         "they differ by posture, or one sweep per results folder",
            )
        sims[k] = (cond, summ)

    use_measured_flag = "stable" in measured.quantities
    rows: list[dict[str, Any]] = []
    unmatched: list[dict[str, Any]] = []
    undefined: list[dict[str, Any]] = []
    per_group: dict[str, dict[str, list[float]]] = {"stable": {}, "vibratory": {}, "unknown": {}}
    confusion = {"both_stable": 0, "both_vibratory": 0,
                 "measured_stable_simulated_vibratory": 0,
                 "measured_vibratory_simulated_stable": 0}
    for m in measured.rows:
        k = _match_key(m.condition, measured.has_posture)
        if k not in sims:
            unmatched.append({"row": m.row, "condition": m.condition})
            continue
        scond, ssum = sims[k]
        ms, ss = m.values.get("stable"), ssum.get("stable")
        flag = ms if use_measured_flag else ss
        group = "unknown" if flag is None else ("stable" if flag else "vibratory")
        qres: dict[str, Any] = {}
        for q in AMPLITUDE_QUANTITIES:
            if q not in m.values:
                continue
            mv, sv = m.values[q], ssum.get(q)
            if sv is None:
                undefined.append({"row": m.row, "quantity": q,
                                  "reason": "the simulation does not give this quantity"})
                qres[q] = {"measured": mv, "simulated": None, "rel_error": None}
                continue
            if mv == 0.0:
                undefined.append({"row": m.row, "quantity": q,
                                  "reason": "measured value is 0: relative error undefined"})
                qres[q] = {"measured": mv, "simulated": sv, "rel_error": None}
                continue
            e = abs(sv - mv) / abs(mv)
            qres[q] = {"measured": mv, "simulated": sv, "rel_error": e}
            per_group[group].setdefault(q, []).append(e)
        agree = None
        if ms is not None and ss is not None:
            agree = ms == ss
            if ms and ss:
                confusion["both_stable"] += 1
            elif not ms and not ss:
                confusion["both_vibratory"] += 1
            elif ms:
                confusion["measured_stable_simulated_vibratory"] += 1
            else:
                confusion["measured_vibratory_simulated_stable"] += 1
        rows.append({"row": m.row, "condition": {**scond, **m.condition}, "group": group,
                     "stable_measured": ms, "stable_simulated": ss, "stable_agree": agree,
                     "quantities": qres})
    if not rows:
        raise DataError(
            "no measured condition matches a simulated one", file=measured.source,
            expected="rows whose speed_rpm, feed_mm_per_rev, depth_of_cut_mm, pressure_MPa "
            "equal those of the sweep",
        )
    groups = {}
    for g, qs in per_group.items():
        if g == "unknown" and not qs:
            continue
        allv = [e for v in qs.values() for e in v]
        groups[g] = {**_stats(allv),
                     "n_conditions": sum(1 for r in rows if r["group"] == g),
                     "per_quantity": {q: _stats(v) for q, v in qs.items()}}
    warn = _unit_slip_warnings(rows, measured.source)
    n_cmp = sum(confusion.values())
    agreement = {"n": n_cmp, "agree": confusion["both_stable"] + confusion["both_vibratory"],
                 "rate": None if n_cmp == 0 else
                 (confusion["both_stable"] + confusion["both_vibratory"]) / n_cmp,
                 **confusion}
    return Comparison(
        rows=tuple(rows), groups=groups, agreement=agreement,
        group_source="measured" if use_measured_flag else "simulated",
        unmatched_measured=tuple(unmatched), undefined=tuple(undefined),
        quantities=measured.quantities, warnings=tuple(warn),
    )


#: a measured column whose median |log10(simulated / measured)| reaches this (two decades)
#: over at least :data:`UNIT_SLIP_MIN_ROWS` rows is reported as a likely unit slip
UNIT_SLIP_DECADES = 2.0
UNIT_SLIP_MIN_ROWS = 3


def _unit_slip_warnings(rows: list[dict[str, Any]], source: str) -> list[str]:
    import math
    import statistics

    out = []
    by_q: dict[str, list[float]] = {}
    for r in rows:
        for q, e in r["quantities"].items():
            mv, sv = e["measured"], e["simulated"]
            if mv and sv and mv > 0 and sv > 0:
                by_q.setdefault(q, []).append(math.log10(sv / mv))
    for q, lr in by_q.items():
        if len(lr) >= UNIT_SLIP_MIN_ROWS:
            med = statistics.median(lr)
            if abs(med) >= UNIT_SLIP_DECADES:
                out.append(f"{source}, column '{q}': the simulation is {10 ** med:.3g} times "
                           f"the measurement (median over {len(lr)} rows): a unit slip in the "
                           "measured column (mm for um, N for kN, ...)? The relative errors "
                           "of this column are not meaningful")
    return out


#: label of results whose store does not name the simulated system (``robobore sweep``)
UNLABELLED = "sweep"


def result_system(path: str | Path) -> str:
    """The simulated system of a stored result: ``runner_options.system`` of its stored config
    (``robobore paper`` labels ``robot`` and ``machine_tool``), else :data:`UNLABELLED`."""
    import json

    import netCDF4

    try:
        with netCDF4.Dataset(path) as nc:
            text = nc.getncattr("robobore_config") if "robobore_config" in nc.ncattrs() else ""
    except OSError as exc:
        raise DataError(f"cannot read result file ({exc})", file=str(path)) from None
    try:
        cfg = json.loads(text) if text else {}
    except ValueError:
        cfg = {}
    opts = cfg.get("runner_options") if isinstance(cfg, dict) else None
    label = opts.get("system") if isinstance(opts, dict) else None
    return str(label) if label else UNLABELLED


def resolve_store_dir(results_dir: str | Path) -> Path:
    """The results store in ``results_dir``: the folder itself or, for the output folder of
    ``robobore paper``, its ``sweep`` store."""
    p = Path(results_dir)
    if not (p / "store.json").is_file() and (p / "sweep" / "store.json").is_file():
        return p / "sweep"
    return p


def compare_results(measured_csv: str | Path, results_dir: str | Path,
                    system: str | None = None, progress=None) -> Comparison:
    """Compare a measured CSV with the finished conditions of a results store.

    ``results_dir``: a store (``robobore sweep``) or the output folder of ``robobore paper``
    (its ``sweep`` store). A store may hold several simulated systems (the paper's robot and
    machine tool, told apart by :func:`result_system`); ``system`` chooses one, and by
    default the robot is compared when the store holds it next to others. A manifest's
    records are measured first (``progress(task, done, total)`` per record row)."""
    from robobore.study.store import ResultsStore

    table = read_measured_csv(measured_csv, None if progress is None else (
        lambda done, total: progress("measuring records", done, total)))
    store_dir = resolve_store_dir(results_dir)
    store = ResultsStore.open_existing(store_dir)
    by_system: dict[str, list[tuple[dict[str, Any], dict[str, Any]]]] = {}
    coef_w: dict[str, list[tuple[dict[str, Any], tuple[str, ...]]]] = {}
    for r in store.records():
        sysname = result_system(r.path)
        by_system.setdefault(sysname, []).append((r.condition, r.summary))
        coef_w.setdefault(sysname, []).append((r.condition, r.coefficient_warnings))
    if not by_system:
        raise DataError("the results store has no finished condition", file=str(store_dir),
                        expected="a folder with results written by 'robobore sweep' or "
                                 "'robobore paper'")
    systems = tuple(sorted(by_system))
    if system is not None:
        if system not in by_system:
            raise DataError("no results of this system in the store", file=str(store_dir),
                            field="--system", value=system,
                            expected=f"one of {', '.join(systems)}")
        chosen = system
    elif len(systems) == 1:
        chosen = systems[0]
    elif "robot" in by_system:
        chosen = "robot"
    else:
        raise DataError("the store holds results of several systems", file=str(store_dir),
                        field="--system", expected=f"--system with one of {', '.join(systems)}")
    cmp = compare(table, by_system[chosen])
    from dataclasses import replace

    warn = cmp.warnings + coefficient_warnings(cmp, coef_w[chosen], table.has_posture)
    return replace(cmp, system=chosen, systems=systems, records=table.records,
                   warnings=warn)


def coefficient_warnings(cmp: Comparison,
                         runs: Iterable[tuple[dict[str, Any], tuple[str, ...]]],
                         with_posture: bool) -> tuple[str, ...]:
    """The coefficient warnings of the simulated runs ``cmp`` compares (``(condition,
    warnings)`` per stored run: the runner's ``coefficient_warnings``, a set used outside its
    calibrated speeds or chip thicknesses), one line per distinct warning with the number
    of compared conditions it applies to (:func:`robobore.study.sweep.coefficient_warning_lines`)."""
    from robobore.study.sweep import coefficient_warning_lines

    by_key = {_match_key(c, with_posture): w for c, w in runs}
    counts: dict[str, int] = {}
    for r in cmp.rows:
        for w in by_key.get(_match_key(r["condition"], with_posture), ()):
            counts[w] = counts.get(w, 0) + 1
    return coefficient_warning_lines(counts, len(cmp.rows))


__all__ = [
    "KNOWN_COLUMNS",
    "MeasuredRow",
    "MeasuredTable",
    "Comparison",
    "parse_measured_csv",
    "parse_manifest_csv",
    "read_measured_csv",
    "RECORD_COLUMNS",
    "compare",
    "compare_results",
    "coefficient_warnings",
    "result_system",
    "resolve_store_dir",
]
