"""Measured time records: one validated type and the readers of its file formats.

A :class:`Record` holds ``signals`` of shape ``(n_channels, n_samples)`` sampled uniformly at
``sample_rate_Hz``, the channel names and units, and where it came from. Readers
(:func:`read_record`) take:

* **CSV** (``.csv``, ``.txt``): a header line of column names, then one row per sample; a
  ``time_s`` column (seconds; also ``t_s``, ``time`` or ``t`` with its unit, ``Time [s]``,
  ``time (ms)``, ``t [us]``: read in s) or a sample rate given
  by the caller; every other column is a signal channel, but for a data frame's row index (an
  unnamed or ``index`` column counting 0, 1, 2 ... or 1, 2, 3 ..., as pandas and R write
  it). Separators ``,``, ``;`` or tab; quoted cells; with ``;`` or tab a decimal comma; a
  trailing separator on every line (an empty last column) is ignored. Lines starting with
  ``#`` are comments.
* **NPZ**: 1-D arrays of equal length, one per channel, plus ``time_s`` (1-D) or
  ``sample_rate_Hz`` (a scalar); or one 2-D ``signals`` array ``(n_channels, n_samples)``
  with ``channels`` (names) and ``sample_rate_Hz``.
* **UFF** (``.uff``, ``.unv``): dataset 58 time records (``func_type`` 1), one per channel,
  all with the same sampling.
* **WAV**: the channels of the file at its sample rate (integer PCM scaled to +-1).

Every reader checks the record before it is used: a time column that decreases or is not
uniform (a step more than 20 % off the median step, or a time more than a quarter step off
the uniform grid: a missing sample; times written with few decimals may be off by half their
last digit, a step by one), non-finite samples,
fewer than :data:`MIN_SAMPLES` samples, or a file whose parsed size would not fit in memory
(estimated from the file size before reading) are refused with a
:class:`~robobore.errors.DataError` naming the file, the row or column, the value and what
was expected.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robobore.errors import DataError

#: Fewest samples a record may have (a spectrum needs a few periods of anything).
MIN_SAMPLES = 64
#: Largest relative deviation of one time step from the median step (rounding of the
#: written times, float32 clocks: 2 % at 30 s and 10 kHz) ...
STEP_TOLERANCE = 0.2
#: ... and of a time from the uniform grid, in steps (a missing or repeated sample shifts the
#: grid by one step).
GRID_TOLERANCE = 0.25
#: A cutting record sampled slower than this (Hz) shows neither chatter nor the revolutions
#: (a time column in ms read as s gives 1000 x slower rates)
MIN_RECORD_RATE_HZ = 100.0


@dataclass(frozen=True)
class Record:
    """A uniformly sampled multi-channel record.

    ``signals``: ``(n_channels, n_samples)`` float64 in the channels' units; ``units``: one
    unit string per channel (``""`` when the file does not say); ``kind``: ``"measured"`` or
    ``"SYNTHETIC"``; ``truth``: the generator's ground truth for a SYNTHETIC record.
    """

    signals: np.ndarray
    sample_rate_Hz: float
    channels: tuple[str, ...]
    units: tuple[str, ...]
    source: str = "<record>"
    t0_s: float = 0.0
    kind: str = "measured"
    truth: dict[str, Any] = field(default_factory=dict)

    @property
    def n_channels(self) -> int:
        return int(self.signals.shape[0])

    @property
    def n_samples(self) -> int:
        return int(self.signals.shape[1])

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.sample_rate_Hz

    def channel(self, name: str) -> Record:
        """The record reduced to one channel (``DataError`` naming the channels if unknown)."""
        if name not in self.channels:
            raise DataError("no such channel", file=self.source, field="--channel", value=name,
                            expected=f"one of {', '.join(self.channels)}")
        i = self.channels.index(name)
        return Record(self.signals[i:i + 1], self.sample_rate_Hz, (name,), (self.units[i],),
                      self.source, self.t0_s, self.kind, self.truth)

    def to_dict(self) -> dict[str, Any]:
        """Metadata (not the samples)."""
        return {"source": self.source, "kind": self.kind, "channels": list(self.channels),
                "units": list(self.units), "sample_rate_Hz": self.sample_rate_Hz,
                "n_samples": self.n_samples, "duration_s": self.duration_s, "t0_s": self.t0_s}


def make_record(signals: Any, sample_rate_Hz: float, channels: list[str] | tuple[str, ...],
                units: list[str] | tuple[str, ...] | None = None, source: str = "<record>",
                t0_s: float = 0.0, kind: str = "measured",
                truth: dict[str, Any] | None = None) -> Record:
    """Validate arrays into a :class:`Record` (the checks of the module docstring)."""
    x = np.asarray(signals, dtype=float)
    if x.ndim == 1:
        x = x[None, :]
    if x.ndim != 2:
        raise DataError("signals must be (n_channels, n_samples)", file=source,
                        value=f"shape {x.shape}", expected="a 2-D array")
    chans = tuple(str(c) for c in channels)
    if len(chans) != x.shape[0]:
        raise DataError("one name per channel", file=source, value=len(chans),
                        expected=f"{x.shape[0]} channel names")
    fs = float(sample_rate_Hz)
    if not (math.isfinite(fs) and fs > 0):
        raise DataError("sample rate must be positive", file=source, field="sample_rate_Hz",
                        value=sample_rate_Hz, expected="a rate > 0 in Hz")
    check_samples(x, chans, source)
    u = tuple("" for _ in chans) if units is None else tuple(str(v) for v in units)
    return Record(np.ascontiguousarray(x), fs, chans, u, source, float(t0_s), kind,
                  dict(truth or {}))


def check_samples(x: np.ndarray, channels: tuple[str, ...], source: str,
                  first_row: int = 1) -> None:
    """Refuse too few samples and non-finite samples (naming row and column)."""
    if x.shape[1] < MIN_SAMPLES:
        raise DataError("too few samples for a spectrum", file=source, value=x.shape[1],
                        expected=f"at least {MIN_SAMPLES} samples")
    bad = ~np.isfinite(x)
    if bad.any():
        ch, row = np.argwhere(bad)[0]
        raise DataError("non-finite sample", file=source, row=int(row) + first_row,
                        field=channels[int(ch)], value=float(x[ch, row]),
                        expected="a finite number in every row (fill or cut the gap)")


def _time_quantum(t: np.ndarray) -> float:
    """The resolution the times were written with: the largest ``10^-d`` (``d`` = 0 .. 12) of
    which every time is a multiple (to a thousandth of it), 0 where none is."""
    for d in range(13):
        v = t * 10.0 ** d
        if np.all(np.abs(v - np.round(v)) < 1e-3):
            return 10.0 ** -d
    return 0.0


def sample_rate_from_time(t: np.ndarray, source: str, column: str = "time_s",
                          first_row: int = 1) -> tuple[float, float]:
    """``(sample_rate_Hz, t0_s)`` of a time column; refuses a decreasing, repeated or
    non-uniform time (naming the row)."""
    t = np.asarray(t, float)
    if t.size < 2:
        raise DataError("too few samples for a spectrum", file=source, value=int(t.size),
                        expected=f"at least {MIN_SAMPLES} samples")
    if not np.all(np.isfinite(t)):
        i = int(np.argmax(~np.isfinite(t)))
        raise DataError("non-finite time", file=source, row=i + first_row, field=column,
                        value=float(t[i]), expected="a finite time in s")
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.argmax(d <= 0)) + 1
        raise DataError("time does not increase", file=source, row=i + first_row, field=column,
                        value=float(t[i]), expected=f"a time after {t[i - 1]!r} s "
                        "(samples in time order, each once)")
    dt = (t[-1] - t[0]) / (t.size - 1)
    med = float(np.median(d))
    dev = np.abs(t - (t[0] + dt * np.arange(t.size)))
    step_bad = np.abs(d - med) > STEP_TOLERANCE * med
    grid_bad = dev > GRID_TOLERANCE * dt
    if step_bad.any() or grid_bad.any():
        # times written with few decimals: each within half a printed digit of the grid
        q = _time_quantum(t)
        step_bad = np.abs(d - med) > max(STEP_TOLERANCE * med, 1.01 * q)
        grid_bad = dev > max(GRID_TOLERANCE * dt, 0.51 * q)
    if step_bad.any() or grid_bad.any():
        # a gap or a repeat is a bad step there, else the first time off the grid
        i = max(1, int(np.argmax(step_bad)) + 1 if step_bad.any() else int(np.argmax(grid_bad)))
        raise DataError("time is not uniformly sampled", file=source, row=i + first_row,
                        field=column, value=float(t[i]),
                        expected=f"steps of {med:.6g} s (each within "
                        f"{100 * STEP_TOLERANCE:g} %, every time within "
                        f"{100 * GRID_TOLERANCE:g} % of a step of the uniform grid; step here "
                        f"{d[i - 1]:.6g} s; resample the record or give each uniform part "
                        "as its own file)")
    if 1.0 / dt < MIN_RECORD_RATE_HZ:
        raise DataError(f"time step {dt:.6g} s: {1.0 / dt:.4g} Hz, too slow for a cutting "
                        "record (a time column in ms read as s?)", file=source, field=column,
                        value=float(t[1]),
                        expected=f"times in s, a sample rate of at least "
                                 f"{MIN_RECORD_RATE_HZ:g} Hz")
    return 1.0 / dt, float(t[0])


def guard_size(path: Path, bytes_per_file_byte: float, what: str) -> None:
    """Refuse a file whose parsed size (estimated from its size on disk) does not fit in
    memory, before reading it (:func:`robobore.io.memory.check_memory`)."""
    from robobore.io.memory import check_memory

    size = path.stat().st_size
    check_memory(size * bytes_per_file_byte, f"reading {what} ({size / 2**20:.4g} MiB on disk)",
                 "the record's length (split it into shorter files)", file=str(path))


#: Time units a CSV header may declare (``time [ms]``), in s.
TIME_UNITS_S = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}


def time_column(header: list[str], source: str | None = None) -> tuple[int, float] | None:
    """The time column of a table's header and the factor of its unit to s, or None: the
    first column named ``time_s`` or ``t_s`` (unit s or none), or ``time`` or ``t`` (unit
    none or one of :data:`TIME_UNITS_S`: ``Time [s]``, ``time (ms)``: 1e-3). With ``source``
    (the file), a ``time`` column in another unit (``time [min]``) is a :class:`DataError`,
    not a signal."""
    for i, h in enumerate(header):
        name, unit = split_unit(h)
        name = name.lower()
        if name in ("time_s", "t_s") and unit in ("", "s"):
            return i, 1.0
        if name in ("time", "t") and (unit == "" or unit in TIME_UNITS_S):
            return i, TIME_UNITS_S.get(unit, 1.0)
        if name == "time" and source is not None:
            raise DataError("unknown time unit", file=source, field=h, value=unit,
                            expected=f"a time in {', '.join(TIME_UNITS_S)}")
    return None


_UNIT_RE = re.compile(r"^(?P<name>.*?)\s*(?:\[(?P<b>[^\]]*)\]|\((?P<p>[^)]*)\))\s*$")


def split_unit(column: str) -> tuple[str, str]:
    """``"Fx [kN]"`` / ``"Fx (kN)"`` -> ``("Fx", "kN")``; ``"acc_x_m_s2"`` -> unchanged
    name and ``""`` (suffix units are read by the callers that know their quantities)."""
    m = _UNIT_RE.match(column.strip())
    if m:
        return m.group("name").strip(), (m.group("b") or m.group("p") or "").strip()
    return column.strip(), ""


def read_csv_table(path: Path, what: str = "a record CSV", skip_lines: int = 0,
                   delimiter: str | None = None, header: list[str] | None = None
                   ) -> tuple[list[str], np.ndarray, int]:
    """Header and numeric rows of a CSV ``(header, data (n_rows, n_cols), header_line)``;
    ``#`` comments and blank lines skipped. Bad cells are reported with row and column.

    The samples are parsed from the open file (never the whole text in memory); before that
    the number of rows is estimated from the file size and the length of the first lines, and
    a table that would not fit in memory is refused with its estimate. ``skip_lines``: lines
    before the header (a header block); ``delimiter`` and ``header``: given by a caller that
    has read the header itself (the header line is then line ``skip_lines + 1``)."""
    src = str(path)
    size = path.stat().st_size
    try:
        fh = path.open("r", encoding="utf-8-sig", newline="")
        with fh:
            for _ in range(skip_lines):
                fh.readline()
            line_no = skip_lines
            if header is None:
                while True:
                    ln = fh.readline()
                    if not ln:
                        raise DataError("no header line", file=src,
                                        expected=f"{what} with a header")
                    line_no += 1
                    st = ln.strip()
                    if st and not st.startswith("#"):
                        break
                delim = ";" if ln.count(";") > ln.count(",") else ","
                if delim == "," and "," not in ln and "\t" in ln:
                    delim = "\t"
                # CSV quoting ("time_s","acc", as R and spreadsheets write it) is read
                header = [h.strip() for h in next(csv.reader([ln.rstrip("\r\n")],
                                                            delimiter=delim))]
            else:
                fh.readline()
                line_no += 1
                delim = delimiter or ","
            header_line = line_no
            start = fh.tell()
            probe = [fh.readline() for _ in range(200)]
            probe = [x for x in probe if x]
            rows = [x.rstrip("\r\n") for x in probe
                    if x.strip() and not x.lstrip().startswith("#")]
            usecols = None
            if len(header) > 1 and header[-1] == "" and rows and all(
                    r.endswith(delim) for r in rows):  # a trailing delimiter on every line
                header = header[:-1]
                usecols = range(len(header))
            # a decimal comma (a ';' or tab separated export of a comma-decimal locale)
            comma = delim in (";", "\t") and any("," in r for r in rows)
            per_line = max(1.0, sum(len(x.encode()) for x in probe) / max(1, len(probe)))
            rows_est = size / per_line
            from robobore.io.memory import check_memory

            check_memory(rows_est * len(header) * 8.0 * 3.0,
                         f"reading {what} (about {rows_est:.3g} rows x {len(header)} columns, "
                         f"{size / 2**20:.4g} MiB on disk)",
                         "the record's length (split it into shorter files)", file=src)
            fh.seek(start)
            try:
                data = np.loadtxt(fh, delimiter=None if delim == " " else delim,
                                  comments="#", dtype=float, ndmin=2, quotechar='"',
                                  usecols=usecols,
                                  converters=_comma_float if comma else None)
            except ValueError:
                data = None
            if data is None or data.shape[1] != len(header) or data.shape[0] == 0:
                fh.seek(start)
                _locate_bad_row(fh, header, src, delim, comma, usecols is not None)
                raise DataError("no data rows", file=src, expected="one row per sample")
    except UnicodeDecodeError as exc:
        raise DataError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=src,
                        expected=f"{what} in UTF-8") from None
    return header, data, header_line


def _comma_float(cell: str) -> float:
    """A number written with a decimal comma (``"0,125"``)."""
    return float(cell.replace(",", "."))


def _locate_bad_row(lines: Any, header: list[str], source: str, delim: str | None,
                    comma: bool = False, trailing: bool = False) -> None:
    """Raise the error of the first bad data row of ``lines`` (an iterable of text lines);
    rows are counted from 1 after the header, blank and comment lines included. Cells may be
    quoted; ``comma``: numbers written with a decimal comma; ``trailing``: every line ends
    with a separator (its empty last cell is not a column)."""
    n = 0
    for ln in lines:
        n += 1
        if not ln.strip() or ln.lstrip().startswith("#"):
            continue
        text = ln.rstrip("\r\n")
        cells = next(csv.reader([text], delimiter=delim)) if delim else text.split()
        if trailing and len(cells) == len(header) + 1 and cells[-1].strip() == "":
            cells = cells[:-1]
        if len(cells) != len(header):
            raise DataError(f"row has {len(cells)} cells, the header has {len(header)}",
                            file=source, row=n, expected=f"{len(header)} cells")
        for h, c in zip(header, cells, strict=True):
            try:
                _comma_float(c) if comma else float(c)
            except ValueError:
                raise DataError("not a number", file=source, row=n, field=h,
                                value=c.strip(), expected="a number") from None


def parse_rows(body: list[str], header: list[str], source: str, header_line: int,
               delim: str | None) -> np.ndarray:
    """Numeric rows (``n_rows, n_cols``) of text lines; a bad row is named by its data row
    (1-based after the header)."""
    rows = [ln for ln in body if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows:
        raise DataError("no data rows", file=source, expected="one row per sample")
    try:
        data = np.loadtxt(rows, delimiter=delim, dtype=float, ndmin=2)
    except ValueError:
        data = None
    if data is None or data.shape[1] != len(header):
        _locate_bad_row(body, header, source, delim)
        raise DataError("unreadable rows", file=source, expected="numbers in every cell")
    return data


def _read_csv(path: Path, sample_rate_Hz: float | None) -> Record:
    header, data, _ = read_csv_table(path)
    src = str(path)
    tc = time_column(header, src)
    ti, t_scale = tc if tc is not None else (None, 1.0)
    if ti is None and sample_rate_Hz is None:
        raise DataError("no time column and no sample rate", file=src, field="time_s",
                        expected="a 'time_s' column in s, or --sample-rate-hz")
    if ti is not None and sample_rate_Hz is not None:
        raise DataError("both a time column and a sample rate", file=src,
                        field="--sample-rate-hz", value=sample_rate_Hz,
                        expected="one of them (the time column is read)")
    cols = [i for i in range(len(header)) if i != ti and not _row_index(header[i], data[:, i])]
    if not cols:
        raise DataError("no signal column", file=src, expected="one or more signal columns "
                        "besides the time")
    names, units = [], []
    for i in cols:
        nm, un = split_unit(header[i])
        names.append(nm or f"column {i + 1}")
        units.append(un)
    x = data[:, cols].T
    check_samples(x, tuple(names), src)
    if ti is not None:
        fs, t0 = sample_rate_from_time(data[:, ti] * t_scale, src, header[ti])
    else:
        fs, t0 = float(sample_rate_Hz), 0.0
    return make_record(x, fs, names, units, src, t0)


#: Headers of the row-index column a data frame writes (pandas ``to_csv``, R ``write.csv``).
INDEX_COLUMNS = ("", "index", "unnamed: 0")


def _row_index(name: str, values: np.ndarray) -> bool:
    """Whether a CSV column is a data frame's row index, not a signal: an unnamed (or
    ``index``) column counting 0, 1, 2 ... or 1, 2, 3 ..."""
    return (name.strip().lower() in INDEX_COLUMNS and values.size > 1
            and values[0] in (0.0, 1.0) and bool(np.all(np.diff(values) == 1.0)))


def _read_npz(path: Path, sample_rate_Hz: float | None) -> Record:
    src = str(path)
    guard_size(path, 1.5, "an NPZ record")
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise DataError(f"not a readable NPZ file ({exc})", file=src,
                        expected="an NPZ archive of arrays") from None
    with z:
        keys = list(z.files)
        fs = sample_rate_Hz
        if "sample_rate_Hz" in keys:
            fs = float(np.asarray(z["sample_rate_Hz"]).reshape(-1)[0])
        t0 = 0.0
        if "signals" in keys:
            x = np.asarray(z["signals"], float)
            if x.ndim == 1:
                x = x[None, :]
            names = ([str(c) for c in z["channels"]] if "channels" in keys
                     else [f"ch{i}" for i in range(x.shape[0])])
            units = [str(u) for u in z["units"]] if "units" in keys else None
        else:
            skip = {"time_s", "sample_rate_Hz", "units", "channels"}
            names = [k for k in keys if k not in skip]
            arrs = [np.asarray(z[k], float) for k in names]
            for k, a in zip(names, arrs, strict=True):
                if a.ndim != 1:
                    raise DataError("channel array is not 1-D", file=src, field=k,
                                    value=f"shape {a.shape}", expected="one 1-D array per "
                                    "channel, or a 2-D 'signals' array")
            if not arrs:
                raise DataError("no signal array", file=src, expected="1-D channel arrays")
            lens = {a.size for a in arrs}
            if len(lens) != 1:
                raise DataError("channels of different lengths", file=src,
                                value=sorted(lens), expected="equal lengths")
            x = np.vstack(arrs)
            units = None
        if "time_s" in keys:
            t = np.asarray(z["time_s"], float).reshape(-1)
            if t.size != x.shape[1]:
                raise DataError("time and signals differ in length", file=src, field="time_s",
                                value=t.size, expected=f"{x.shape[1]} samples")
            fs, t0 = sample_rate_from_time(t, src)
    if fs is None:
        raise DataError("no time and no sample rate", file=src, field="sample_rate_Hz",
                        expected="a 'time_s' or 'sample_rate_Hz' array, or --sample-rate-hz")
    return make_record(x, fs, names, units, src, t0)


def _read_wav(path: Path) -> Record:
    from scipy.io import wavfile

    src = str(path)
    guard_size(path, 8.0, "a WAV record")
    try:
        fs, data = wavfile.read(path, mmap=False)
    except Exception as exc:  # noqa: BLE001  scipy raises several kinds for a broken file
        raise DataError(f"not a readable WAV file ({exc})", file=src,
                        expected="a PCM or float WAV file") from None
    x = np.asarray(data)
    if np.issubdtype(x.dtype, np.integer):
        info = np.iinfo(x.dtype)
        x = (x.astype(float) - (info.max + info.min + 1) / 2.0) / (info.max + 1.0 - (
            info.max + info.min + 1) / 2.0)
    x = np.asarray(x, float)
    x = x[None, :] if x.ndim == 1 else x.T
    names = [f"ch{i}" for i in range(x.shape[0])]
    return make_record(x, float(fs), names, ["" for _ in names], src)


def _read_uff(path: Path) -> Record:
    import pyuff

    src = str(path)
    guard_size(path, 2.0, "a UFF record")
    try:
        sets = pyuff.UFF(src).read_sets()
    except Exception as exc:  # pyuff raises plain Exceptions for unreadable files
        raise DataError(f"not a readable UFF file ({exc})", file=src,
                        expected="a universal file with dataset 58 time records") from None
    sets = [sets] if isinstance(sets, dict) else list(sets)
    recs = [s for s in sets if int(s.get("type", 0)) == 58 and int(s.get("func_type", 0)) == 1]
    if not recs:
        raise DataError("no dataset 58 time record (func_type 1)", file=src,
                        expected="dataset 58 time records, one per channel")
    x, names, units, dts = [], [], [], set()
    for i, r in enumerate(recs):
        d = np.real(np.asarray(r["data"]))
        x.append(d)
        names.append(str(r.get("id2") or r.get("rsp_ent_name") or f"record {i + 1}").strip())
        units.append(str(r.get("ordinate_axis_units_lab", "")).strip())
        xa = np.asarray(r.get("x", []), float)
        if xa.size >= 2:
            dts.add(round(float(xa[1] - xa[0]), 12))
        else:
            dts.add(round(float(r.get("abscissa_inc", 0.0)), 12))
    if len({a.size for a in x}) != 1 or len(dts) != 1:
        raise DataError("time records differ in length or sampling", file=src,
                        expected="one sampling for all dataset 58 records")
    dt = dts.pop()
    if dt <= 0:
        raise DataError("time step must be positive", file=src, field="abscissa_inc",
                        value=dt, expected="a step > 0 in s")
    return make_record(np.vstack(x), 1.0 / dt, names, units, src)


#: the line robobore's record writers put at the top of a SYNTHETIC record (CSV comment,
#: DynoWare ``Comment:``); a reader that finds it labels the record SYNTHETIC
SYNTHETIC_MARK = "SYNTHETIC record generated by robobore"


def with_synthetic_mark(record: Record, path: str | Path) -> Record:
    """``record`` labelled SYNTHETIC when the head of its text file carries
    :data:`SYNTHETIC_MARK` (a record written by ``robobore measure synthetic``)."""
    import dataclasses

    try:
        with Path(path).open("rb") as fh:
            head = fh.read(4096).decode("latin-1")
    except OSError:
        return record
    if SYNTHETIC_MARK in head and record.kind == "measured":
        return dataclasses.replace(record, kind="SYNTHETIC")
    return record


def read_record(path: str | Path, sample_rate_Hz: float | None = None) -> Record:
    """Read a measured record (format by extension; see the module docstring); a text
    record written by robobore's SYNTHETIC generators is labelled SYNTHETIC."""
    p = Path(path)
    if not p.is_file():
        raise DataError("file not found", file=str(p),
                        expected="a record file (.csv, .txt, .npz, .uff, .unv, .wav)")
    ext = p.suffix.lower()
    if sample_rate_Hz is not None and not (math.isfinite(sample_rate_Hz) and sample_rate_Hz > 0):
        raise DataError("sample rate must be positive", field="--sample-rate-hz",
                        value=sample_rate_Hz, expected="a rate > 0 in Hz")
    if ext in (".csv", ".txt"):
        return with_synthetic_mark(_read_csv(p, sample_rate_Hz), p)
    if ext == ".npz":
        return _read_npz(p, sample_rate_Hz)
    if ext == ".wav":
        return _read_wav(p)
    if ext in (".uff", ".unv"):
        return _read_uff(p)
    raise DataError("unknown record format", file=str(p), value=ext,
                    expected=".csv, .txt, .npz, .uff, .unv or .wav")


def write_record_csv(record: Record, path: str | Path, digits: int = 9) -> Path:
    """Write a record as CSV (``time_s`` + one column per channel), atomically."""
    from robobore.io.results import atomic_write_text

    t = record.t0_s + np.arange(record.n_samples) / record.sample_rate_Hz
    cols = [f"{c} [{u}]" if u else c for c, u in zip(record.channels, record.units,
                                                       strict=True)]
    data = np.column_stack([t, record.signals.T])
    import io

    buf = io.StringIO()
    if record.kind != "measured":
        buf.write(f"# {record.kind} record generated by robobore\n")
    buf.write(",".join(["time_s", *cols]) + "\n")
    np.savetxt(buf, data, delimiter=",", fmt=f"%.{digits}g")
    return atomic_write_text(Path(path), buf.getvalue())


__all__ = ["Record", "make_record", "read_record", "read_csv_table", "parse_rows",
           "sample_rate_from_time", "time_column", "check_samples", "split_unit", "guard_size",
           "write_record_csv", "MIN_SAMPLES", "STEP_TOLERANCE", "GRID_TOLERANCE", "TIME_UNITS_S",
           "SYNTHETIC_MARK", "with_synthetic_mark"]
