"""Cases of the malformed-input corpus on the measured-signal and newer modal paths:
``detect chatter``, ``measure cut``, ``compare`` with a manifest of records and on a
``paper`` output folder, ``identify modes --operational``, UFF variants (58 ASCII and 58b,
164, truncated, mixed endian, unknown record type), ``identify virtual-hammer-test
--robot-file``, coefficients and modes files that do not fit the config or the stiffness
file, and misuse of the Python API.

Used by ``benchmarks/malformed_corpus.py`` (``--only`` picks these by their prefixes, e.g.
``--only "meas:|cut:|cmp:|oma:|uff:|vht:|paper:|fit:|api2:"``). :func:`build` writes the
fixtures under a folder (SYNTHETIC vibration and force records of ``robobore measure
synthetic``, a demo sweep store, a ``paper --fast`` output folder, the bundled hammer test
and identification results, and their corrupted copies) and returns the cases as
``(description, argv, pattern, mode)`` like ``malformed_corpus_identity.build``: mode
``error`` expects a clear one-line error matching ``pattern``; mode ``script`` runs a
script that prints ``OK`` when the behaviour is right (a correct result, a warning that
must be given, a ``RoboboreError`` naming the argument).
"""
# ruff: noqa: E501

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
DATA = REPO / "src" / "robobore" / "data"
KUKA = EX / "robots" / "kr240-r2900.toml"
PY = sys.executable

sys.path.insert(0, str(Path(__file__).resolve().parent))
from malformed_corpus_identity import _script_api, _script_cli  # noqa: E402


def _rb(*args: str, out: Path | None = None, cwd: Path | None = None) -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO / "src"), "NUMBA_NUM_THREADS": "1"}
    r = subprocess.run([PY, "-m", "robobore", *args], capture_output=True, text=True, env=env,
                       cwd=cwd)
    if r.returncode != 0:
        raise RuntimeError(f"fixture command failed: {args}: {r.stderr[-400:]}")
    if out is not None:
        out.write_text(r.stdout)


def _uff_variants(W: Path) -> dict[str, Path]:
    """UFF files made from the bundled hammer test (pyuff): 58 ASCII, 58b without 164, the
    byte-order flag swapped (big-endian header on little-endian data), truncated, an
    unknown record type appended, a 164 record alone."""
    sys.path.insert(0, str(REPO / "src"))
    import pyuff

    from robobore.modal.example import example_path

    src = example_path()
    sets = pyuff.UFF(str(src)).read_sets()
    out = {}

    def write(name: str, items: list[dict]) -> Path:
        p = W / name
        if p.exists():
            p.unlink()
        u = pyuff.UFF(str(p))
        for s in items:
            u.write_sets(s, mode="add")
        return p

    s58 = [s for s in sets if s["type"] == 58]
    s164 = [s for s in sets if s["type"] == 164]
    ascii_sets = []
    for s in sets:
        t = dict(s)
        if t["type"] == 58:
            t["binary"] = 0
        ascii_sets.append(t)
    out["ascii"] = write("h_ascii.uff", ascii_sets)
    out["no164"] = write("h_no164.uff", s58)
    out["only164"] = write("h_only164.uff", s164)
    # byte order: the 58b header says big-endian (2), the data stay little-endian
    blob = Path(src).read_bytes()
    text = blob.decode("latin-1")
    lines = text.split("\n")
    swapped = []
    for ln in lines:
        if ln.startswith("    58b"):
            parts = ln.split()
            if len(parts) >= 3 and parts[1] == "1":
                ln = ln.replace(" 1 ", " 2 ", 1)
        swapped.append(ln)
    (W / "h_endian.uff").write_bytes("\n".join(swapped).encode("latin-1"))
    out["endian"] = W / "h_endian.uff"
    (W / "h_trunc.uff").write_bytes(blob[: len(blob) // 3])
    out["trunc"] = W / "h_trunc.uff"
    unknown = "    -1\n  9999\nsomething robobore does not know\n    -1\n"
    (W / "h_unknown.uff").write_bytes(blob + unknown.encode())
    out["unknown"] = W / "h_unknown.uff"
    (W / "h_only_unknown.uff").write_text(unknown)
    out["only_unknown"] = W / "h_only_unknown.uff"
    return out


def build(W: Path) -> list[tuple[str, list, str, str]]:  # noqa: N803, PLR0915
    """Write the fixtures under ``W`` and return the cases."""
    shutil.rmtree(W, ignore_errors=True)
    W.mkdir(parents=True)
    vib = W / "vib.csv"
    _rb("measure", "synthetic", str(vib), "--seed", "0", "--duration-s", "3")
    force = W / "force.csv"
    _rb("measure", "synthetic", str(force), "--kind", "force")
    s = W / "s.json"
    _rb("identify", "stiffness", "--example", "--json", out=s)
    m = W / "m.json"
    _rb("identify", "modes", "--example", "--json", out=m)
    # vibration record variants
    vtext = vib.read_text()
    vlines = vtext.splitlines()
    hdr_i = next(i for i, ln in enumerate(vlines) if ln.startswith("time_s"))
    body = vlines[hdr_i + 1:]
    (W / "vib_ms.csv").write_text("\n".join(vlines[:hdr_i] + ["time_ms,acc"] + body) + "\n")
    (W / "vib_ms_as_s.csv").write_text("\n".join(
        vlines[:hdr_i + 1] + [f"{float(r.split(',')[0]) * 1e3:g},{r.split(',')[1]}" for r in body]) + "\n")
    nan_body = list(body)
    nan_body[500] = nan_body[500].split(",")[0] + ",nan"
    (W / "vib_nan.csv").write_text("\n".join(vlines[:hdr_i + 1] + nan_body) + "\n")
    (W / "vib_const.csv").write_text("\n".join(
        vlines[:hdr_i + 1] + [r.split(",")[0] + ",1.0" for r in body]) + "\n")
    (W / "vib_short.csv").write_text("\n".join(vlines[:hdr_i + 1] + body[:10]) + "\n")
    (W / "vib_semi.csv").write_text(vtext.replace(",", ";"))
    (W / "vib_notime.csv").write_text("acc\n" + "\n".join(r.split(",")[1] for r in body) + "\n")
    rev = list(body)
    rev[100], rev[101] = rev[101], rev[100]
    (W / "vib_order.csv").write_text("\n".join(vlines[:hdr_i + 1] + rev) + "\n")
    (W / "vib_empty.csv").write_text("time_s,acc\n")
    (W / "vib.wav").write_bytes(b"RIFF\x00\x00\x00\x00WAVEjunk")
    # force record variants
    ftext = force.read_text()
    (W / "force_kN.csv").write_text(ftext.replace("Fx [N]", "Fx [kN]").replace(
        "Fy [N]", "Fy [kN]").replace("Fz [N]", "Fz [kN]"))
    (W / "force_lbf.csv").write_text(ftext.replace("Fx [N]", "Fx [lbf]"))
    (W / "force_nounit.csv").write_text(ftext.replace("Fx [N]\tFy [N]\tFz [N]", "Fx\tFy\tFz"))
    (W / "force_norate.csv").write_text("\n".join(
        ln for ln in ftext.splitlines() if not ln.startswith("Sampling rate")).replace(
        "Time [s]\t", "").replace("\n0.", "\n0.") + "\n")
    fl = ftext.splitlines()
    fh = next(i for i, ln in enumerate(fl) if ln.startswith("Time [s]"))
    (W / "force_trunc.csv").write_text("\n".join(fl[: fh + 40]) + "\n")
    (W / "force_air.csv").write_text("\n".join(
        fl[: fh + 1] + ["\t".join([ln.split("\t")[0], "0.01", "0.02", "0.0"]) for ln in fl[fh + 1:]]) + "\n")
    # compare: a demo sweep store and manifests of the SYNTHETIC force record
    store = W / "store"
    _rb("sweep", str(EX / "sweep_demo.toml"), "--out", str(store), "--workers", "0")
    (W / "rec").mkdir()
    shutil.copy(force, W / "rec" / "force.csv")
    hdr = "speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa,posture,stable,force_file"
    man = {
        "manifest.csv": f"{hdr}\n300,0.15,0.05,0,paper,true,force.csv\n",
        "man_missing.csv": f"{hdr}\n300,0.15,0.05,0,paper,true,nope.csv\n",
        "man_qty.csv": f"{hdr},force_amplitude_x_N\n300,0.15,0.05,0,paper,true,force.csv,100\n",
        "man_speed.csv": f"{hdr}\n600,0.15,0.05,0,paper,true,force.csv\n",
        "man_vib.csv": f"{hdr}\n300,0.15,0.05,0,paper,true,../vib.csv\n",
        "man_empty.csv": f"{hdr}\n300,0.15,0.05,0,paper,true,\n",
        "man_semi.csv": f"{hdr}\n300,0.15,0.05,0,paper,true,force.csv\n".replace(",", ";"),
        "man_ninserts.csv": hdr + ",n_inserts\n300,0.15,0.05,0,paper,true,force.csv,0\n",
    }
    for name, text in man.items():
        (W / "rec" / name).write_text(text)
    # the paper's output folder (--fast: the stored coefficients, ~1 min)
    paper = W / "paper_out"
    _rb("paper", "--fast", "--out", str(paper), "--workers", "1")
    pmeas = DATA / "paper_example" / "measured_synthetic.csv"
    shutil.copytree(paper, W / "paper_nosweep")
    for p in (W / "paper_nosweep").iterdir():
        if p.is_dir():
            shutil.rmtree(p)
    # operational records (NPZ)
    rng = np.random.default_rng(0)
    fs = 256.0
    t = np.arange(int(120 * fs)) / fs
    y = np.vstack([np.sin(2 * np.pi * 7 * t) + 0.3 * rng.standard_normal(t.size),
                   np.sin(2 * np.pi * 17 * t + 1) + 0.3 * rng.standard_normal(t.size),
                   np.sin(2 * np.pi * 25 * t + 2) + 0.3 * rng.standard_normal(t.size)])
    np.savez(W / "oma_norate.npz", data=y)
    np.savez(W / "oma_one.npz", data=y[:1], sample_rate_Hz=fs)
    yn = y.copy()
    yn[1, 100] = np.nan
    np.savez(W / "oma_nan.npz", data=yn, sample_rate_Hz=fs)
    np.savez(W / "oma_rate0.npz", data=y, sample_rate_Hz=0.0)
    np.savez(W / "oma_short.npz", data=y[:, :20], sample_rate_Hz=fs)
    np.savez(W / "oma_khz.npz", data=y, sample_rate_Hz=fs / 1000)
    np.savez(W / "oma_2d_wrong.npz", data=y.T, sample_rate_Hz=fs)
    # UFF variants
    uff = _uff_variants(W)
    (W / "csv_as.uff").write_text(vtext)
    # the virtual hammer test of a robot file
    nolinks = W / "robot_nolinks.toml"
    kt = KUKA.read_text()
    cut = kt.find("\n[[links]]")
    nolinks.write_text(kt[:cut] if cut > 0 else kt)
    five = W / "robot_5dh.toml"
    five.write_text(kt.replace("[[dh]]", "[[DH]]", 1) if "[[dh]]" in kt else kt + "\n[[nonsense]]\n")
    sk_irb = W / "s_irb.json"
    shutil.copy(s, sk_irb)  # the IRB 6600's stiffness file with the KUKA robot file
    Q = "20,20,10,0,-30,0"
    # modes / coefficients that do not fit
    md = json.loads(m.read_text())
    two = dict(md, modes=md["modes"][:2])
    (W / "m_two.json").write_text(json.dumps(two))
    khz = json.loads(m.read_text())
    khz["modes"][1]["frequency_Hz"] *= 1000
    (W / "m_khz.json").write_text(json.dumps(khz))
    coef = json.loads((DATA / "paper_example" / "tc4_fe_coefficients.json").read_text())
    c_rake = dict(coef, identity={"kind": "cutting coefficients", "material": "TC4",
                                  "insert": {"rake_deg": 15.0, "edge_radius_um": 20.0,
                                             "inclination_deg": 0.0}})
    (W / "coef_rake15.json").write_text(json.dumps(c_rake))
    c_mat = dict(coef, identity={"kind": "cutting coefficients", "material": "IN718",
                                 "insert": coef["insert"]})
    (W / "coef_in718.json").write_text(json.dumps(c_mat))
    bpaper = (EX / "boring_paper.toml").read_text()
    (W / "b_coef_rake.toml").write_text(bpaper.replace(
        'material = "TC4"', f'file = "{W / "coef_rake15.json"}"'))
    (W / "b_coef_mat.toml").write_text(bpaper.replace(
        'material = "TC4"', f'file = "{W / "coef_in718.json"}"\nmaterial = "TC4"'))
    (W / "b_coef_ok.toml").write_text(bpaper.replace(
        'material = "TC4"', f'file = "{DATA / "paper_example" / "tc4_fe_coefficients.json"}"\nmaterial = "Ti-6Al-4V"'))
    lob = ["lobes", str(EX / "boring_process.toml"), "--method", "frequency"]
    dc = ["detect", "chatter"]
    cases: list[tuple[str, list, str, str]] = [
        # ---- detect chatter
        ("meas: detect chatter on a SYNTHETIC record says SYNTHETIC and finds the chatter",
         _script_cli([*dc, str(vib), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "ok = d['chatter'] and d['record']['kind'] == 'SYNTHETIC' and abs(d['chatter_frequency_Hz'] - 1847.25) < 5\n"
                     "print('OK' if ok else (d['chatter'], d['record']['kind'], d['chatter_frequency_Hz'])); sys.exit(0 if ok else 1)"), "", "script"),
        ("meas: detect chatter, time column in ms (named time_ms)", [*dc, W / "vib_ms.csv"],
         r"vib_ms\.csv.*time", "error"),
        ("meas: detect chatter, times in ms in a time_s column",
         [*dc, W / "vib_ms_as_s.csv"], r"vib_ms_as_s\.csv.*(time|sample rate|Hz)", "error"),
        ("meas: detect chatter, NaN in the signal", [*dc, W / "vib_nan.csv"], r"vib_nan\.csv.*(row|nan|finite)", "error"),
        ("meas: detect chatter, constant signal",
         _script_cli([*dc, str(W / "vib_const.csv"), "--json"],
                     "ok = (r.returncode == 0 and not json.loads(r.stdout)['chatter']) or (r.returncode == 2 and 'vib_const.csv' in r.stderr)\n"
                     "print('OK' if ok else r.stderr[-300:] + r.stdout[-200:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("meas: detect chatter, 10 samples", [*dc, W / "vib_short.csv"], r"vib_short\.csv.*(samples|short)", "error"),
        ("meas: detect chatter, ';' separated record is read",
         _script_cli([*dc, str(W / "vib_semi.csv"), "--json"],
                     "ok = r.returncode == 0 and json.loads(r.stdout)['chatter']\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("meas: detect chatter, no time column and no --sample-rate-hz", [*dc, W / "vib_notime.csv"],
         r"vib_notime\.csv.*(time|sample-rate)", "error"),
        ("meas: detect chatter, time not increasing", [*dc, W / "vib_order.csv"], r"vib_order\.csv.*(time|row)", "error"),
        ("meas: detect chatter, header only", [*dc, W / "vib_empty.csv"], r"vib_empty\.csv", "error"),
        ("meas: detect chatter, a broken WAV", [*dc, W / "vib.wav"], r"vib\.wav", "error"),
        ("meas: detect chatter, --speed-rpm -300", [*dc, vib, "--speed-rpm", "-300"], r"--speed-rpm", "error"),
        ("meas: detect chatter, --n-inserts 0", [*dc, vib, "--n-inserts", "0"], r"--n-inserts", "error"),
        ("meas: detect chatter, --window-s 100 on a 3 s record", [*dc, vib, "--window-s", "100"], r"--window-s", "error"),
        ("meas: detect chatter, --channel nope", [*dc, vib, "--channel", "nope"], r"vib\.csv.*--channel.*nope", "error"),
        ("meas: detect chatter, --fixed-lines-hz abc", [*dc, vib, "--fixed-lines-hz", "abc"], r"--fixed-lines-hz", "error"),
        ("meas: detect chatter, a stiffness file as --modes-file", [*dc, vib, "--modes-file", s], r"s\.json.*modes", "error"),
        ("meas: detect chatter, --sample-rate-hz 0", [*dc, W / "vib_notime.csv", "--sample-rate-hz", "0"], r"--sample-rate-hz", "error"),
        ("meas: detect chatter, file not found", [*dc, W / "nope.csv"], r"nope\.csv", "error"),
        # ---- measure cut
        ("cut: measure cut on a SYNTHETIC force record: 40 N mean feed force, SYNTHETIC",
         _script_cli(["measure", "cut", str(force), "--json"],
                     "d = json.loads(r.stdout)['records'][0]\n"
                     "ok = d['kind'] == 'SYNTHETIC' and abs(d['force_mean_N']['z'] - 40) < 1 and abs(d['speed_rpm'] - 300) < 3\n"
                     "print('OK' if ok else (d['kind'], d['force_mean_N'], d['speed_rpm'])); sys.exit(0 if ok else 1)"), "", "script"),
        ("cut: forces in kN columns are converted (x1000)",
         _script_cli(["measure", "cut", str(W / "force_kN.csv"), "--json"],
                     "d = json.loads(r.stdout)['records'][0]\n"
                     "ok = abs(d['force_mean_N']['z'] - 40e3) < 1e3\n"
                     "print('OK' if ok else d['force_mean_N']); sys.exit(0 if ok else 1)"), "", "script"),
        ("cut: an Fx column in lbf is converted (x 4.448)",
         _script_cli(["measure", "cut", str(W / "force_lbf.csv"), "--speed-rpm", "300", "--json"],
                     "d = json.loads(r.stdout)['records'][0]['force_amplitude_N']\n"
                     "ok = abs(d['x'] / d['y'] - 4.448) < 0.1\n"
                     "print('OK' if ok else d); sys.exit(0 if ok else 1)"), "", "script"),
        ("cut: force columns without units", ["measure", "cut", W / "force_nounit.csv"], r"force_nounit\.csv.*(unit|Fx)", "error"),
        ("cut: no sampling rate and no time column", ["measure", "cut", W / "force_norate.csv"], r"force_norate\.csv.*(rate|time)", "error"),
        ("cut: a record of 40 samples", ["measure", "cut", W / "force_trunc.csv"], r"force_trunc\.csv", "error"),
        ("cut: a record of air (no cut)",
         _script_cli(["measure", "cut", str(W / "force_air.csv"), "--speed-rpm", "300", "--json"],
                     "ok = r.returncode == 2 and 'force_air.csv' in r.stderr or (r.returncode == 0 and 'warnings' in r.stdout and 'cut' in r.stdout)\n"
                     "print('OK' if ok else r.stderr[-300:] + r.stdout[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("cut: --speed-rpm in rad/s (31.4 for 300 r/min)",
         _script_cli(["measure", "cut", str(force), "--speed-rpm", "31.4", "--json"],
                     "e = ' '.join(r.stderr.split())\n"
                     "ok = (r.returncode == 2 and '31.4' in e and 'force.csv' in e) or (r.returncode == 0 and '300' in e and 'speed' in e)\n"
                     "print('OK' if ok else r.stderr[-300:] + r.stdout[:200]); sys.exit(0 if ok else 1)"), "", "script"),
        ("cut: --n-inserts 0", ["measure", "cut", force, "--n-inserts", "0"], r"--n-inserts", "error"),
        ("cut: a vibration record (no force channel)", ["measure", "cut", vib], r"vib\.csv.*(force|channel|column)", "error"),
        # ---- compare with a manifest
        ("cmp: compare with a manifest of a SYNTHETIC record says so",
         _script_cli(["compare", str(W / "rec" / "manifest.csv"), str(store), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "ok = d['measured_synthetic'] is True and d['measured_records'][0]['force_file']['kind'] == 'SYNTHETIC'\n"
                     "print('OK' if ok else d.get('measured_records')); sys.exit(0 if ok else 1)"), "", "script"),
        ("cmp: manifest names a missing record", ["compare", W / "rec" / "man_missing.csv", store],
         r"man_missing\.csv.*row 1.*force_file.*nope\.csv", "error"),
        ("cmp: manifest with a quantity column", ["compare", W / "rec" / "man_qty.csv", store],
         r"man_qty\.csv.*force_amplitude_x_N", "error"),
        ("cmp: manifest row speed 600 r/min, record cut at 300",
         _script_cli(["compare", str(W / "rec" / "man_speed.csv"), str(store), "--json"],
                     "ok = (r.returncode == 2 and 'man_speed.csv' in r.stderr) or (r.returncode == 0 and any('speed' in w for w in json.loads(r.stdout)['warnings']))\n"
                     "print('OK' if ok else r.stderr[-300:] + str(json.loads(r.stdout).get('warnings') if r.returncode == 0 else '')); sys.exit(0 if ok else 1)"), "", "script"),
        ("cmp: manifest names a vibration record as force_file", ["compare", W / "rec" / "man_vib.csv", store],
         r"vib\.csv.*(force|channel|column)", "error"),
        ("cmp: manifest row without a record", ["compare", W / "rec" / "man_empty.csv", store],
         r"man_empty\.csv.*(record|force_file|row)", "error"),
        ("cmp: a ';' separated manifest is read",
         _script_cli(["compare", str(W / "rec" / "man_semi.csv"), str(store), "--json"],
                     "ok = r.returncode == 0 and json.loads(r.stdout)['measured_records']\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("cmp: manifest n_inserts 0", ["compare", W / "rec" / "man_ninserts.csv", store], r"man_ninserts\.csv.*n_inserts", "error"),
        # ---- compare on a paper folder
        ("paper: compare the paper's measured CSV with its output folder",
         _script_cli(["compare", str(pmeas), str(paper), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "ok = r.returncode == 0 and d['system'] == 'robot' and 'machine_tool' in d['systems_in_store']\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("paper: compare --system nope on a paper folder", ["compare", pmeas, paper, "--system", "nope"],
         r"--system.*nope", "error"),
        ("paper: compare on a paper folder without its results", ["compare", pmeas, W / "paper_nosweep"],
         r"paper_nosweep", "error"),
        ("paper: compare on a paper folder's report file", ["compare", pmeas, paper / "coefficients.json"],
         r"coefficients\.json", "error"),
        # ---- identify modes --operational
        ("oma: NPZ without sample_rate_Hz", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_norate.npz"],
         r"oma_norate\.npz.*sample_rate", "error"),
        ("oma: one channel", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_one.npz"], r"oma_one\.npz.*1 response channel", "error"),
        ("oma: NaN in a channel", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_nan.npz"], r"oma_nan\.npz.*(NaN|finite)", "error"),
        ("oma: sample rate 0", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_rate0.npz"], r"oma_rate0\.npz.*sample_rate", "error"),
        ("oma: 20 samples", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_short.npz"], r"oma_short\.npz", "error"),
        ("oma: sample rate in kHz (0.256)", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_khz.npz"],
         r"oma_khz\.npz.*(sample_rate|band|Hz)", "error"),
        ("oma: channels and samples swapped",
         _script_cli(["identify", "modes", "--band-hz", "3", "60", "--operational", str(W / "oma_2d_wrong.npz"), "--json"],
                     "ok = (r.returncode == 2 and 'oma_2d_wrong.npz' in r.stderr) or (r.returncode == 0 and 'warn' in (r.stdout + r.stderr).lower())\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("oma: --spindle-rpm -1", ["identify", "modes", "--band-hz", "3", "60", "--operational", W / "oma_one.npz", "--spindle-rpm", "-1"],
         r"--spindle-rpm", "error"),
        ("oma: a CSV as the operational record", ["identify", "modes", "--band-hz", "3", "60", "--operational", vib],
         r"vib\.csv", "error"),
        # ---- UFF variants (identify modes)
        ("uff: 58 ASCII copy of the bundled test gives its modes",
         _script_cli(["identify", "modes", str(uff["ascii"]), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "f = sorted(x['frequency_Hz'] for x in d['modes'])\n"
                     "ok = len(f) == 5 and abs(f[0] - 6.90) < 0.2\n"
                     "print('OK' if ok else f); sys.exit(0 if ok else 1)"), "", "script"),
        ("uff: 58b without the 164 units record",
         _script_cli(["identify", "modes", str(uff["no164"]), "--json"],
                     "ok = r.returncode == 0 and len(json.loads(r.stdout)['modes']) == 5\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("uff: a 164 record alone", ["identify", "modes", uff["only164"]], r"h_only164\.uff.*58", "error"),
        ("uff: 58b header big-endian, data little-endian", ["identify", "modes", uff["endian"]],
         r"h_endian\.uff", "error"),
        ("uff: truncated to a third", ["identify", "modes", uff["trunc"]], r"h_trunc\.uff", "error"),
        ("uff: an unknown record type appended",
         _script_cli(["identify", "modes", str(uff["unknown"]), "--json"],
                     "ok = (r.returncode == 0 and len(json.loads(r.stdout)['modes']) == 5) or (r.returncode == 2 and 'h_unknown.uff' in r.stderr and '9999' in r.stderr)\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("uff: only an unknown record type", ["identify", "modes", uff["only_unknown"]], r"h_only_unknown\.uff", "error"),
        ("uff: a CSV given as a UFF", ["identify", "modes", W / "csv_as.uff"], r"csv_as\.uff.*CSV", "error"),
        # ---- identify virtual-hammer-test --robot-file
        ("vht: the KUKA robot file at a posture (stiffness from the library ground truth)",
         _script_cli(["identify", "virtual-hammer-test", str(W / "k.uff"), "--robot-file", str(KUKA), "--joints-deg", Q, "--json"],
                     "ok = r.returncode == 0 and (Path(sys.argv[1]) / 'k.uff.truth.json').is_file()\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("vht: --robot-file not found", ["identify", "virtual-hammer-test", W / "k1.uff", "--robot-file", W / "nope.toml", "--joints-deg", Q],
         r"nope\.toml", "error"),
        ("vht: a robot file without [[links]] and a joint stiffness (the multibody model needs them)",
         ["identify", "virtual-hammer-test", W / "k2.uff", "--robot-file", nolinks, "--joints-deg", Q,
          "--joint-stiffness-Nm-per-rad", "3e6,4e6,2.5e6,5e5,4.5e5,3e5"],
         r"robot_nolinks\.toml.*links", "error"),
        ("vht: a robot file without [[links]], no joint stiffness (the example's modes on its compliance)",
         _script_cli(["identify", "virtual-hammer-test", str(W / "k2b.uff"), "--robot-file", str(nolinks), "--joints-deg", Q, "--json"],
                     "print('OK' if r.returncode == 0 else r.stderr[-300:]); sys.exit(0 if r.returncode == 0 else 1)"), "", "script"),
        ("vht: a robot file with an unknown table", ["identify", "virtual-hammer-test", W / "k3.uff", "--robot-file", five, "--joints-deg", Q],
         r"robot_5dh\.toml", "error"),
        ("vht: --robot and --robot-file", ["identify", "virtual-hammer-test", W / "k4.uff", "--robot", "irb6600-175-2.55", "--robot-file", KUKA, "--joints-deg", Q],
         r"--robot", "error"),
        ("vht: 5 joint angles", ["identify", "virtual-hammer-test", W / "k5.uff", "--robot-file", KUKA, "--joints-deg", "20,20,10,0,-30"],
         r"--joints-deg", "error"),
        ("vht: the IRB 6600's stiffness file with the KUKA robot file",
         ["identify", "virtual-hammer-test", W / "k6.uff", "--robot-file", KUKA, "--joints-deg", Q, "--joint-stiffness-file", sk_irb],
         r"s_irb\.json.*irb6600.*kr240|s_irb\.json.*kr240.*irb6600", "error"),
        ("vht: joint angles in radians (a warning)",
         _script_cli(["identify", "virtual-hammer-test", str(W / "k7.uff"), "--robot-file", str(KUKA), "--joints-deg", "0.35,0.35,0.17,0,-0.52,0"],
                     "ok = 'radians?' in ' '.join(r.stderr.split())\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        # ---- files that do not fit the config or the stiffness file
        ("fit: model equivalent with 2 modes", ["model", "equivalent", "--stiffness-file", s, "--modes-file", W / "m_two.json"],
         r"m_two\.json.*2 mode.*s\.json", "error"),
        ("fit: modes file with a mode in kHz", ["model", "equivalent", "--stiffness-file", s, "--modes-file", W / "m_khz.json"],
         r"m_khz\.json.*band", "error"),
        ("fit: lobes with a coefficients file for another rake", ["lobes", W / "b_coef_rake.toml", "--method", "frequency"],
         r"coef_rake15\.json.*rake_deg = 15.*b_coef_rake\.toml", "error"),
        ("fit: lobes with a coefficients file of another material", ["lobes", W / "b_coef_mat.toml", "--method", "frequency"],
         r"coef_in718\.json.*IN718.*TC4", "error"),
        ("fit: lobes with the bundled FE coefficients and material Ti-6Al-4V",
         _script_cli(["lobes", str(W / "b_coef_ok.toml"), "--method", "frequency", "--json"],
                     "print('OK' if r.returncode == 0 else r.stderr[-300:]); sys.exit(0 if r.returncode == 0 else 1)"), "", "script"),
        ("fit: fe boring --coefficients of another rake (refused before the FE)",
         ["fe", "boring", EX / "fe_boring_paper.toml", "--coefficients", W / "coef_rake15.json"],
         r"coef_rake15\.json.*rake_deg", "error"),
        # ---- Python API
        ("api2: equivalent_model with 2 modes",
         _script_api("api.equivalent_model(json.loads((W / 's.json').read_text()), json.loads((W / 'm_two.json').read_text()))",
                     ["2 mode"]), "", "script"),
        ("api2: stability_lobes of a config with another rake's coefficients",
         _script_api("api.stability_lobes(str(W / 'b_coef_rake.toml'), method='frequency')", ["coef_rake15.json", "rake_deg"]), "", "script"),
        ("api2: identify_modes of a missing file",
         _script_api("api.identify_modes(str(W / 'nope.uff'))", ["nope.uff"]), "", "script"),
        ("api2: load_hammer_test of a CSV record",
         _script_api("api.load_hammer_test(str(W / 'vib.csv'))", ["vib.csv"]), "", "script"),
        ("api2: stiffness_at_pose with 5 joint angles",
         _script_api("api.stiffness_at_pose(json.loads((W / 's.json').read_text()), [0, 10, 20, 0, 30])", ["joints_deg"]), "", "script"),
        ("api2: directional_stiffness(frame='up')",
         _script_api("api.directional_stiffness(json.loads((W / 's.json').read_text()), frame='up')", ["frame"]), "", "script"),
        ("api2: cutting_coefficients(path=a modes file)",
         _script_api("api.cutting_coefficients(path=str(W / 'm.json'))", ["m.json"]), "", "script"),
        ("api2: simulate_boring(process=None)",
         _script_api("api.simulate_boring(None)", ["process"]), "", "script"),
        ("api2: equivalent_model(stiffness=[1, 2, 3], modes=m)",
         _script_api("api.equivalent_model([1, 2, 3], json.loads((W / 'm.json').read_text()))", ["stiffness"]), "", "script"),
    ]
    out = []
    for desc, argv, pat, mode in cases:
        argv = [str(a).replace("{W}", str(W)) for a in argv]
        out.append((desc, argv, pat, mode))
    return out
