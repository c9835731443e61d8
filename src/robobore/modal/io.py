"""Modal-analysis files: UFF 58 (time records, FRFs) and 164 (units) via pyuff; NPZ; JSON.

UFF conventions used (and expected when reading)
------------------------------------------------
* Dataset 58, ``func_type`` 1 (time response): one record per channel and hit. The force
  channel has ordinate specific data type 13 (excitation force); responses 12
  (acceleration), 11 (velocity) or 8 (displacement). ``ref_node/ref_dir`` = the hammer point
  and direction of that hit; ``rsp_node/rsp_dir`` = the channel; ``load_case_id`` = the hit
  number (1-based). Channel names go in ``id2``. Sampling from ``abscissa_inc`` (s).
* Dataset 58, ``func_type`` 4 (FRF): complex data over frequency (Hz), one record per
  (output, input) pair; the FRF type comes from the ordinate specific data type (12
  accelerance, 11 mobility, 8 receptance) unless given.
* Dataset 164: unit factors; values are converted to SI on reading (SI = value / factor,
  as the UFF 164 definition says), and written as SI (units code 1, factors 1).

NPZ contract: ``frequency_Hz (n_f,)``, ``frf`` complex ``(n_outputs, n_inputs, n_f)``,
``frf_type`` (accelerance | mobility | receptance); optional ``coherence``,
``output_names``, ``input_names``, ``output_dofs``/``input_dofs`` (int ``(n, 2)``: node,
direction; outputs and inputs with the same DOF are driving points).
"""

from __future__ import annotations

import io as _io
import re
from pathlib import Path
from typing import Any

import numpy as np

from robobore.errors import DataError
from robobore.io.ranges import check_array, check_value
from robobore.io.results import atomic_write_bytes
from robobore.modal.frf import HammerRecords
from robobore.modal.frf_data import FRFData, check_frf_type

SPEC_FORCE = 13
SPEC_BY_QUANTITY = {"acceleration": 12, "velocity": 11, "displacement": 8}
QUANTITY_BY_SPEC = {v: k for k, v in SPEC_BY_QUANTITY.items()}
FRF_TYPE_BY_SPEC = {12: "accelerance", 11: "mobility", 8: "receptance"}
SPEC_BY_FRF_TYPE = {v: k for k, v in FRF_TYPE_BY_SPEC.items()}
_DIRS = {"x": 1, "y": 2, "z": 3}


def default_dofs(names: tuple[str, ...], start_node: int = 1) -> list[tuple[int, int]]:
    """(node, direction) per channel name: ``<point>_<x|y|z>`` groups by point, else node
    per channel with direction 1 (+X)."""
    nodes: dict[str, int] = {}
    out = []
    for k, nm in enumerate(names):
        m = re.match(r"^(.*)[_\-]([xyzXYZ])$", nm)
        if m:
            pt = m.group(1)
            if pt not in nodes:
                nodes[pt] = start_node + len(nodes)
            out.append((nodes[pt], _DIRS[m.group(2).lower()]))
        else:
            out.append((start_node + 100 + k, 1))
    return out


#: what the UFF reader takes: dataset types and the 58 function types it reads
UFF_READS = ("58/58b function type 1 (time response) and 4 (FRF), with 6 (coherence) beside "
             "FRFs; 164 (units); 151 (header); 55 (mode shapes, read_uff_modes)")
UFF_FUNC_NAMES = {0: "general", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
                  4: "frequency response function", 5: "transmissibility", 6: "coherence",
                  7: "auto correlation", 8: "cross correlation", 9: "power spectral density",
                  10: "energy spectral density", 11: "probability density function",
                  12: "spectrum", 13: "cumulative frequency distribution",
                  14: "peaks valley", 15: "stress/cycles", 16: "strain/cycles", 17: "orbit",
                  18: "mode indicator function", 19: "force pattern", 20: "partial power",
                  21: "partial coherence", 22: "eigenvalue", 23: "eigenvector",
                  24: "shock response spectrum", 25: "finite impulse response filter",
                  26: "multiple coherence", 27: "order function", 28: "phase compensation"}
UFF_SET_NAMES = {15: "nodes", 18: "coordinate systems", 55: "data at nodes (mode shapes)",
                 58: "function at nodal DOF", 82: "trace lines", 151: "header", 164: "units",
                 2411: "nodes (double precision)", 2412: "elements", 2414: "analysis data",
                 2420: "coordinate systems", 2429: "permanent groups", 2467: "groups"}
#: abscissa specific data types: 17 time (s), 18 frequency (Hz); 0/1 unknown/general
ABSCISSA_TIME, ABSCISSA_FREQUENCY, ABSCISSA_ANY = 17, 18, (0, 1)
STANDARD_G = 9.80665  # m/s^2 per g (ordinate unit labels "g", "g/N", ...)


class UFFWarning(UserWarning):
    """Records of a UFF file that robobore does not read (skipped)."""


def _uff_sets(path: Path, need: int | None = 58) -> list[dict[str, Any]]:
    """Every dataset of a UFF file (one dict each; unsupported sets as ``{"type": T}``),
    read one at a time so that an unreadable record is named."""
    import pyuff

    p = Path(path)
    if not p.is_file():
        raise DataError("file not found", file=str(p), expected="a UFF (.uff/.unv) file")
    try:  # a universal file ends with the "-1" delimiter of its last dataset; without it
        # the file is cut short and the reader would silently drop the last records
        with p.open("rb") as fh:
            fh.seek(max(p.stat().st_size - 64, 0))
            tail = fh.read().rstrip()
    except OSError as exc:
        raise DataError(f"cannot read: {exc.strerror or exc}", file=str(p)) from None
    try:
        with p.open("rb") as fh:
            head = fh.read(512)
    except OSError as exc:
        raise DataError(f"cannot read: {exc.strerror or exc}", file=str(p)) from None
    first = next((ln.strip() for ln in head.splitlines() if ln.strip()), b"")
    if first != b"-1":  # every universal file starts with a "    -1" delimiter line
        table = next((ln.strip() for ln in head.splitlines()
                      if ln.strip() and not ln.lstrip().startswith(b"#")), b"")
        kind = ("a CSV / text table" if any(c in table for c in (b",", b";", b"\t"))
                else "not a universal file")
        raise DataError(f"{kind}: its first line is {first[:60].decode('latin-1')!r}, not "
                        "the UFF delimiter '-1'", file=str(p),
                        expected="a UFF file (dataset 58 records, each between '    -1' "
                                 "lines) or an NPZ FRF file")
    if not tail.endswith(b"-1"):
        raise DataError("truncated or not a universal file: it does not end with the "
                        "dataset delimiter '-1'", file=str(p),
                        expected="a complete UFF file (every dataset closed by '    -1')")
    try:
        uff = pyuff.UFF(str(p))
        types = [int(t) for t in uff.get_set_types()]
    except Exception as exc:  # pyuff raises plain Exceptions for unreadable files
        raise DataError(f"not a readable UFF file ({exc})", file=str(p),
                        expected="a universal file with dataset 58 records") from None
    if need is not None and need not in types:
        found = ", ".join(f"{t} ({UFF_SET_NAMES.get(t, 'not read')})"
                          for t in sorted(set(types)))
        raise DataError(f"UFF file has no dataset {need}", file=str(p),
                        value=f"datasets {found or 'none'}", expected=f"robobore reads {UFF_READS}")
    sets = []
    for i, t in enumerate(types):
        if t not in (55, 58, 151, 164):
            sets.append({"type": t})
            continue
        try:
            d = uff.read_sets(i)
        except Exception as exc:
            raise DataError(f"UFF dataset {t} could not be parsed ({exc})", file=str(p),
                            field=f"dataset {i + 1} (type {t})",
                            expected=f"a valid dataset {t} record") from None
        sets.append(d)
    return sets


def _unit_factors(sets: list[dict[str, Any]]) -> tuple[float, float]:
    for s in sets:
        if int(s.get("type", 0)) == 164:
            return float(s.get("length", 1.0) or 1.0), float(s.get("force", 1.0) or 1.0)
    return 1.0, 1.0


def _plausible(v: np.ndarray) -> bool:
    """Measurement values: finite, below 1e20 and no tiny non-zero (denormal-like) values."""
    a = np.abs(np.asarray(v, float).ravel())
    if not np.all(np.isfinite(a)):
        return False
    nz = a[a > 0]
    return bool(a.max(initial=0.0) < 1e20 and (nz.size == 0 or nz.min() > 1e-100))


def _swapped(v: np.ndarray, single: bool) -> np.ndarray:
    """The same bytes read in the other byte order."""
    a = np.asarray(v).astype(np.float32 if single else np.float64)
    with np.errstate(all="ignore"):
        return a.byteswap().astype(float)


def _check_record(p: str, k: int, r: dict[str, Any]) -> None:
    """A 58 record: as many values as its header declares, in its declared byte order."""
    name = f"record {k + 1} ({str(r.get('id2', '')).strip() or 'unnamed'})"
    data = np.asarray(r.get("data"))
    n_decl = int(r.get("num_pts", data.size) or data.size)
    if data.size != n_decl:
        hint = ""
        if r.get("binary") and data.size == 2 * n_decl and int(r.get("ord_data_type", 0)) in (2, 5):
            hint = (": its header declares single precision (ordinate data type "
                    f"{int(r['ord_data_type'])}) but it holds double-precision values")
        raise DataError(f"UFF 58 record holds {data.size} values, its header declares "
                        f"{n_decl}{hint}", file=p, field=name, value=data.size,
                        expected=f"{n_decl} values (a complete, consistent record)")
    if r.get("binary"):
        single = int(r.get("ord_data_type", 4)) in (2, 5)
        parts = [data.real, data.imag] if np.iscomplexobj(data) else [data]
        if int(r.get("abscissa_spacing", 1)) == 0:
            parts.append(np.asarray(r.get("x")))
        if not all(_plausible(v) for v in parts) and all(
                _plausible(_swapped(v, single)) for v in parts):
            order = {1: "little-endian", 2: "big-endian"}.get(int(r.get("byte_ordering", 1)),
                                                             "unknown")
            raise DataError("binary record's byte order does not match its header: read as "
                            f"declared ({order}) its values are not numbers a measurement "
                            "gives, read in the other order they are", file=p, field=name,
                            value=f"byte_ordering {int(r.get('byte_ordering', 1))}",
                            expected="each 58b record's header giving its own byte order "
                                     "(1 little-endian, 2 big-endian)")
    if not _plausible(data.real if np.iscomplexobj(data) else data):
        a = np.asarray(data)
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.argmax(bad))
            raise DataError("non-finite sample", file=p, field=name,
                            value=f"sample {i}: {a[i]!r}", expected="finite numbers")


def _factor(r: dict[str, Any], lf: float, ff: float, default: tuple[int, int]) -> float:
    """SI = value / factor: ``lf^a ff^b`` with the record's length/force unit exponents
    (numerator minus denominator), or ``default`` ``(a, b)`` when the record gives none;
    ordinate unit labels in g (``g``, ``g/N``) count ``9.80665 m/s^2`` per g."""
    a = int(r.get("ordinate_len_unit_exp", 0) or 0) - int(r.get("orddenom_len_unit_exp", 0) or 0)
    b = int(r.get("ordinate_force_unit_exp", 0) or 0) - int(
        r.get("orddenom_force_unit_exp", 0) or 0)
    if a == 0 and b == 0:
        a, b = default
    fac = lf**a * ff**b
    lab = str(r.get("ordinate_axis_units_lab", "")).strip().lower().replace(" ", "")
    if lab == "g" or lab.startswith("g/"):
        fac = fac / lf**a / STANDARD_G  # the length part is in g, not the file's unit
    return fac


def read_uff(path: str | Path, frf_type: str | None = None) -> HammerRecords | FRFData:
    """Read UFF 58 time records (-> HammerRecords) or FRFs (-> FRFData), in SI units.

    ASCII 58 and binary 58b (either byte order per record), real and complex, single and
    double precision, even and uneven abscissa; function type 1 (time) or 4 (FRF) with
    coherence (6) records of the same pairs; units from 164 (and the records' unit
    exponents). Records of other function types or datasets are skipped with a
    :class:`UFFWarning`; a file with nothing robobore reads is refused naming what it holds.
    """
    import warnings

    p = str(path)
    sets = _uff_sets(Path(path), need=None)
    lf, ff = _unit_factors(sets)
    s58 = [s for s in sets if int(s.get("type", 0)) == 58]
    for k, r in enumerate(s58):
        _check_record(p, k, r)
    ftypes = sorted({int(s.get("func_type", 0)) for s in s58})
    other_sets = sorted({int(s["type"]) for s in sets if int(s["type"]) not in (58, 151, 164)})
    main = 1 if 1 in ftypes else 4 if 4 in ftypes else None
    if main is None:
        held = [f"dataset 58 function type {t} ({UFF_FUNC_NAMES.get(t, 'unknown')})"
                for t in ftypes]
        held += [f"dataset {t} ({UFF_SET_NAMES.get(t, 'not read')})"
                 for t in sorted({int(s["type"]) for s in sets if int(s["type"]) != 58})]
        msg = ("UFF file has no dataset 58 (time records or FRFs)" if not s58
               else "UFF file holds no time records or FRFs")
        raise DataError(msg, file=p,
                        field="dataset/function type", value="; ".join(held) or "nothing",
                        expected=f"robobore reads {UFF_READS}")
    skip = [t for t in ftypes if t != main and not (main == 4 and t == 6)]
    if skip or other_sets:
        what = [f"58 function type {t} ({UFF_FUNC_NAMES.get(t, 'unknown')})" for t in skip]
        what += [f"dataset {t} ({UFF_SET_NAMES.get(t, 'not read')})" for t in other_sets]
        warnings.warn(f"{p}: skipped " + ", ".join(what) + f" (robobore reads {UFF_READS})",
                      UFFWarning, stacklevel=2)
    header = next((s for s in sets if int(s.get("type", 0)) == 151), None)
    if main == 1:
        rec = _read_time(p, [s for s in s58 if int(s["func_type"]) == 1], lf, ff)
        if header is not None:
            rec.meta["header"] = {k: str(header.get(k, "")).strip()
                                  for k in ("model_name", "description", "program")}
        return rec
    coh = [s for s in s58 if int(s["func_type"]) == 6]
    return _read_frf(p, [s for s in s58 if int(s["func_type"]) == 4], lf, ff, frf_type, coh)


def read_uff_records(path: str | Path) -> list[dict[str, Any]]:
    """The dataset 58 records of a UFF file, each checked (:func:`read_uff`'s record checks)
    and in SI units (responses by the 164 length factor and their unit exponents)."""
    p = str(path)
    sets = _uff_sets(Path(path), need=58)
    lf, ff = _unit_factors(sets)
    out = []
    for k, r in enumerate(s for s in sets if int(s.get("type", 0)) == 58):
        _check_record(p, k, r)
        r = dict(r)
        force = int(r.get("ordinate_spec_data_type", 0)) == SPEC_FORCE
        r["data"] = np.asarray(r["data"]) / _factor(r, lf, ff, (0, 1) if force else (1, 0))
        out.append(r)
    return out


def read_uff_modes(path: str | Path) -> list[dict[str, Any]]:
    """Mode shapes of UFF dataset 55 (normal modes, analysis type 2; complex eigenvalues,
    type 3): per mode ``{mode, frequency_Hz, damping_ratio (viscous; complex modes from the
    eigenvalue), modal_mass, node_numbers, shape (n_nodes, n_values) real or complex}`` in
    the file's order; lengths converted to SI by the 164 units."""
    p = str(path)
    sets = _uff_sets(Path(path), need=55)
    lf, _ = _unit_factors(sets)
    out = []
    for k, s in enumerate(x for x in sets if int(x.get("type", 0)) == 55):
        at = int(s.get("analysis_type", 0))
        nodes = np.asarray(s.get("node_nums", []), int)
        cols = [np.asarray(s[c]) for c in ("r1", "r2", "r3", "r4", "r5", "r6") if c in s]
        shape = np.column_stack(cols) if cols else np.zeros((nodes.size, 0))
        if at == 2:
            f = float(s.get("freq", 0.0))
            z = float(s.get("modal_damp_vis", 0.0) or 0.0)
        elif at == 3:
            lam = complex(s.get("eig", 0.0))
            f = abs(lam) / (2 * np.pi)
            z = float(-lam.real / abs(lam)) if lam != 0 else 0.0
        else:
            raise DataError("dataset 55 is not a mode shape", file=p,
                            field=f"dataset 55 number {k + 1}", value=f"analysis type {at}",
                            expected="analysis type 2 (normal modes) or 3 (complex "
                                     "eigenvalues)")
        check_value(f, "frequency_Hz", file=p, field=f"dataset 55 number {k + 1} frequency")
        out.append({"mode": int(s.get("mode_n", k + 1)), "frequency_Hz": f,
                    "damping_ratio": z, "modal_mass": s.get("modal_m"),
                    "node_numbers": nodes.tolist(), "shape": shape / lf})
    return out


def _finite(r: dict[str, Any], p: str) -> None:
    """A record's samples must be finite numbers (a NaN is not a measurement)."""
    a = np.asarray(r["data"])
    if not np.issubdtype(a.dtype, np.number):
        raise DataError("record samples are not numbers", file=p,
                        field=f"record {r.get('id2', '')}", value=str(a.dtype),
                        expected="numeric samples")
    bad = ~np.isfinite(a)
    if bad.any():
        i = int(np.argmax(bad))
        raise DataError("non-finite sample", file=p, field=f"record {r.get('id2', '')}",
                        value=f"sample {i}: {a[i]!r}", expected="finite numbers")


def _read_time(p: str, recs: list[dict[str, Any]], lf: float, ff: float) -> HammerRecords:
    forces = [r for r in recs if int(r.get("ordinate_spec_data_type", 0)) == SPEC_FORCE]
    resps = [r for r in recs if int(r.get("ordinate_spec_data_type", 0)) != SPEC_FORCE]
    if not forces:
        raise DataError("time records have no force channel", file=p,
                        field="ordinate_spec_data_type",
                        expected="one record per hit with specific data type 13 (force)")
    if not resps:
        raise DataError("time records have no response channel", file=p,
                        field="ordinate_spec_data_type",
                        expected="response records (12 acceleration, 11 velocity, 8 disp.)")
    qty = {int(r.get("ordinate_spec_data_type", 0)) for r in resps}
    if len(qty) != 1 or next(iter(qty)) not in QUANTITY_BY_SPEC:
        raise DataError("response records mix or lack quantities", file=p,
                        field="ordinate_spec_data_type", value=sorted(qty),
                        expected="all 12 (acceleration), all 11 (velocity) or all 8 (disp.)")
    quantity = QUANTITY_BY_SPEC[next(iter(qty))]
    inputs = sorted({(int(r["ref_node"]), int(r["ref_dir"])) for r in forces})
    outputs = sorted({(int(r["rsp_node"]), int(r["rsp_dir"])) for r in resps})
    hits = sorted({int(r.get("load_case_id", 0)) for r in forces})
    n = len(forces[0]["data"])
    dt = float(forces[0]["abscissa_inc"])
    if not dt > 0:
        raise DataError("abscissa increment must be > 0", file=p, field="abscissa_inc",
                        value=dt, expected="sampling interval in s")
    # Nyquist frequency within the plausible frequency range (a time axis scaled by 1e3..)
    check_value(0.5 / dt, "nyquist_Hz", file=p, field="abscissa_inc (as Nyquist frequency)")
    for r in recs:
        _finite(r, p)
        if len(r["data"]) != n or not np.isclose(float(r["abscissa_inc"]), dt):
            raise DataError("time records differ in length or sampling", file=p,
                            field=f"record {r.get('id2', '')}",
                            value=(len(r["data"]), float(r["abscissa_inc"])),
                            expected=f"{n} samples at dt = {dt:g} s like the first record")
    ni, nh, no = len(inputs), len(hits), len(outputs)
    force = np.full((ni, nh, n), np.nan)
    resp = np.full((ni, nh, no, n), np.nan)
    in_names = [""] * ni
    out_names = [""] * no
    for r in recs:
        if np.iscomplexobj(r["data"]):
            raise DataError("time record holds complex values", file=p,
                            field=f"record {r.get('id2', '')}",
                            value=f"ordinate data type {r.get('ord_data_type')}",
                            expected="real samples (ordinate data type 2 or 4)")
        if int(r.get("abscissa_spacing", 1)) == 0:
            raise DataError("time record has an uneven abscissa", file=p,
                            field=f"record {r.get('id2', '')}", value="abscissa_spacing 0",
                            expected="evenly sampled records (abscissa_spacing 1)")
        ab = int(r.get("abscissa_spec_data_type", 0) or 0)
        if ab != ABSCISSA_TIME and ab not in ABSCISSA_ANY:
            raise DataError("time record's abscissa is not time", file=p,
                            field=f"record {r.get('id2', '')}",
                            value=f"abscissa specific data type {ab}",
                            expected="17 (time, s) or 0/1 (unknown/general, read as s)")
    for r in forces:
        i = inputs.index((int(r["ref_node"]), int(r["ref_dir"])))
        h = hits.index(int(r.get("load_case_id", 0)))
        force[i, h] = np.asarray(r["data"], float) / _factor(r, lf, ff, (0, 1))
        nm = str(r.get("id2", "")).strip()
        in_names[i] = nm if nm and nm != "NONE" else f"n{inputs[i][0]}d{inputs[i][1]}"
    for r in resps:
        key = (int(r["ref_node"]), int(r["ref_dir"]))
        if key not in inputs:
            raise DataError("response record refers to an input without force record", file=p,
                            field="ref_node/ref_dir", value=key,
                            expected=f"one of the hammer DOFs {inputs}")
        i = inputs.index(key)
        h = hits.index(int(r.get("load_case_id", 0))) if int(r.get("load_case_id", 0)) in \
            hits else -1
        if h < 0:
            raise DataError("response record of a hit without force record", file=p,
                            field="load_case_id", value=int(r.get("load_case_id", 0)),
                            expected=f"one of the hits {hits}")
        o = outputs.index((int(r["rsp_node"]), int(r["rsp_dir"])))
        resp[i, h, o] = np.asarray(r["data"], float) / _factor(r, lf, ff, (1, 0))
        nm = str(r.get("id2", "")).strip()
        out_names[o] = nm if nm and nm != "NONE" else f"n{outputs[o][0]}d{outputs[o][1]}"
    # inputs may have different numbers of hits (hit numbers are per file): a hit without
    # force record for one input is marked invalid, not an error
    valid = ~np.isnan(force[:, :, 0])
    for i in range(ni):
        if not valid[i].any():  # pragma: no cover - inputs come from force records
            raise DataError("no force record for an input", file=p, field=f"input {i}")
    orphan = np.argwhere(~valid[:, :, None] & ~np.isnan(resp[:, :, :, 0]))
    if orphan.size:
        i, h, _ = orphan[0]
        raise DataError("response record of a hit without force record", file=p,
                        field=f"input {in_names[i]}", value=f"hit {hits[h]}",
                        expected="a force record (specific data type 13) for every hit")
    force[~valid] = 0.0
    resp[~valid] = 0.0
    missing = np.argwhere(np.isnan(resp[:, :, :, 0]))
    if missing.size:
        i, h, o = missing[0]
        raise DataError("missing response record", file=p,
                        field=f"output n{outputs[o][0]}d{outputs[o][1]}",
                        value=f"input {in_names[i]}, hit {hits[h]}",
                        expected="every response channel recorded for every hit")
    return HammerRecords(1.0 / dt, force, resp, quantity, tuple(out_names), tuple(in_names),
                         valid=valid, source=p,
                         meta={"input_dofs": inputs, "output_dofs": outputs, "hits": hits})


def _read_frf(p: str, recs: list[dict[str, Any]], lf: float, ff: float,
              frf_type: str | None, coh_recs: list[dict[str, Any]] | None = None) -> FRFData:
    outputs = sorted({(int(r["rsp_node"]), int(r["rsp_dir"])) for r in recs})
    inputs = sorted({(int(r["ref_node"]), int(r["ref_dir"])) for r in recs})
    x = np.asarray(recs[0]["x"], float)
    check_array(x, "frequency_Hz", file=p, field="abscissa (frequency axis)")
    if frf_type is None:
        specs = {int(r.get("ordinate_spec_data_type", 0)) for r in recs}
        if len(specs) != 1 or next(iter(specs)) not in FRF_TYPE_BY_SPEC:
            raise DataError("cannot tell the FRF type from the UFF records", file=p,
                            field="ordinate_spec_data_type", value=sorted(specs),
                            expected="12, 11 or 8 in every record, or give --frf-type")
        frf_type = FRF_TYPE_BY_SPEC[next(iter(specs))]
    frf_type = check_frf_type(frf_type, file=p)
    H = np.full((len(outputs), len(inputs), x.size), np.nan + 0j)
    for r in recs:
        _finite(r, p)
        xr = np.asarray(r["x"], float)
        if xr.size != x.size or not np.allclose(xr, x):
            raise DataError("FRF records have different frequency axes", file=p,
                            field=f"record {r.get('id2', '')}", value=xr.size,
                            expected=f"{x.size} lines from {x[0]:g} Hz like the first record")
        if not np.iscomplexobj(r["data"]):
            raise DataError("FRF record holds real values", file=p,
                            field=f"record {r.get('id2', '')}",
                            value=f"ordinate data type {r.get('ord_data_type')}",
                            expected="complex values (ordinate data type 5 or 6)")
        ab = int(r.get("abscissa_spec_data_type", 0) or 0)
        if ab != ABSCISSA_FREQUENCY and ab not in ABSCISSA_ANY:
            raise DataError("FRF record's abscissa is not frequency", file=p,
                            field=f"record {r.get('id2', '')}",
                            value=f"abscissa specific data type {ab}",
                            expected="18 (frequency, Hz) or 0/1 (unknown/general, read as Hz)")
        o = outputs.index((int(r["rsp_node"]), int(r["rsp_dir"])))
        i = inputs.index((int(r["ref_node"]), int(r["ref_dir"])))
        H[o, i] = np.asarray(r["data"], complex) / _factor(r, lf, ff, (1, -1))
    miss = np.argwhere(np.isnan(H[:, :, 0].real))
    if miss.size:
        o, i = miss[0]
        raise DataError("FRF matrix is incomplete", file=p,
                        field=f"output n{outputs[o][0]}d{outputs[o][1]}",
                        value=f"input n{inputs[i][0]}d{inputs[i][1]}",
                        expected="one FRF record per (output, input) pair")
    on = [f"n{n}d{d}" for n, d in outputs]
    inn = [f"n{n}d{d}" for n, d in inputs]
    for r in recs:  # channel names written as "output/input" in id2 (write_uff_frf)
        parts = str(r.get("id2", "")).strip().split("/")
        if len(parts) == 2 and all(parts):
            on[outputs.index((int(r["rsp_node"]), int(r["rsp_dir"])))] = parts[0]
            inn[inputs.index((int(r["ref_node"]), int(r["ref_dir"])))] = parts[1]
    if len(set(on)) < len(on) or len(set(inn)) < len(inn):
        on = [f"n{n}d{d}" for n, d in outputs]
        inn = [f"n{n}d{d}" for n, d in inputs]
    coh = None
    if coh_recs:
        coh = np.full(H.shape, np.nan)
        for r in coh_recs:
            key_o = (int(r["rsp_node"]), int(r["rsp_dir"]))
            key_i = (int(r["ref_node"]), int(r["ref_dir"]))
            xr = np.asarray(r["x"], float)
            if key_o not in outputs or key_i not in inputs or xr.size != x.size or \
                    not np.allclose(xr, x):
                raise DataError("coherence record does not match an FRF", file=p,
                                field=f"record {r.get('id2', '')}",
                                value=f"response {key_o}, reference {key_i}, {xr.size} lines",
                                expected="the DOFs and frequency axis of an FRF record")
            coh[outputs.index(key_o), inputs.index(key_i)] = np.real(np.asarray(r["data"]))
        if np.isnan(coh).any():  # not every pair has one: keep none rather than half
            coh = None
        else:
            coh = np.clip(coh, 0.0, 1.0)
    return FRFData(x, H, frf_type, coh, tuple(on), tuple(inn), source=p,
                   output_dofs=tuple(outputs), input_dofs=tuple(inputs))


def _units_set() -> dict[str, Any]:
    return {"type": 164, "units_code": 1, "units_description": "SI - meter newton",
            "temp_mode": 2, "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}


def _write_sets(path: str | Path, sets: list[dict[str, Any]]) -> Path:
    """Write datasets through pyuff into a temporary file, then rename (atomic, durable)."""
    import pyuff

    from robobore.io.results import atomic_path

    dest = Path(path)
    with atomic_path(dest) as tmp:
        tmp.unlink(missing_ok=True)
        uff = pyuff.UFF(str(tmp))
        uff.write_sets(sets, mode="overwrite", force_double=True)
    return dest


def header_set(model_name: str = "", description: str = "", program: str = "robobore"
               ) -> dict[str, Any]:
    """A UFF 151 header dataset (80-character fields)."""
    return {"type": 151, "model_name": model_name[:80], "description": description[:80],
            "db_app": "robobore", "date_db_created": "NONE", "time_db_created": "NONE",
            "version_db1": 0, "version_db2": 0, "file_type": 0, "date_db_saved": "NONE",
            "time_db_saved": "NONE", "program": program[:80], "date_file_written": "NONE",
            "time_file_written": "NONE"}


def write_uff_time(records: HammerRecords, path: str | Path,
                   input_dofs: list[tuple[int, int]] | None = None,
                   output_dofs: list[tuple[int, int]] | None = None,
                   description: str = "", header: dict[str, str] | None = None) -> Path:
    """Write time records as UFF 58 (binary 58b, float64: pyuff writes binary data in
    double precision only) + 164 (SI units); ``header``: 151 fields (model_name,
    description, program) written first."""
    out_d = output_dofs or default_dofs(records.output_names)
    in_d = input_dofs or default_dofs(records.input_names)
    dt = 1.0 / records.sample_rate_Hz
    x = np.arange(records.n_samples) * dt
    odt = 4
    spec = SPEC_BY_QUANTITY[records.response_quantity]
    sets: list[dict[str, Any]] = ([header_set(**header)] if header else []) + [_units_set()]
    desc = (description or "robobore hammer test")[:80]

    def rec(data: np.ndarray, name: str, rsp: tuple[int, int], ref: tuple[int, int],
            hit: int, sp: int) -> dict[str, Any]:
        d = dict(
            type=58, binary=1, id1=desc, id2=name[:80], id3=f"hit {hit}", id4="robobore.modal",
            id5="NONE", func_type=1, ver_num=0, load_case_id=hit, rsp_ent_name=name[:10],
            rsp_node=rsp[0], rsp_dir=rsp[1], ref_ent_name="hammer", ref_node=ref[0],
            ref_dir=ref[1], ord_data_type=odt, num_pts=x.size, abscissa_spacing=1,
            abscissa_min=0.0, abscissa_inc=dt, abscissa_spec_data_type=17,
            abscissa_axis_units_lab="s", ordinate_spec_data_type=sp,
            ordinate_axis_units_lab="N" if sp == SPEC_FORCE else "m/s^2",
            orddenom_spec_data_type=0, z_axis_spec_data_type=0,
            data=np.asarray(data, float), x=x)
        return d

    for i in range(records.n_inputs):
        for h in range(records.n_hits):
            if not records.valid[i, h]:
                continue
            sets.append(rec(records.force[i, h], records.input_names[i], in_d[i], in_d[i],
                            h + 1, SPEC_FORCE))
            for o in range(records.n_outputs):
                sets.append(rec(records.response[i, h, o], records.output_names[o], out_d[o],
                                in_d[i], h + 1, spec))
    return _write_sets(path, sets)


def write_uff_frf(data: FRFData, path: str | Path,
                  input_dofs: list[tuple[int, int]] | None = None,
                  output_dofs: list[tuple[int, int]] | None = None,
                  description: str = "") -> Path:
    """Write an FRF matrix as UFF 58 (func_type 4, complex) + 164 (SI)."""
    out_d = output_dofs or default_dofs(data.output_names)
    in_d = input_dofs or default_dofs(data.input_names)
    sets: list[dict[str, Any]] = [_units_set()]
    for i in range(data.n_inputs):
        for o in range(data.n_outputs):
            sets.append(dict(
                type=58, binary=1, id1=(description or "robobore FRF")[:80],
                id2=f"{data.output_names[o]}/{data.input_names[i]}"[:80], id3="NONE",
                id4="robobore.modal", id5="NONE", func_type=4, ver_num=0, load_case_id=0,
                rsp_ent_name="rsp", rsp_node=out_d[o][0], rsp_dir=out_d[o][1],
                ref_ent_name="ref", ref_node=in_d[i][0], ref_dir=in_d[i][1], ord_data_type=6,
                num_pts=data.frequency_Hz.size, abscissa_spacing=0,
                abscissa_spec_data_type=18, abscissa_axis_units_lab="Hz",
                ordinate_spec_data_type=SPEC_BY_FRF_TYPE[data.frf_type],
                orddenom_spec_data_type=SPEC_FORCE, z_axis_spec_data_type=0,
                data=data.frf[o, i].astype(complex), x=data.frequency_Hz))
    return _write_sets(path, sets)


def load_npz(path: str | Path) -> FRFData:
    """Read the NPZ contract (see module docstring)."""
    p = Path(path)
    if not p.is_file():
        raise DataError("file not found", file=str(p), expected="an .npz file")
    try:
        z = np.load(p, allow_pickle=False)
    except Exception as exc:
        raise DataError(f"not a readable NPZ file ({exc})", file=str(p),
                        expected="numpy .npz with frequency_Hz, frf, frf_type") from None
    try:
        return _npz_frf(z, p)
    except ValueError as exc:  # object (pickled) arrays, which allow_pickle=False refuses
        if "allow_pickle" not in str(exc) and "Object arrays" not in str(exc):
            raise
        raise DataError("NPZ file holds pickled (object) arrays, which are not read (a "
                        "pickle can run code)", file=str(p),
                        expected="numeric and string arrays only (numpy.savez without "
                        "object dtype)") from None


def _npz_frf(z: Any, p: Path) -> FRFData:
    with z:
        try:
            return _npz_frf(z, p)
        except DataError:
            raise
        except (ValueError, OSError, EOFError) as exc:  # pickled / truncated arrays
            raise DataError(f"cannot read an array of the NPZ file ({exc})", file=str(p),
                            expected="plain numeric arrays (no pickled objects)") from None


def _npz_frf(z: Any, p: Path) -> FRFData:
    for key in ("frequency_Hz", "frf", "frf_type"):
        if key not in z.files:
            raise DataError("NPZ file lacks a required array", file=str(p), field=key,
                            value=sorted(z.files),
                            expected="arrays frequency_Hz (Hz), frf (complex), frf_type")
    frf = z["frf"]
    names = {k: tuple(str(v) for v in z[k]) for k in ("output_names", "input_names")
             if k in z.files}
    coh = z["coherence"] if "coherence" in z.files else None
    # plausible ranges: frequency axis in Hz (not scaled), coherence within 0..1
    check_array(z["frequency_Hz"], "frequency_Hz", file=str(p))
    if coh is not None:
        check_array(coh, "coherence", file=str(p))
    dofs = {}
    for k in ("output_dofs", "input_dofs"):
        if k in z.files:
            a = np.asarray(z[k])
            if a.ndim != 2 or a.shape[1:] != (2,) or not np.issubdtype(a.dtype, np.integer):
                raise DataError("DOF array has the wrong shape or type", file=str(p),
                                field=k, value=f"shape {a.shape}, {a.dtype}",
                                expected="integers of shape (n, 2): node, direction")
            dofs[k] = tuple((int(u), int(v)) for u, v in a)
    data = FRFData(z["frequency_Hz"], frf, str(z["frf_type"]), coh,
                   names.get("output_names", ()), names.get("input_names", ()),
                   source=str(p), **dofs)
    if not np.iscomplexobj(frf):  # (after the structural checks of FRFData)
        raise DataError("the FRF array is real (magnitudes only?)", file=str(p), field="frf",
                        value=str(frf.dtype), expected="complex FRF values (magnitude and "
                        "phase), as numpy.savez writes a complex array")
    return data


def save_npz(data: FRFData, path: str | Path) -> Path:
    """Write FRFs in the NPZ contract (atomically)."""
    buf = _io.BytesIO()
    arrays: dict[str, Any] = {"frequency_Hz": data.frequency_Hz, "frf": data.frf,
                              "frf_type": np.array(data.frf_type),
                              "output_names": np.array(data.output_names),
                              "input_names": np.array(data.input_names)}
    if data.coherence is not None:
        arrays["coherence"] = data.coherence
    if data.output_dofs and data.input_dofs:
        arrays["output_dofs"] = np.array(data.output_dofs, dtype=np.int64)
        arrays["input_dofs"] = np.array(data.input_dofs, dtype=np.int64)
    np.savez_compressed(buf, **arrays)
    return atomic_write_bytes(path, buf.getvalue())


def load_input(path: str | Path, frf_type: str | None = None) -> HammerRecords | FRFData:
    """Read a UFF (.uff/.unv) or NPZ file by extension (UFF if not .npz)."""
    p = Path(path)
    if p.suffix.lower() == ".npz":
        return load_npz(p)
    return read_uff(p, frf_type)


__all__ = ["read_uff", "read_uff_modes", "read_uff_records", "header_set", "write_uff_time", "write_uff_frf", "load_npz",
           "save_npz", "load_input", "default_dofs", "UFFWarning", "UFF_READS"]
