"""Raw cutting records to the paper's quantities (``robobore measure cut``).

Readers (:func:`read_cut_record`):

* **Kistler DynoWare ASCII export**: a header block of ``key: value`` (or tab-separated)
  lines, then a column line such as ``Time [s]  Fx [N]  Fy [N]  Fz [N]`` (tab, ``;`` or ``,``
  separated) and the samples. The three force channels ``Fx``, ``Fy``, ``Fz`` must all be
  there; a missing one is refused naming the file, the column and what was expected.
* **generic CSV / NPZ** with the unit in each column name: ``Fx_N``, ``Fx [kN]``,
  ``Fz (N)``; displacements ``z_um``, ``z [mm]``, ``dz_m``. Units are converted at reading
  (force: N, kN, daN, lbf; displacement: m, mm, um, nm); an unknown unit is refused. A time
  column (``time_s``, ``Time [s]``) or ``sample_rate_Hz`` gives the sampling.

Quantities per record (:func:`cut_quantities`), all on the *cutting part* of the record (the
longest run of revolutions whose mean resultant force is at least half the 90th percentile
of the per-revolution means, less its first and last revolution; the whole record for a
displacement-only record):

* ``force_mean_N`` per axis: the mean force;
* ``force_amplitude_N`` per axis: the paper's "average amplitude of the cutting force" (its
  Figs. 7 and 10: the forces of a stable cut are near-sinusoidal over a revolution of the
  bar): the half peak-to-peak of the force in each revolution, averaged over the
  revolutions; ``force_amplitude_overall_N``: the half peak-to-peak over the whole cutting
  part (:func:`robobore.dynamics.timedomain.summarize`'s definition for simulated runs; the
  two coincide for a steady periodic cut);
* ``feed_amplitude_um``: the half peak-to-peak of the feed-direction (z) displacement in each
  revolution, averaged over the revolutions (the simulated run's ``feed_amplitude``,
  :func:`robobore.dynamics.timedomain.simulate`, the same quantity);
* ``per_revolution``: each revolution's mean, half peak-to-peak and RMS of every force axis
  and the half peak-to-peak of each displacement axis;
* ``chatter``: the verdict of :func:`robobore.measure.detect.detect_chatter` on the cutting
  part (force channels, else displacement channels).

The spindle speed comes from the caller; without it, it is estimated from the record's
harmonic comb (:func:`robobore.measure.detect.find_spindle`): the forces of a rotating bar on
a fixed dynamometer turn once per revolution.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from robobore.errors import DataError
from robobore.measure.records import (
    Record,
    make_record,
    parse_rows,
    read_csv_table,
    sample_rate_from_time,
    split_unit,
    time_column,
)

FORCE_UNITS = {"n": 1.0, "kn": 1e3, "dan": 10.0, "lbf": 4.4482216152605}
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "micron": 1e-6, "nm": 1e-9}
FORCE_NAMES = {"fx": "Fx", "fy": "Fy", "fz": "Fz"}
DISP_NAMES = {"x": "x", "y": "y", "z": "z", "dx": "x", "dy": "y", "dz": "z",
              "disp_x": "x", "disp_y": "y", "disp_z": "z"}
_SUFFIX = re.compile(r"^(?P<name>.+?)_(?P<unit>[A-Za-zµ]+)$")


def _column(col: str, source: str) -> tuple[str, str, float] | None:
    """``(kind, axis name, factor to SI)`` of a column, or None when it is not a force or
    displacement column. ``kind``: ``"force"`` / ``"disp"``."""
    name, unit = split_unit(col)
    if not unit:
        m = _SUFFIX.match(name)
        if m and (m.group("name").lower() in FORCE_NAMES or m.group("name").lower() in
                  DISP_NAMES):
            name, unit = m.group("name"), m.group("unit")
    low = name.strip().lower()
    if low in FORCE_NAMES:
        u = unit.lower()
        if u not in FORCE_UNITS:
            raise DataError("unknown force unit", file=source, field=col, value=unit or "(none)",
                            expected=f"a unit in the column name: {', '.join(FORCE_UNITS)} "
                                     "(e.g. 'Fx [N]' or 'Fx_kN')")
        return "force", FORCE_NAMES[low], FORCE_UNITS[u]
    if low in DISP_NAMES:
        u = unit.lower()
        if u not in LENGTH_UNITS:
            raise DataError("unknown length unit", file=source, field=col, value=unit or "(none)",
                            expected=f"a unit in the column name: {', '.join(LENGTH_UNITS)} "
                                     "(e.g. 'z_um' or 'z [mm]')")
        return "disp", DISP_NAMES[low], LENGTH_UNITS[u]
    return None


def _from_table(header: list[str], data: np.ndarray, source: str, header_line: int,
                sample_rate_Hz: float | None, dynoware: bool) -> Record:
    tc = time_column(header, source)
    ti, t_scale = tc if tc is not None else (None, 1.0)
    cols: dict[str, tuple[int, float]] = {}
    for i, h in enumerate(header):
        if i == ti:
            continue
        c = _column(h, source)
        if c is None:
            continue
        kind, ax, fac = c
        if ax in cols:
            raise DataError("channel appears twice", file=source, field=h,
                            expected="each force or displacement channel once")
        cols[ax] = (i, fac)
    if dynoware:
        for need in ("Fx", "Fy", "Fz"):
            if need not in cols:
                raise DataError("missing force channel", file=source, field=need,
                                expected="the DynoWare columns Time [s], Fx [N], Fy [N], Fz [N]"
                                         f" (found {', '.join(header)})")
    if not cols:
        raise DataError("no force or displacement column", file=source,
                        value=", ".join(header),
                        expected="columns such as 'Fx [N]', 'Fy_N', 'z_um' (unit in the name)")
    order = [a for a in ("Fx", "Fy", "Fz", "x", "y", "z") if a in cols]
    x = np.vstack([data[:, cols[a][0]] * cols[a][1] for a in order])
    units = ["N" if a.startswith("F") else "m" for a in order]
    if ti is not None:
        fs, t0 = sample_rate_from_time(data[:, ti] * t_scale, source, header[ti])
    elif sample_rate_Hz is not None:
        fs, t0 = float(sample_rate_Hz), 0.0
    else:
        raise DataError("no time column and no sample rate", file=source, field="time_s",
                        expected="a 'time_s' / 'Time [s]' column, or a sample rate")
    return make_record(x, fs, order, units, source, t0)


def _dynoware_header(lines: list[str]) -> int | None:
    """Index of a DynoWare column line (a time column and an ``Fx``-like column)."""
    for i, ln in enumerate(lines[:200]):
        cells = [c.strip() for c in re.split(r"[\t;,]", ln) if c.strip()]
        if len(cells) >= 2 and time_column(cells[:1]) is not None and any(
                split_unit(c)[0].lower().startswith("f") for c in cells[1:]):
            if i > 0 and any(":" in x or "\t" in x for x in lines[:i]):
                return i
    return None


def _head_lines(p: Path) -> tuple[list[str], str]:
    """The first 200 lines of a text file and the encoding they were read in (UTF-8, else
    ANSI: DynoWare writes ANSI text)."""
    head: list[str] = []
    for enc in ("utf-8-sig", "latin-1"):
        try:
            with p.open("r", encoding=enc, newline="") as fh:
                head = [fh.readline().rstrip("\r\n") for _ in range(200)]
            break
        except UnicodeDecodeError:
            continue
    return head, enc


def is_dynoware(path: str | Path) -> bool:
    """Whether a file is a DynoWare ASCII export (a header block of ``key: value`` lines,
    then a time column and force columns)."""
    p = Path(path)
    if not p.is_file() or p.suffix.lower() not in (".csv", ".txt", ".asc", ".dat"):
        return False
    return _dynoware_header(_head_lines(p)[0]) is not None


def read_cut_record(path: str | Path, sample_rate_Hz: float | None = None) -> Record:
    """Read a force and/or displacement record (module docstring); SI units."""
    p = Path(path)
    src = str(p)
    if not p.is_file():
        raise DataError("file not found", file=src,
                        expected="a force/displacement record (.csv, .txt, .npz)")
    ext = p.suffix.lower()
    if ext == ".npz":
        with np.load(p, allow_pickle=False) as z:
            keys = list(z.files)
            arrs = {k: np.asarray(z[k], float).reshape(-1) for k in keys
                    if k not in ("sample_rate_Hz",)}
            fs = (float(np.asarray(z["sample_rate_Hz"]).reshape(-1)[0])
                  if "sample_rate_Hz" in keys else sample_rate_Hz)
        header = list(arrs)
        lens = {a.size for a in arrs.values()}
        if len(lens) != 1:
            raise DataError("arrays of different lengths", file=src, value=sorted(lens),
                            expected="one length for all channels")
        data = np.column_stack([arrs[k] for k in header])
        return _from_table(header, data, src, 0, fs, False)
    if ext not in (".csv", ".txt", ".asc", ".dat"):
        raise DataError("unknown record format", file=src, value=ext,
                        expected=".csv, .txt, .asc, .dat (DynoWare ASCII) or .npz")
    head, enc = _head_lines(p)
    hi = _dynoware_header(head)
    if hi is not None:
        hdr_line = head[hi]
        delim = "\t" if "\t" in hdr_line else (";" if ";" in hdr_line else ",")
        header = [c.strip() for c in hdr_line.split(delim)]
        while header and header[-1] == "":
            header.pop()
        meta = {}
        for ln in head[:hi]:
            kv = re.split(r":\s*|\t", ln, maxsplit=1)
            if len(kv) == 2 and kv[0].strip():
                meta[kv[0].strip()] = kv[1].strip()
        rate = None
        for k, v in meta.items():
            if "sampling rate" in k.lower():
                try:
                    rate = float(v.split()[0].replace(",", "."))
                except (ValueError, IndexError):
                    rate = None
        if delim == ";" or enc != "utf-8-sig":  # decimal commas or ANSI: parsed as text
            from robobore.measure.records import guard_size

            guard_size(p, 6.0, "a force record")
            lines = p.read_text(encoding=enc).splitlines()
            body = [ln.replace(",", ".").strip(delim) for ln in lines[hi + 1:]]
            data = parse_rows(body, header, src, hi + 1, delim)
        else:
            _, data, _ = read_csv_table(p, "a DynoWare export", skip_lines=hi, delimiter=delim,
                                        header=header)
        from robobore.measure.records import with_synthetic_mark

        return with_synthetic_mark(_from_table(header, data, src, hi + 1,
                                               rate if rate else sample_rate_Hz, True), p)
    from robobore.measure.records import with_synthetic_mark

    header, data, hl = read_csv_table(p, "a force/displacement record")
    return with_synthetic_mark(_from_table(header, data, src, hl, sample_rate_Hz, False), p)


def _cutting_span(F: np.ndarray, fs: float) -> tuple[int, int]:
    """Samples of the cutting part before the speed is known: the longest run where the
    resultant force, averaged over 0.1 s, is at least half its 90th percentile."""
    mag = np.linalg.norm(F, axis=0)
    w = max(1, int(0.1 * fs))
    env = np.convolve(mag, np.ones(w) / w, mode="same")
    on = env >= 0.5 * np.percentile(env, 90)
    best, cur, start, bstart = 0, 0, 0, 0
    for i, v in enumerate(on):
        if v:
            if cur == 0:
                start = i
            cur += 1
            if cur > best:
                best, bstart = cur, start
        else:
            cur = 0
    a, b = bstart + w, bstart + best - w
    return (a, b) if b - a >= 256 else (0, F.shape[1])


def _cutting_revolutions(F: np.ndarray, spr: float, nrev: int) -> tuple[int, int]:
    """First and last+1 revolution of the cutting part (module docstring)."""
    mags = np.array([np.linalg.norm(F[:, int(round(i * spr)):int(round((i + 1) * spr))],
                                    axis=0).mean() for i in range(nrev)])
    thr = 0.5 * np.percentile(mags, 90)
    on = mags >= thr
    best, cur, start, bstart = 0, 0, 0, 0
    for i, v in enumerate(on):
        if v:
            if cur == 0:
                start = i
            cur += 1
            if cur > best:
                best, bstart = cur, start
        else:
            cur = 0
    a, b = bstart, bstart + best
    if b - a >= 4:
        a, b = a + 1, b - 1
    return a, b


def cut_quantities(record: Record, speed_rpm: float | None = None,
                   n_inserts: int = 1, return_detection: bool = False) -> dict[str, Any]:
    """The paper's quantities of one record (module docstring); a JSON-ready dict (with the
    :class:`~robobore.measure.detect.ChatterDetection` under ``"detection"`` when asked)."""
    from robobore.measure.detect import (
        DetectSettings,
        detect_chatter,
        find_spindle,
        spectral_lines,
        window_spectra,
    )

    fs = record.sample_rate_Hz
    src = record.source
    names = record.channels
    fi = [i for i, c in enumerate(names) if c in ("Fx", "Fy", "Fz")]
    di = [i for i, c in enumerate(names) if c in ("x", "y", "z")]
    sig = record.signals[fi or di]
    if sig.size and np.all(np.ptp(sig, axis=1) <= 1e-9 * (np.max(np.abs(sig), axis=1) + 1e-300)):
        raise DataError("every force / displacement channel is constant: the record holds no "
                        "cut (a channel not connected, or a record of the idle bar)", file=src,
                        field=", ".join(names[i] for i in (fi or di)),
                        value=[float(v) for v in sig[:, 0]],
                        expected="a record of a cut (forces or displacements that vary)")
    src_speed = "given"
    if speed_rpm is None:
        use = fi or di
        i0, i1 = _cutting_span(record.signals[fi], fs) if fi else (0, record.n_samples)
        seg = record.signals[use, i0:i1]
        nl = int(min(seg.shape[1], max(256, round(min(4.0, seg.shape[1] / fs / 2) * fs))))
        f, _, P = window_spectra(seg, fs, nl, nl // 2)
        Pn = P / (P[:, :, 2:].sum(axis=2, keepdims=True) + 1e-300)
        avg = Pn.mean(axis=(0, 1))
        f0, _, _ = find_spindle(f, avg, None, float(f[2]), 0.45 * fs)
        src_speed = "estimated from the record's harmonic comb"
        if f0 is None and fi:
            # the forces of a rotating bar turn once per revolution: the strongest line
            lines, prom = spectral_lines(f, avg, 2)
            if lines.size:
                f0 = float(lines[int(np.argmax(prom))])
                src_speed = "estimated from the strongest force line (once per revolution)"
        if f0 is None:
            raise DataError("spindle speed not given and not found in the record", file=src,
                            field="--speed-rpm", expected="the spindle speed in r/min")
        speed_rpm = 60.0 * f0
    n = float(speed_rpm)
    if not (math.isfinite(n) and 1.0 <= n <= 100000.0):
        raise DataError("spindle speed out of range", file=src, field="--speed-rpm", value=n,
                        expected="1 .. 100000 r/min")
    f1 = n / 60.0
    if fs < 2.0 * f1:
        raise DataError("sample rate below twice the spindle frequency", file=src,
                        field="sample_rate_Hz", value=fs,
                        expected=f"at least {2 * f1:.6g} Hz for {n:g} r/min")
    spr = fs / f1
    if spr < 8:
        raise DataError("too few samples per revolution for per-revolution statistics",
                        file=src, field="sample_rate_Hz", value=fs,
                        expected=f"at least {8 * f1:.6g} Hz (8 samples per revolution)")
    nrev = int(record.n_samples // spr)
    if nrev < 3:
        raise DataError("record shorter than 3 revolutions", file=src,
                        value=f"{record.duration_s:.4g} s",
                        expected=f"at least {3 / f1:.4g} s at {n:g} r/min")
    X = record.signals
    a, b = (_cutting_revolutions(X[fi], spr, nrev) if fi else (0, nrev))
    revs = []
    for r in range(a, b):
        i0, i1 = int(round(r * spr)), int(round((r + 1) * spr))
        seg = X[:, i0:i1]
        row: dict[str, Any] = {"revolution": r, "t0_s": record.t0_s + i0 / fs}
        for i in fi:
            ax = names[i][1].lower()
            row[f"force_mean_{ax}_N"] = float(seg[i].mean())
            row[f"force_amplitude_{ax}_N"] = float(0.5 * np.ptp(seg[i]))
            row[f"force_rms_{ax}_N"] = float(np.sqrt(np.mean((seg[i] - seg[i].mean()) ** 2)))
        for i in di:
            row[f"amplitude_{names[i]}_um"] = float(0.5 * np.ptp(seg[i]) * 1e6)
        revs.append(row)
    i0, i1 = int(round(a * spr)), int(round(b * spr))
    part = X[:, i0:i1]
    out: dict[str, Any] = {
        "source": src, "kind": record.kind, "channels": list(names),
        "sample_rate_Hz": fs, "speed_rpm": n, "speed_source": src_speed,
        "revolutions_total": nrev, "cutting_revolutions": [a, b - 1],
        "cutting_time_s": [record.t0_s + i0 / fs, record.t0_s + i1 / fs],
    }
    if fi:
        out["force_mean_N"] = {names[i][1].lower(): float(part[i].mean()) for i in fi}
        out["force_amplitude_N"] = {
            names[i][1].lower(): float(np.mean([rv[f"force_amplitude_{names[i][1].lower()}_N"]
                                                for rv in revs])) for i in fi}
        out["force_amplitude_overall_N"] = {names[i][1].lower(): float(0.5 * np.ptp(part[i]))
                                            for i in fi}
    if "z" in names:
        out["feed_amplitude_um"] = float(np.mean([rv["amplitude_z_um"] for rv in revs]))
    elif di:
        out["feed_amplitude_um"] = None
    use = fi or di
    sub = make_record(part[use], fs, [names[i] for i in use], [record.units[i] for i in use],
                      src, record.t0_s + i0 / fs, record.kind)
    det = detect_chatter(sub, DetectSettings(speed_rpm=n, n_inserts=n_inserts))
    out["chatter"] = det.chatter
    out["chatter_frequency_Hz"] = det.chatter_frequency_Hz
    out["chatter_detection"] = {k: v for k, v in det.to_dict().items() if k != "windows"}
    out["per_revolution"] = revs
    if return_detection:
        out["detection"] = det
    return out


def synthetic_force_record(speed_rpm: float = 300.0, sample_rate_Hz: float = 2000.0,
                           duration_s: float = 6.0, force_N: tuple[float, float, float] = (
                               120.0, 60.0, 40.0), air_s: float = 1.0, noise_N: float = 1.5,
                           feed_amplitude_um: float | None = 4.0, seed: int = 0) -> Record:
    """A SYNTHETIC dynamometer (and grating-scale) record of a boring cut.

    Ground truth: the bar turns at ``speed_rpm``; the tangential, radial and feed forces
    ``force_N`` turn with it, so the fixed dynamometer sees ``Fx = -Ft sin t + Fr cos t``,
    ``Fy = Ft cos t + Fr sin t`` (amplitude ``hypot(Ft, Fr)``, mean 0) and a steady ``Fz``;
    ``air_s`` of air cut (no force) before and after; white noise ``noise_N``; the feed
    displacement ``z`` a sinusoid of ``feed_amplitude_um`` at the spindle frequency (the
    grating scale). ``truth`` holds the exact per-revolution amplitudes."""
    rng = np.random.default_rng(seed)
    fs = float(sample_rate_Hz)
    n = int(round(duration_s * fs))
    t = np.arange(n) / fs
    th = 2 * np.pi * speed_rpm / 60.0 * t + rng.uniform(0, 2 * np.pi)
    ft, fr, fz = force_N
    on = ((t >= air_s) & (t < duration_s - air_s)).astype(float)
    F = np.vstack([(-ft * np.sin(th) + fr * np.cos(th)) * on,
                   (ft * np.cos(th) + fr * np.sin(th)) * on,
                   fz * on]) + noise_N * rng.standard_normal((3, n))
    chans, units, X = ["Fx", "Fy", "Fz"], ["N", "N", "N"], F
    truth: dict[str, Any] = {"force_amplitude_N": {"x": math.hypot(ft, fr),
                                                   "y": math.hypot(ft, fr), "z": 0.0},
                             "force_mean_N": {"x": 0.0, "y": 0.0, "z": fz},
                             "speed_rpm": speed_rpm, "noise_N": noise_N, "seed": seed}
    if feed_amplitude_um is not None:
        z = feed_amplitude_um * 1e-6 * np.sin(th + 0.3) * on
        X = np.vstack([F, z])
        chans, units = [*chans, "z"], [*units, "m"]
        truth["feed_amplitude_um"] = feed_amplitude_um
    return make_record(X, fs, chans, units, "<SYNTHETIC force record>", 0.0, "SYNTHETIC",
                       truth)


def write_dynoware_ascii(record: Record, path: str | Path) -> Path:
    """Write the force channels of a record as a DynoWare-style ASCII export (header block,
    tab-separated ``Time [s]  Fx [N]  Fy [N]  Fz [N]``), atomically."""
    import io

    from robobore.io.results import atomic_write_text

    fi = [i for i, c in enumerate(record.channels) if c in ("Fx", "Fy", "Fz")]
    buf = io.StringIO()
    buf.write("DynoWare ASCII export\n")
    if record.kind != "measured":
        buf.write(f"Comment:\t{record.kind} record generated by robobore\n")
    buf.write("Measuring time [s]:\t%.6g\n" % record.duration_s)
    buf.write("Sampling rate [Hz]:\t%.6g\n" % record.sample_rate_Hz)
    buf.write("Number of samples:\t%d\n" % record.n_samples)
    buf.write("Channels:\t%d\n\n" % len(fi))
    buf.write("\t".join(["Time [s]", *(f"{record.channels[i]} [N]" for i in fi)]) + "\n")
    t = record.t0_s + np.arange(record.n_samples) / record.sample_rate_Hz
    np.savetxt(buf, np.column_stack([t, record.signals[fi].T]), delimiter="\t", fmt="%.6f")
    return atomic_write_text(Path(path), buf.getvalue())


__all__ = ["read_cut_record", "cut_quantities", "synthetic_force_record", "write_dynoware_ascii",
           "FORCE_UNITS", "LENGTH_UNITS"]
