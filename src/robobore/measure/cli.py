"""CLI commands of the measure stage: ``robobore detect chatter``, ``robobore measure cut``
(registered by ``robobore.cli``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import typer

from robobore.clitools import (
    JSON_OPTION,
    emit,
    fmt,
    fraction_progress,
    handle_errors,
    kv_table,
    parse_floats,
    stdout,
)
from robobore.errors import ConfigError, DataError


def _modes_Hz(path: Path | None) -> tuple[float, ...]:
    """Mode frequencies [Hz] of a modes JSON (``identify modes --json``: ``modes[].
    frequency_Hz``), or of a JSON list of numbers / of such mode objects."""
    if path is None:
        return ()
    import json

    from robobore.io.readers import read_text

    text = read_text(path, "modes file")
    try:
        d = json.loads(text)
    except ValueError as exc:
        raise ConfigError(f"not valid JSON ({exc})", file=str(path),
                          expected="a modes JSON (robobore identify modes --json)") from None
    modes = d.get("modes") if isinstance(d, dict) else d
    if isinstance(modes, dict) and "modes" in modes:
        modes = modes["modes"]
    if not isinstance(modes, list) or not modes:
        raise ConfigError("no modes", file=str(path), field="modes",
                          expected="a list of modes with frequency_Hz")
    out = []
    for i, m in enumerate(modes):
        v = m.get("frequency_Hz") if isinstance(m, dict) else m
        try:
            out.append(float(v))
        except (TypeError, ValueError):
            raise ConfigError("not a frequency", file=str(path), field=f"modes[{i}].frequency_Hz",
                              value=v, expected="a number in Hz") from None
    return tuple(out)


@handle_errors
def detect_chatter_cmd(
    file: Path = typer.Argument(..., help="Record: CSV (time_s + signal columns), NPZ, "
                                          "UFF 58 time records (.uff/.unv) or WAV (a "
                                          "DynoWare force export: `measure cut`)."),
    speed_rpm: float | None = typer.Option(None, "--speed-rpm", help="Spindle speed [r/min] "
                                           "(refined within +-1.5 %; estimated from the "
                                           "record's harmonics when not given)."),
    n_inserts: int = typer.Option(1, "--n-inserts", help="Inserts (teeth) on the tool."),
    modes_file: Path | None = typer.Option(None, "--modes-file", help="Modes JSON (`identify "
                                           "modes --json`): chatter is looked for near them."),
    channel: str | None = typer.Option(None, "--channel", help="Analyse this channel only."),
    window_s: float | None = typer.Option(None, "--window-s", help="Window length [s] "
                                          "(default: 0.5 s or 16 revolutions, the longer)."),
    sample_rate_hz: float | None = typer.Option(None, "--sample-rate-hz", help="Sample rate "
                                                "[Hz] of a CSV/NPZ without a time column."),
    fixed_lines_hz: str | None = typer.Option(None, "--fixed-lines-hz", help="Comma-separated "
                                              "fixed lines [Hz] to exclude (besides mains)."),
    plot: Path | None = typer.Option(None, "--plot", help="Write chatter_spectrogram.png "
                                                          "into this folder."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Chatter in a measured vibration, sound or force record: verdict, onset, frequency."""
    from robobore.io.outputs import check_output_dir
    from robobore.measure.cut import is_dynoware
    from robobore.measure.detect import DetectSettings, detect_chatter
    from robobore.measure.records import read_record

    check_output_dir(plot, "--plot", "chatter_spectrogram.png")
    modes = _modes_Hz(modes_file)
    lines = tuple(parse_floats(fixed_lines_hz, None, "--fixed-lines-hz", "Hz")
                  ) if fixed_lines_hz else ()
    with fraction_progress("chatter detection", not as_json) as prog:
        if is_dynoware(file):  # its verdict is measure cut's: on the cut, at its speed
            raise DataError("a DynoWare force export", file=str(file),
                            expected="`robobore measure cut FILE`: the record's chatter "
                            "verdict on the cutting part, at the speed found from the forces "
                            "(detect chatter reads CSV, NPZ, UFF 58 and WAV records)")
        rec = read_record(file, sample_rate_hz)
        if channel is not None:
            rec = rec.channel(channel)
        prog(0.2)
        det = detect_chatter(rec, DetectSettings(speed_rpm=speed_rpm, n_inserts=n_inserts,
                                                 modes_Hz=modes, window_s=window_s,
                                                 fixed_lines_Hz=lines),
                             progress=lambda x: prog(0.2 + 0.8 * x))
        prog(1.0)
    out = det.to_dict()
    if plot is not None:
        from robobore.measure.plots import plot_spectrogram

        out["plot"] = str(plot_spectrogram(det, plot, modes))

    def render(r: dict[str, Any]) -> None:
        rows = [("verdict", "CHATTER" if r["chatter"] else "stable"),
                ("chatter frequency (Hz)", r["chatter_frequency_Hz"]),
                ("onset (s)", r["onset_s"]),
                ("channel", r["channel"]),
                ("spindle frequency (Hz)", r["spindle_frequency_Hz"]),
                ("spindle speed (r/min)", r["speed_rpm"]),
                ("spindle speed from", r["speed_source"]),
                ("spindle speed spread over the windows (%)", 100.0 * r["speed_spread"]),
                ("energy share away from harmonics and fixed lines",
                 r["nonharmonic_energy_share"]),
                ("chatter peak energy share (median)", r["chatter_energy_share"]),
                ("peak above floor (dB)", r["peak_prominence_dB"]),
                ("chatter line growth in the record (dB)", r["chatter_growth_dB"]),
                ("fixed lines excluded (Hz)", ", ".join(fmt(v) for v in r["fixed_lines_Hz"])
                 or "none"),
                ("nearest mode (Hz)", r["nearest_mode_Hz"]),
                ("windows (chatter / all)",
                 f"{sum(w['chatter'] for w in r['windows'])} / {len(r['windows'])} of "
                 f"{fmt(r['window_s'])} s")]
        rows += [("reason", why) for why in r["reasons"]]
        if r.get("plot"):
            rows.append(("plot", r["plot"]))
        stdout.print(kv_table(f"chatter detection: {file}", rows))

    emit(out, as_json, render)


@handle_errors
def measure_cut_cmd(
    files: list[Path] = typer.Argument(..., help="Force / displacement records: DynoWare "
                                                 "ASCII export, CSV or NPZ with units in the "
                                                 "column names (Fx [N], Fy_kN, z_um)."),
    speed_rpm: float | None = typer.Option(None, "--speed-rpm", help="Spindle speed [r/min] "
                                           "(estimated from the record when not given)."),
    n_inserts: int = typer.Option(1, "--n-inserts", help="Inserts on the bar."),
    sample_rate_hz: float | None = typer.Option(None, "--sample-rate-hz", help="Sample rate "
                                                "[Hz] of a file without a time column."),
    plot: Path | None = typer.Option(None, "--plot", help="Write cut_<file>.png and "
                                                          "chatter_<file>.png here."),
    as_json: bool = JSON_OPTION,
) -> None:
    """The paper's quantities of raw cutting records: mean force, force amplitude, feed
    amplitude, per-revolution statistics, chatter verdict."""
    from robobore.io.outputs import check_output_dir
    from robobore.measure.cut import cut_quantities, read_cut_record

    check_output_dir(plot, "--plot", "cut.png")
    results = []
    with fraction_progress("measure cut", not as_json) as prog:
        for i, fpath in enumerate(files):
            rec = read_cut_record(fpath, sample_rate_hz)
            q = cut_quantities(rec, speed_rpm, n_inserts, return_detection=plot is not None)
            if plot is not None:
                from robobore.measure.plots import plot_cut, plot_spectrogram

                det = q.pop("detection")
                q["plots"] = [str(plot_cut(rec, q, plot, f"cut_{Path(fpath).stem}.png")),
                              str(plot_spectrogram(det, plot,
                                                   name=f"chatter_{Path(fpath).stem}.png"))]
            results.append(q)
            prog((i + 1) / len(files))
    out = {"records": results}

    def render(r: dict[str, Any]) -> None:
        for q in r["records"]:
            rows = [("spindle speed (r/min)", q["speed_rpm"]),
                    ("speed from", q["speed_source"]),
                    ("cutting part (s)", f"{fmt(q['cutting_time_s'][0])} .. "
                                         f"{fmt(q['cutting_time_s'][1])}"),
                    ("revolutions analysed", len(q["per_revolution"]))]
            for a in "xyz":
                if "force_mean_N" in q and a in q["force_mean_N"]:
                    rows.append((f"mean force {a} (N)", q["force_mean_N"][a]))
                    rows.append((f"force amplitude {a} (N, per revolution)",
                                 q["force_amplitude_N"][a]))
            if "feed_amplitude_um" in q:
                rows.append(("feed amplitude (um)", q["feed_amplitude_um"]))
            rows.append(("chatter", "CHATTER" if q["chatter"] else "no"))
            rows.append(("chatter frequency (Hz)", q["chatter_frequency_Hz"]))
            for p in q.get("plots", []):
                rows.append(("plot", p))
            stdout.print(kv_table(f"cutting record: {q['source']}", rows))

    emit(out, as_json, render)


@handle_errors
def measure_synthetic_cmd(
    out: Path = typer.Argument(..., help="Record to write: .csv (vibration: time_s + acc; "
                                         "force: DynoWare-style ASCII) ."),
    kind: str = typer.Option("vibration", "--kind", help="vibration (a tool-holder "
                             "accelerometer record of the time-domain simulation, labelled by "
                             "its verdict) or force (a dynamometer record of a boring cut)."),
    seed: int = typer.Option(0, "--seed", help="Random seed (the record's ground truth)."),
    duration_s: float | None = typer.Option(None, "--duration-s", help="Length [s] of the "
                                            "cut (0.5 .. 60; default 3, 8 with --low-speed; "
                                            "a force record adds 1 s of air before and "
                                            "after)."),
    low_speed: bool = typer.Option(False, "--low-speed", help="Vibration: the low-speed "
                                   "regime (150-1000 r/min, half of the seeds a cut "
                                   "interrupted once per revolution; "
                                   "robobore.measure.synthetic.LOW_SPEED)."),
    speed_wander: float = typer.Option(0.0, "--speed-wander", help="Vibration: standard "
                                       "deviation of the spindle speed's relative wander "
                                       "(0 .. 0.05; e.g. 0.003 for 0.3 %; default 0, a "
                                       "steady speed)."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Write a SYNTHETIC record with its ground truth (to try `detect chatter` and
    `measure cut`)."""
    from robobore.io.outputs import check_output_file

    check_output_file(out, "OUT", "the record")
    if duration_s is None:
        duration_s = 8.0 if low_speed else 3.0
    if not 0.5 <= duration_s <= 60.0:
        raise ConfigError("duration out of range", field="--duration-s", value=duration_s,
                          expected="0.5 .. 60 s")
    if not (math.isfinite(speed_wander) and 0.0 <= speed_wander <= 0.05):
        raise ConfigError("speed wander out of range", field="--speed-wander",
                          value=speed_wander,
                          expected="0 .. 0.05 (a relative standard deviation of the speed; "
                                   "0.003 for 0.3 %)")
    if kind == "vibration":
        from robobore.measure.records import write_record_csv
        from robobore.measure.synthetic import LOW_SPEED, simulated_record

        kw = {k: v for k, v in LOW_SPEED.items() if k != "duration_s"} if low_speed else {}
        rec = simulated_record(seed, duration_s=duration_s, speed_wander=speed_wander, **kw)
        write_record_csv(rec, out)
    elif kind == "force":
        if low_speed:
            raise ConfigError("--low-speed is for vibration records", field="--low-speed",
                              value=True, expected="--kind vibration")
        if speed_wander:
            raise ConfigError("--speed-wander is for vibration records",
                              field="--speed-wander", value=speed_wander,
                              expected="--kind vibration")
        from robobore.measure.cut import synthetic_force_record, write_dynoware_ascii

        rec = synthetic_force_record(duration_s=duration_s + 2.0, seed=seed)  # + 1 s of air
        # before and after the cut
        write_dynoware_ascii(rec, out)
    else:
        raise ConfigError("unknown kind", field="--kind", value=kind,
                          expected="vibration or force")
    res = {"file": str(out), "kind": rec.kind, "truth": rec.truth, "record": rec.to_dict()}

    def render(r: dict[str, Any]) -> None:
        rows = [("file", r["file"]), ("kind", r["kind"])]
        rows += [(f"truth: {k}", v) for k, v in r["truth"].items()
                 if not isinstance(v, dict)]
        stdout.print(kv_table("SYNTHETIC record", rows))

    emit(res, as_json, render)


def register(groups: dict[str, typer.Typer]) -> None:
    """Add ``detect chatter`` and ``measure cut``."""
    groups.setdefault("detect", typer.Typer(help="Detect events in measured records.",
                                            no_args_is_help=True, rich_markup_mode=None))
    groups.setdefault("measure", typer.Typer(help="Measured cutting records to the paper's "
                                                  "quantities.", no_args_is_help=True,
                                             rich_markup_mode=None))
    groups["detect"].command("chatter")(detect_chatter_cmd)
    groups["measure"].command("cut")(measure_cut_cmd)
    groups["measure"].command("synthetic")(measure_synthetic_cmd)
