"""Cases of the malformed-input corpus on output paths, huge requests, encodings, corrupt
files, partial failures and durability (resume after a kill, a zero-byte result).

Used by ``benchmarks/malformed_corpus.py``, which runs them with its own cases; not run alone.
:func:`build` writes the fixture files under a folder and returns the cases as tuples
``(description, argv, pattern, mode)``: ``argv`` for ``robobore`` (or, for mode ``script``,
a Python script), ``pattern`` a regular expression the error line must match (the file,
option or key at fault), ``mode`` one of

* ``error``   -- a user mistake: a clear one-line error is expected;
* ``partial`` -- a run with a failed condition: exit 1, the failure named in the output;
* ``script``  -- a multi-step check (kill and resume, zero-byte result): the script exits 0
  and prints ``OK`` when the behaviour is right, else it prints what went wrong.

``fe`` and ``calibrate`` commands are run with the FE solver replaced by a stub that stops
the process (the corpus never runs an FE simulation): each of those cases must be refused
before the FE run would start.
"""
# ruff: noqa: E501

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
PAPER = REPO / "src/robobore/data/paper_example"


def build(W: Path) -> list[tuple[str, list, str, str]]:  # noqa: N803, PLR0915
    """Write the fixtures under ``W`` and return the cases."""
    shutil.rmtree(W, ignore_errors=True)
    W.mkdir(parents=True)
    # ---- fixtures
    afile = W / "afile.txt"
    afile.write_text("x")
    adir = W / "adir"
    adir.mkdir()
    ncdir = W / "d.nc"
    ncdir.mkdir()
    (W / "u16.toml").write_bytes((EX / "sweep_demo.toml").read_text().encode("utf-16"))
    (W / "bin.toml").write_bytes(bytes(range(256)) * 4)
    (W / "u16_lobes.toml").write_bytes((EX / "lobes_single_point.toml").read_text()
                                       .encode("utf-16"))
    (W / "u16_fe.toml").write_bytes((EX / "fe_orthogonal.toml").read_text().encode("utf-16"))
    big = W / "big.toml"
    big.write_text('[sweep]\nname="big"\nrunner="demo"\n[grid]\n'
                   'speed_rpm={start=100,stop=3000,num=10000}\n'
                   'feed_mm_per_rev={start=0.05,stop=0.3,num=10000}\n'
                   'depth_of_cut_mm={start=0.1,stop=1,num=10000}\n')
    fe = (EX / "fe_orthogonal.toml").read_text()
    (W / "fe_huge.toml").write_text(fe.replace("uncut_chip_thickness_um = 60.0",
                                               "uncut_chip_thickness_um = 0.05")
                                    .replace("length_mm = 1.0", "length_mm = 50.0")
                                    .replace("element_size_um = 10.0", "element_size_um = 0.01"))
    feb = (EX / "fe_boring_paper.toml").read_text()

    (W / "feb_huge.toml").write_text(re.sub(r"element_size_um\s*=\s*[0-9.]+",
                                            "element_size_um = 0.01", feb))
    # corrupt coefficient files
    (W / "coef_corrupt.json").write_text('{"coefficients": {"Ktc_N_per_m2": 1.0e9,')
    (W / "coef_list.json").write_text("[1, 2, 3]")
    (W / "coef_u16.json").write_bytes(
        (PAPER / "tc4_fe_coefficients.json").read_text().encode("utf-16"))
    paper = (PAPER / "paper.toml").read_text()
    for name in ("coef_corrupt", "coef_list", "coef_u16"):
        d = W / f"paper_{name}"
        d.mkdir()
        for f in PAPER.iterdir():
            if f.is_file():
                shutil.copy(f, d / f.name)
        shutil.copy(W / f"{name}.json", d / "tc4_fe_coefficients.json")
    d = W / "paper_band3"
    shutil.copytree(PAPER, d)
    (d / "paper.toml").write_text(paper.replace("band_Hz = [3.0, 60.0]", "band_Hz = [3]"))
    d = W / "paper_bandstr"
    shutil.copytree(PAPER, d)
    (d / "paper.toml").write_text(paper.replace("band_Hz = [3.0, 60.0]", 'band_Hz = "3-60"'))
    bp = (EX / "boring_paper.toml").read_text()
    (W / "boring_coef_corrupt.toml").write_text(
        bp + '\n[coefficients]\nfile = "coef_corrupt.json"\n' if "[coefficients]" not in bp
        else re.sub(r"\[coefficients\][^\[]*", '[coefficients]\nfile = "coef_corrupt.json"\n', bp))
    (W / "boring_coef_u16.toml").write_text(
        re.sub(r"\[coefficients\][^\[]*", '[coefficients]\nfile = "coef_u16.json"\n', bp)
        if "[coefficients]" in bp else bp + '\n[coefficients]\nfile = "coef_u16.json"\n')
    # NPZ
    np.savez(W / "pickled.npz", frequency_Hz=np.arange(10.0),
             frf=np.array([{"a": 1}] * 10, dtype=object), frf_type=np.array("accelerance"))
    (W / "empty.npz").write_bytes(b"")
    (W / "garbage.uff").write_bytes(os.urandom(5000))
    (W / "u16.uff").write_bytes("    -1\n    58\n".encode("utf-16") * 50)
    # JSON files for model equivalent / robot stiffness
    (W / "list.json").write_text("[1, 2, 3]")
    (W / "modes_list.json").write_text('{"modes": {"frequency_Hz": 5}}')
    (W / "stiff_list.json").write_text('{"directional_stiffness_N_per_m": [1e6, 2e6, 3e6]}')
    (W / "u16.json").write_bytes('{"directional_stiffness_N_per_m": {"x": 1e6, "y": 1e6, "z": 1e6}}'
                                 .encode("utf-16"))
    (W / "bin.json").write_bytes(os.urandom(300))
    (W / "ok_stiff.json").write_text('{"directional_stiffness_N_per_m": {"x": 3e6, "y": 2.5e6, '
                                     '"z": 4e6}}')
    # campaign / measured CSV in UTF-16 and binary
    camp = REPO / "src/robobore/data/campaign_irb6600"
    camp_csv = next(camp.glob("*.csv"))
    (W / "camp_u16.csv").write_bytes(camp_csv.read_text().encode("utf-16"))
    (W / "camp_bin.csv").write_bytes(os.urandom(4000))
    (W / "meas_u16.csv").write_bytes((PAPER / "measured_synthetic.csv").read_text()
                                     .encode("utf-16"))
    (W / "robot_bin.toml").write_bytes(os.urandom(500))
    # a results store with a corrupt store.json; a file as a store
    (W / "badstore").mkdir()
    (W / "badstore/store.json").write_text("{not json")
    (W / "badstore/results").mkdir()
    (W / "u16_mat.toml").write_bytes(b"\xff\xfe" + "[johnson_cook]\n".encode("utf-16-le"))
    (W / "fe_mat_u16.toml").write_text(fe.replace('name = "TC4"', 'name = "u16_mat.toml"'))


    # ---- more fixtures
    HAM = next((REPO / "src/robobore/data/hammer_test").glob("*.uff"))
    (W / "trunc.uff").write_bytes(HAM.read_bytes()[: HAM.stat().st_size // 3])
    (W / "empty.uff").write_bytes(b"")
    (W / "empty.toml").write_text("")
    (W / "empty.json").write_text("")
    (W / "empty.csv").write_text("")
    (W / "trunc_camp.csv").write_text(camp_csv.read_text()[: len(camp_csv.read_text()) // 2])
    (W / "meas_bin.csv").write_bytes(os.urandom(3000))
    np.savez(W / "nokeys.npz", a=np.arange(3))
    np.savez(W / "strfrf.npz", frequency_Hz=np.arange(5.0), frf=np.array(["a"] * 5),
             frf_type=np.array("accelerance"))
    (W / "u16_paper.toml").write_bytes(paper.encode("utf-16"))
    (W / "u16_cal.toml").write_bytes(paper.encode("utf-16"))
    (W / "bin_mat.toml").write_bytes(os.urandom(400))
    (W / "fe_mat_bin.toml").write_text(fe.replace('name = "TC4"', 'name = "bin_mat.toml"'))
    (W / "u16_robot.toml").write_bytes("name = 'x'\n".encode("utf-16"))
    (W / "big_conditions.toml").write_text(
        '[sweep]\nname="bc"\n[grid]\nspeed_rpm={start=100,stop=3000,num=1000}\n'
        'feed_mm_per_rev={start=0.05,stop=0.3,num=1000}\ndepth_of_cut_mm=[0.1]\n')
    (W / "sweep_fail.toml").write_text(
        '[sweep]\nname="sf"\nrunner="demo"\n[grid]\nspeed_rpm=[200,400]\nfeed_mm_per_rev=[0.1]\n'
        'depth_of_cut_mm=[0.1]\n[model]\nduration_s=1.0\n[runner_options]\nfail_speeds_rpm=[400]\n')
    (W / "sweep_boring_bad.toml").write_text(
        '[sweep]\nname="bb"\nrunner="boring"\n[grid]\nspeed_rpm=[300]\nfeed_mm_per_rev=[0.1]\n'
        'depth_of_cut_mm=[0.05]\n[model]\nsystem="robot"\n[model.dynamics.insert]\n'
        'nose_radius_mm=-1\n')
    (W / "emptystore").mkdir()
    (W / "timedomain_huge.toml").write_text((EX / "boring_paper.toml").read_text().replace(
        "revolutions = 60", "revolutions = 20000\nsamples_per_rev = 200000"))
    (W / "ro_parent").mkdir()

    for name, old, new, extra in (
            ("paper_campaign_u16", '# campaign = "my_campaign.csv"', 'campaign = "c16.csv"',
             ("c16.csv", camp_csv.read_text().encode("utf-16"))),
            ("paper_modal_garbage", '# file = "my_hammer_test.uff"', 'file = "g.uff"',
             ("g.uff", os.urandom(3000))),
            ("paper_measured_bin", 'file = "measured_synthetic.csv"', 'file = "m.csv"',
             ("m.csv", os.urandom(2000))),
            ("paper_coef_strings", None, None,
             ("tc4_fe_coefficients.json", b'{"coefficients": {"Ktc_N_per_m2": "lots", '
              b'"Kte_N_per_m": 1, "Kfc_N_per_m2": 1, "Kfe_N_per_m": 1}}')),
            ("paper_missing_campaign", '# campaign = "my_campaign.csv"', 'campaign = "nope.csv"',
             None)):
        d = W / name
        shutil.copytree(PAPER, d)
        if old:
            (d / "paper.toml").write_text(paper.replace(old, new))
        if extra:
            (d / extra[0]).write_bytes(extra[1])
    (W / "lobes_coef_list.toml").write_text(
        re.sub(r"\[coefficients\][^\[]*", '[coefficients]\nfile = "coef_list.json"\n', bp)
        if "[coefficients]" in bp else bp + '\n[coefficients]\nfile = "coef_list.json"\n')

    O = W / "out"  # fresh output names under here
    CASES = [
        # ---- outputs refused before work
        ("out: simulate --out is a folder", ["simulate", "boring", EX / "boring_paper.toml",
                                             "--out", ncdir], "--out"),
        ("out: simulate --out under a file", ["simulate", "boring", EX / "boring_paper.toml",
                                              "--out", afile / "r.nc"], "--out"),
        ("out: simulate --plot is a file", ["simulate", "boring", EX / "boring_paper.toml",
                                            "--plot", afile], "--plot"),
        ("out: lobes --plot is a file", ["lobes", EX / "lobes_single_point.toml", "--plot", afile],
         "--plot"),
        ("out: lobes --plot uncreatable", ["lobes", EX / "lobes_single_point.toml", "--plot",
                                           "/proc/robobore/x"], "--plot"),
        ("out: modes --out is a folder", ["identify", "modes", "--example", "--out", adir], "--out"),
        ("out: modes --plot is a file", ["identify", "modes", "--example", "--plot", afile],
         "--plot"),
        ("out: hammer test OUT is a folder", ["identify", "virtual-hammer-test", adir], "OUT"),
        ("out: hammer test OUT under a file", ["identify", "virtual-hammer-test",
                                               afile / "t.uff"], "OUT"),
        ("out: campaign OUT is a folder", ["robot", "campaign", adir], "OUT"),
        ("out: campaign OUT uncreatable", ["robot", "campaign", "/proc/robobore/c.csv"], "OUT"),
        ("out: robot stiffness --plot file", ["robot", "stiffness", "--joints-deg", "0,-20,20,0,30,0",
                                              "--joint-stiffness-Nm-per-rad",
                                              "1e7,1e7,1e7,1e6,1e6,1e6", "--plot", afile], "--plot"),
        ("out: identify stiffness --plot file", ["identify", "stiffness", "--example", "--plot",
                                                 afile], "--plot"),
        ("out: sweep --out is a file", ["sweep", EX / "sweep_demo.toml", "--out", afile], "--out"),
        ("out: sweep --report is a folder", ["sweep", EX / "sweep_demo.toml", "--out", O / "s1",
                                             "--report", adir, "--workers", "0"], "--report"),
        ("out: compare --report under a file", ["compare", PAPER / "measured_synthetic.csv",
                                                W / "badstore", "--report", afile / "r.html"],
         "--report"),
        ("out: paper --out is a file", ["paper", "--fast", "--out", afile], "--out"),
        ("out: paper --out uncreatable", ["paper", "--fast", "--out", "/proc/robobore/p"], "--out"),
        ("out: calibrate --out is a folder", ["calibrate", "forces", "--out", adir], "--out"),
        ("out: fe orthogonal --out folder", ["fe", "orthogonal", EX / "fe_orthogonal.toml", "--out",
                                             adir], "--out"),
        ("out: fe orthogonal --vtk file", ["fe", "orthogonal", EX / "fe_orthogonal.toml", "--vtk",
                                           afile], "--vtk"),
        ("out: fe orthogonal --plot uncreatable", ["fe", "orthogonal", EX / "fe_orthogonal.toml",
                                                   "--plot", "/proc/robobore/p"], "--plot"),
        ("out: fe boring --vtk file", ["fe", "boring", EX / "fe_boring_paper.toml", "--vtk", afile],
         "--vtk"),
        # ---- huge requests
        ("size: sweep grid 1e12", ["sweep", big, "--out", O / "big"], "grid"),
        ("size: fe 0.01 um mesh of 50 mm", ["fe", "orthogonal", W / "fe_huge.toml"],
         "element_size_um"),
        ("size: fe boring 0.01 um mesh", ["fe", "boring", W / "feb_huge.toml"], "element_size_um"),
        ("size: 20000 rev x 200000 samples", ["simulate", "boring", EX / "boring_paper.toml",
                                              "--revolutions", "20000", "--samples-per-rev",
                                              "200000"], "revolutions"),
        ("size: hammer test 1e11 samples", ["identify", "virtual-hammer-test", O / "h.uff",
                                            "--sample-rate-hz", "1e7", "--duration-s", "1e4"],
         "--duration-s"),
        ("size: hammer test nan rate", ["identify", "virtual-hammer-test", O / "h2.uff",
                                        "--sample-rate-hz", "nan"], "--sample-rate-hz"),
        # ---- encodings and corrupt files
        ("enc: sweep UTF-16 TOML", ["sweep", W / "u16.toml", "--out", O / "s2"], "u16.toml"),
        ("enc: sweep binary TOML", ["sweep", W / "bin.toml", "--out", O / "s3"], "bin.toml"),
        ("enc: lobes UTF-16 TOML", ["lobes", W / "u16_lobes.toml"], "u16_lobes.toml"),
        ("enc: fe UTF-16 TOML", ["fe", "orthogonal", W / "u16_fe.toml"], "u16_fe.toml"),
        ("enc: fe material UTF-16", ["fe", "orthogonal", W / "fe_mat_u16.toml"], "u16_mat.toml"),
        ("enc: config is a folder", ["lobes", adir], "adir"),
        ("enc: config missing", ["lobes", W / "nope.toml"], "nope.toml"),
        ("corrupt: simulate coefficients JSON", ["simulate", "boring",
                                                 W / "boring_coef_corrupt.toml"], "coef_corrupt"),
        ("corrupt: simulate coefficients UTF-16", ["simulate", "boring",
                                                   W / "boring_coef_u16.toml"], "coef_u16"),
        ("corrupt: paper coefficients JSON", ["paper", W / "paper_coef_corrupt/paper.toml", "--fast",
                                              "--out", O / "p1"], "tc4_fe_coefficients.json"),
        ("corrupt: paper coefficients list", ["paper", W / "paper_coef_list/paper.toml", "--fast",
                                              "--out", O / "p2"], "tc4_fe_coefficients.json"),
        ("corrupt: paper coefficients UTF-16", ["paper", W / "paper_coef_u16/paper.toml", "--fast",
                                                "--out", O / "p3"], "tc4_fe_coefficients.json"),
        ("corrupt: paper band_Hz = [3]", ["paper", W / "paper_band3/paper.toml", "--fast", "--out",
                                          O / "p4"], "band_Hz"),
        ("corrupt: paper band_Hz string", ["paper", W / "paper_bandstr/paper.toml", "--fast",
                                           "--out", O / "p5"], "band_Hz"),
        ("corrupt: pickled NPZ", ["identify", "modes", W / "pickled.npz"], "pickled.npz"),
        ("corrupt: empty NPZ", ["identify", "modes", W / "empty.npz"], "empty.npz"),
        ("corrupt: garbage UFF", ["identify", "modes", W / "garbage.uff"], "garbage.uff"),
        ("corrupt: UTF-16 UFF", ["identify", "modes", W / "u16.uff"], "u16.uff"),
        ("corrupt: equivalent stiffness list", ["model", "equivalent", "--stiffness-file",
                                                W / "list.json", "--frequencies-Hz", "7,17,25",
                                                "--damping-ratios", "0.03,0.03,0.02"], "list.json"),
        ("corrupt: equivalent stiffness xyz list", ["model", "equivalent", "--stiffness-file",
                                                    W / "stiff_list.json", "--frequencies-Hz",
                                                    "7,17,25", "--damping-ratios", "0.03,0.03,0.02"],
         "stiff_list.json"),
        ("corrupt: equivalent modes table", ["model", "equivalent", "--stiffness-file",
                                             W / "ok_stiff.json", "--modes-file",
                                             W / "modes_list.json"], "modes_list.json"),
        ("corrupt: equivalent modes list", ["model", "equivalent", "--stiffness-file",
                                            W / "ok_stiff.json", "--modes-file", W / "list.json"],
         "list.json"),
        ("enc: equivalent UTF-16 JSON", ["model", "equivalent", "--stiffness-file", W / "u16.json",
                                         "--frequencies-Hz", "7,17,25", "--damping-ratios",
                                         "0.03,0.03,0.02"], "u16.json"),
        ("enc: equivalent binary JSON", ["model", "equivalent", "--stiffness-file", W / "bin.json",
                                         "--frequencies-Hz", "7,17,25", "--damping-ratios",
                                         "0.03,0.03,0.02"], "bin.json"),
        ("enc: joint stiffness UTF-16 JSON", ["robot", "stiffness", "--joints-deg", "0,-20,20,0,30,0",
                                              "--joint-stiffness-file", W / "u16.json"], "u16.json"),
        ("enc: joint stiffness list JSON", ["robot", "stiffness", "--joints-deg", "0,-20,20,0,30,0",
                                            "--joint-stiffness-file", W / "list.json"], "list.json"),
        ("enc: campaign UTF-16", ["identify", "stiffness", W / "camp_u16.csv", "--robot", "irb6600-175-2.55"], "camp_u16.csv"),
        ("enc: campaign binary", ["identify", "stiffness", W / "camp_bin.csv", "--robot", "irb6600-175-2.55"], "camp_bin.csv"),
        ("enc: robot file binary", ["robot", "fk", "--joints-deg", "0,0,0,0,0,0", "--robot-file",
                                    W / "robot_bin.toml"], "robot_bin.toml"),
        ("enc: measured CSV UTF-16", ["compare", W / "meas_u16.csv", W / "badstore"],
         "meas_u16.csv|store.json"),
        ("corrupt: store.json", ["sweep", EX / "sweep_demo.toml", "--out", W / "badstore"],
         "store.json"),
        ("corrupt: compare store is a file", ["compare", PAPER / "measured_synthetic.csv", afile],
         "afile"),

        # ---- more output cases
        ("out: lobes --plot under a file", ["lobes", EX / "lobes_single_point.toml", "--plot",
                                            afile / "sub"], "--plot"),
        ("out: simulate --out uncreatable", ["simulate", "boring", EX / "boring_paper.toml",
                                             "--out", "/proc/robobore/r.nc"], "--out"),
        ("out: simulate --out not .nc", ["simulate", "boring", EX / "boring_paper.toml", "--out",
                                         O / "r.txt"], "--out"),
        ("out: modes --out under a file", ["identify", "modes", "--example", "--out",
                                           afile / "r.json"], "--out"),
        ("out: modes --plot uncreatable", ["identify", "modes", "--example", "--plot",
                                           "/proc/robobore/p"], "--plot"),
        ("out: hammer --example OUT folder", ["identify", "virtual-hammer-test", "--example", adir],
         "OUT"),
        ("out: campaign OUT under a file", ["robot", "campaign", afile / "c.csv"], "OUT"),
        ("out: robot stiffness --plot uncreatable", ["robot", "stiffness", "--joints-deg",
                                                     "0,-20,20,0,30,0",
                                                     "--joint-stiffness-Nm-per-rad",
                                                     "1e7,1e7,1e7,1e6,1e6,1e6", "--plot",
                                                     "/proc/robobore/p"], "--plot"),
        ("out: sweep --out uncreatable", ["sweep", EX / "sweep_demo.toml", "--out",
                                          "/proc/robobore/s"], "--out"),
        ("out: sweep --out under a file", ["sweep", EX / "sweep_demo.toml", "--out", afile / "s"],
         "--out"),
        ("out: sweep --report under a file", ["sweep", EX / "sweep_demo.toml", "--out", O / "s9",
                                              "--report", afile / "r.html"], "--report"),
        ("out: compare --report is a folder", ["compare", PAPER / "measured_synthetic.csv",
                                               W / "badstore", "--report", adir], "--report"),
        ("out: paper --out under a file", ["paper", "--fast", "--out", afile / "p"], "--out"),
        ("out: calibrate --out under a file", ["calibrate", "forces", "--out", afile / "c.json"],
         "--out"),
        ("out: calibrate --out uncreatable", ["calibrate", "forces", "--out",
                                              "/proc/robobore/c.json"], "--out"),
        ("out: fe orthogonal --out under a file", ["fe", "orthogonal", EX / "fe_orthogonal.toml",
                                                   "--out", afile / "h.nc"], "--out"),
        ("out: fe orthogonal --plot file", ["fe", "orthogonal", EX / "fe_orthogonal.toml",
                                            "--plot", afile], "--plot"),
        ("out: fe boring --vtk uncreatable", ["fe", "boring", EX / "fe_boring_paper.toml", "--vtk",
                                              "/proc/robobore/v"], "--vtk"),
        # ---- more size cases
        ("size: sweep grid 1e6", ["sweep", W / "big_conditions.toml", "--out", O / "bc"], "grid"),
        ("size: time-domain from [simulation]", ["simulate", "boring", W / "timedomain_huge.toml"],
         "revolutions"),
        ("size: hammer test 1e5 hits", ["identify", "virtual-hammer-test", O / "h3.uff", "--hits",
                                        "100000", "--duration-s", "100"], "--hits"),
        ("size: hammer test 0 hits", ["identify", "virtual-hammer-test", O / "h4.uff", "--hits",
                                      "0"], "--hits"),
        # ---- more corrupt / encoding cases
        ("corrupt: truncated UFF", ["identify", "modes", W / "trunc.uff"], "trunc.uff"),
        ("corrupt: empty UFF", ["identify", "modes", W / "empty.uff"], "empty.uff"),
        ("corrupt: NPZ without keys", ["identify", "modes", W / "nokeys.npz"], "nokeys.npz"),
        ("corrupt: NPZ string FRF", ["identify", "modes", W / "strfrf.npz"], "strfrf.npz"),
        ("corrupt: empty TOML (lobes)", ["lobes", W / "empty.toml"], "empty.toml"),
        ("corrupt: empty TOML (sweep)", ["sweep", W / "empty.toml", "--out", O / "e"],
         "empty.toml"),
        ("corrupt: empty JSON stiffness", ["model", "equivalent", "--stiffness-file",
                                           W / "empty.json", "--frequencies-Hz", "7,17,25",
                                           "--damping-ratios", "0.03,0.03,0.02"], "empty.json"),
        ("corrupt: empty campaign CSV", ["identify", "stiffness", W / "empty.csv", "--robot",
                                         "irb6600-175-2.55"], "empty.csv"),
        ("corrupt: truncated campaign CSV", ["identify", "stiffness", W / "trunc_camp.csv",
                                             "--robot", "irb6600-175-2.55"], "trunc_camp.csv"),
        ("corrupt: binary measured CSV", ["compare", W / "meas_bin.csv", W / "badstore"],
         "meas_bin.csv|store.json"),
        ("corrupt: compare empty store folder", ["compare", PAPER / "measured_synthetic.csv",
                                                 W / "emptystore"], "emptystore"),
        ("enc: paper UTF-16 config", ["paper", W / "u16_paper.toml", "--fast", "--out", O / "p6"],
         "u16_paper.toml"),
        ("enc: calibrate UTF-16 config", ["calibrate", "forces", W / "u16_cal.toml"],
         "u16_cal.toml"),
        ("enc: fe material binary", ["fe", "orthogonal", W / "fe_mat_bin.toml"], "bin_mat.toml"),
        ("enc: robot file UTF-16", ["robot", "fk", "--joints-deg", "0,0,0,0,0,0", "--robot-file",
                                    W / "u16_robot.toml"], "u16_robot.toml"),
        ("enc: stiffness file missing", ["model", "equivalent", "--stiffness-file",
                                         W / "nope.json", "--frequencies-Hz", "7,17,25",
                                         "--damping-ratios", "0.03,0.03,0.02"], "nope.json"),
        ("enc: stiffness file is a folder", ["model", "equivalent", "--stiffness-file", adir,
                                             "--frequencies-Hz", "7,17,25", "--damping-ratios",
                                             "0.03,0.03,0.02"], "adir"),
        ("enc: modes file binary", ["model", "equivalent", "--stiffness-file", W / "ok_stiff.json",
                                    "--modes-file", W / "bin.json"], "bin.json"),
        ("enc: joint stiffness file folder", ["robot", "stiffness", "--joints-deg",
                                              "0,-20,20,0,30,0", "--joint-stiffness-file", adir],
         "adir"),
        ("enc: fe config is a folder", ["fe", "orthogonal", adir], "adir"),
        ("enc: fe boring UTF-16", ["fe", "boring", W / "u16_fe.toml"], "u16_fe.toml"),
        # ---- partial failure
        ("fail: sweep with a failed condition", ["sweep", W / "sweep_fail.toml", "--out", O / "sf",
                                                 "--workers", "0"], "400"),
        ("fail: boring runner bad model", ["sweep", W / "sweep_boring_bad.toml", "--out", O / "sb",
                                           "--workers", "0"], "sweep_boring_bad.toml"),

        ("paper: campaign UTF-16", ["paper", W / "paper_campaign_u16/paper.toml", "--fast", "--out",
                                    O / "q1"], "c16.csv"),
        ("paper: hammer test garbage", ["paper", W / "paper_modal_garbage/paper.toml", "--fast",
                                        "--out", O / "q2"], "g.uff"),
        ("paper: measured CSV binary", ["paper", W / "paper_measured_bin/paper.toml", "--fast",
                                        "--out", O / "q3"], "m.csv"),
        ("paper: coefficient strings", ["paper", W / "paper_coef_strings/paper.toml", "--fast",
                                        "--out", O / "q4"], "Ktc|tc4_fe_coefficients"),
        ("paper: missing campaign", ["paper", W / "paper_missing_campaign/paper.toml", "--fast",
                                     "--out", O / "q5"], "nope.csv"),
        ("corrupt: lobes coefficients list", ["lobes", W / "lobes_coef_list.toml"], "coef_list"),
    ]

    # ---- found while merging the corpora
    (W / "sweep_empty_levels.toml").write_text(
        '[sweep]\nname="e"\nrunner="demo"\n[grid]\nspeed_rpm=[]\nfeed_mm_per_rev=[0.1]\n'
        'depth_of_cut_mm=[0.1]\n')
    (W / "lobes_huge_count.toml").write_text(
        (EX / "lobes_single_point.toml").read_text().replace("count = 601",
                                                             "count = 1000000000"))
    for i, (old, new) in enumerate((("edge_radius_um = 20.0", "edge_radius_um = 0.02"),
                                    ("approach_angle_deg = 90.0", "approach_angle_deg = 1.5708"),
                                    ("ra_tolerance_um = 1.6", "ra_tolerance_um = 0.0016"))):
        assert old in bp, old
        (W / f"boring_down{i}.toml").write_text(bp.replace(old, new))
        CASES.append((f"slip: process TOML {new} (a unit slip downwards)",
                      ["simulate", "boring", W / f"boring_down{i}.toml"],
                      f"boring_down{i}.toml.*{old.split(' =')[0]}"))
    CASES += [
        ("corrupt: sweep TOML with an empty level list", ["sweep", W / "sweep_empty_levels.toml",
                                                          "--out", O / "se"],
         "sweep_empty_levels.toml"),
        ("size: lobes TOML with 1e9 speeds", ["lobes", W / "lobes_huge_count.toml"],
         "lobes_huge_count.toml.*speed_rpm.count"),
        ("corrupt: sweep --scheduler unreachable", ["sweep", EX / "sweep_demo.toml", "--out",
                                                    O / "sx", "--scheduler", "tcp://127.0.0.1:1"],
         "127.0.0.1:1"),
        ("corrupt: identify modes --frf-type bogus", ["identify", "modes", "--example",
                                                      "--frf-type", "bogus"], "--frf-type"),
    ]
    return [(name, argv, must, "error") for name, argv, must in CASES if not
            name.startswith("fail:")] + \
        [(name, argv, must, "partial") for name, argv, must in CASES if
         name.startswith("fail:")] + durability_cases(W)


# ----------------------------------------------------------------------------- durability
_SWEEP = '''
[sweep]
name = "dur"
runner = "demo"
seed = 3
[grid]
speed_rpm = {speeds}
feed_mm_per_rev = [0.1, 0.3]
depth_of_cut_mm = [0.05, 0.2]
pressure_MPa = [0.0]
[model]
duration_s = 2.0
[runner_options]
marker_dir = "{marks}"
sleep_s = {sleep}
'''

_PRELUDE = '''
import json, os, signal, subprocess, sys, time
from collections import Counter
from pathlib import Path
d = Path(sys.argv[1])
marks = d / "marks"
cfg = d / "sweep.toml"
cfg.write_text(sys.argv[2].format(speeds=sys.argv[3], marks=marks, sleep=sys.argv[4]))
store = d / "store"
def cmd(*extra):
    return [sys.executable, "-m", "robobore", "sweep", str(cfg), "--out", str(store),
            "--json", *extra]
def markers():
    return Counter(p.name.split(".")[0] for p in marks.glob("*.run"))
def fail(msg):
    print("WRONG:", msg); sys.exit(1)
'''

#: a result file left empty or unreadable is recomputed on resume, with a warning
_ZERO_BYTE = _PRELUDE + '''
r = subprocess.run(cmd("--workers", "0"), capture_output=True, text=True)
if r.returncode != 0: fail("first run: " + r.stderr[-300:])
res = sorted((store / "results").glob("*.nc"))
if len(res) != 12: fail(f"{len(res)} results stored, expected 12")
empty, garbage = res[0], res[1]
empty.write_bytes(b"")
garbage.write_bytes(b"not netCDF" * 20)
r = subprocess.run(cmd("--workers", "0"), capture_output=True, text=True)
if r.returncode != 0: fail("resume: " + r.stderr[-300:])
out = json.loads(r.stdout)
if out["computed"] != 2 or out["skipped"] != 10: fail(f"resume computed {out['computed']}")
w = " ".join(out.get("warnings", []))
if "zero-byte" not in w or empty.stem not in w: fail("no warning naming the zero-byte file")
if empty.stat().st_size == 0: fail("the zero-byte result was not recomputed")
m = markers()
if m[empty.stem] != 2 or m[garbage.stem] != 2: fail(f"recomputed counts {m}")
print("OK: 2 of 12 results recomputed, warned:", w[:200])
'''

#: SIGKILL at random points (seeded), then a run to the end: each condition stored once
_KILL = _PRELUDE + '''
import random
rng = random.Random(int(sys.argv[5]))
target, snaps = 0, []
for _ in range(3):
    target = min(target + rng.randint(1, 4), 15)
    p = subprocess.Popen(cmd("--workers", "2", "--threads"), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, start_new_session=True)
    t0 = time.monotonic()
    while p.poll() is None and time.monotonic() - t0 < 90:
        n = len(list((store / "results").glob("*.nc"))) if (store / "results").exists() else 0
        if n >= target: break
        time.sleep(0.01)
    time.sleep(rng.uniform(0.0, 0.2))
    if p.poll() is None: os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    done = {q.stem for q in (store / "results").glob("*.nc") if q.stat().st_size > 0}
    snaps.append((done, markers()))
r = subprocess.run(cmd("--workers", "0"), capture_output=True, text=True)
if r.returncode != 0: fail("final run: " + r.stderr[-300:])
keys = {q.stem for q in (store / "results").glob("*.nc")}
if len(keys) != 16: fail(f"{len(keys)} of 16 conditions stored")
final = markers()
for done, then in snaps:
    for k in done:
        if final[k] != then[k]: fail(f"{k} stored before a kill was computed again")
idx = json.loads((store / "index.json").read_text())
if idx["counts"] != {"done": 16, "failed": 0, "pending": 0}: fail(str(idx["counts"]))
if [q for q in store.rglob("*.tmp")]: fail("temporary files left in the store")
print(f"OK: 3 kills (after {[len(s[0]) for s in snaps]} stored), 16 conditions, "
      f"{sum(final.values())} starts")
'''


def durability_cases(W: Path) -> list[tuple[str, list, str, str]]:  # noqa: N803
    import sys

    py = sys.executable
    return [
        ("resume: zero-byte and unreadable results recomputed",
         [py, "-c", _ZERO_BYTE, "{d}", _SWEEP, "[200, 400, 600]", "0.0"], "", "script"),
        ("resume: sweep killed at 3 random points (seed 1)",
         [py, "-c", _KILL, "{d}", _SWEEP, "[200, 400, 600, 800]", "0.15", "1"], "", "script"),
        ("resume: sweep killed at 3 random points (seed 2)",
         [py, "-c", _KILL, "{d}", _SWEEP, "[200, 400, 600, 800]", "0.15", "2"], "", "script"),
    ]
