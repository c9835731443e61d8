"""Outputs checked before work, durable atomic writes, size guards, partial failures and no
traceback at the CLI's top level (issue 28, items 3-6)."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import ConfigError, DataError

REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
runner = CliRunner()


def _cli(*args: str):
    return runner.invoke(app, [str(a) for a in args])


def _sub(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), COLUMNS="300")
    return subprocess.run([sys.executable, "-m", "robobore", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, env=env)


# --------------------------------------------------------------- outputs checked up front
def test_check_output_dir_and_file(tmp_path):
    from robobore.io.outputs import check_output_dir, check_output_file

    f = tmp_path / "f.txt"
    f.write_text("x")
    assert check_output_dir(None, "--plot") is None
    assert check_output_dir(tmp_path / "a" / "b", "--plot").is_dir()  # parents created
    assert check_output_file(tmp_path / "c" / "r.nc", "--out") == tmp_path / "c" / "r.nc"
    assert list((tmp_path / "c").iterdir()) == []  # the probe file is gone
    for call, path, words in (
            (check_output_dir, f, "existing file, not a folder"),
            (check_output_dir, f / "sub", "cannot create"),
            (check_output_dir, Path("/proc/robobore-test/x"), "cannot create"),
            (check_output_file, tmp_path, "existing folder, not a file"),
            (check_output_file, f / "r.nc", "existing file, not a folder")):
        with pytest.raises(ConfigError) as e:
            call(path, "--opt")
        assert words in str(e.value) and "--opt" in str(e.value) and str(path) in str(e.value)


def test_read_only_folder_is_refused(tmp_path, monkeypatch):
    """A folder that refuses new files (read-only; faked for root, who writes anyway)."""
    import tempfile

    from robobore.io import outputs

    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(stat.S_IRUSR | stat.S_IXUSR)
    if os.geteuid() == 0:
        def refuse(*a, **k):
            raise PermissionError(13, "Permission denied")

        monkeypatch.setattr(tempfile, "mkstemp", refuse)
    try:
        with pytest.raises(ConfigError) as e:
            outputs.check_output_dir(ro, "--plot")
        assert "cannot write into the folder" in str(e.value)
        assert "Permission denied" in str(e.value)
    finally:
        ro.chmod(stat.S_IRWXU)


@pytest.mark.parametrize("args,option", [
    (["lobes", EX / "lobes_single_point.toml", "--plot", "{file}"], "--plot"),
    (["simulate", "boring", EX / "boring_paper.toml", "--out", "{dir}"], "--out"),
    (["simulate", "boring", EX / "boring_paper.toml", "--plot", "{file}"], "--plot"),
    (["identify", "modes", "--example", "--plot", "{file}"], "--plot"),
    (["identify", "modes", "--example", "--out", "{dir}"], "--out"),
    (["identify", "virtual-hammer-test", "{dir}"], "OUT"),
    (["robot", "campaign", "{file}/c.csv"], "OUT"),
    (["identify", "stiffness", "--example", "--plot", "{file}"], "--plot"),
    (["sweep", EX / "sweep_demo.toml", "--out", "{file}"], "--out"),
    (["paper", "--fast", "--out", "{file}"], "--out"),
    (["calibrate", "forces", "--out", "{dir}"], "--out"),
    (["calibrate", "dynamics", EX / "boring_paper.toml", "--out", "{file}"], "--out"),
    (["fe", "orthogonal", EX / "fe_orthogonal.toml", "--out", "{dir}"], "--out"),
    (["fe", "orthogonal", EX / "fe_orthogonal.toml", "--vtk", "{file}"], "--vtk"),
    (["fe", "boring", EX / "fe_boring_paper.toml", "--vtk", "{file}"], "--vtk"),
])
def test_unwritable_output_refused_before_any_work(tmp_path, monkeypatch, args, option):
    """Each command refuses a destination it cannot write before computing anything (FE
    runs, the paper study and the calibration included): one line, exit 2. The entry points
    of the work are replaced by functions that fail the test if they are reached."""
    import importlib

    def work_started(*a, **k):
        raise AssertionError("the computation started before the output was checked")

    # modules that bind a patched name at import: imported first, so they keep the real one
    importlib.import_module("robobore.modal.example")

    for mod, name in (("robobore.cutting.fe.models.orthogonal", "simulate_orthogonal"),
                      ("robobore.cutting.fe.models.boring3d", "simulate_boring"),
                      ("robobore.cutting.calibrate", "calibrate_forces"),
                      ("robobore.study.paper", "run_paper"),
                      ("robobore.study.sweep", "run_sweep"),
                      ("robobore.dynamics.api", "run_boring"),
                      ("robobore.dynamics.stability", "lobes_frequency_domain"),
                      ("robobore.modal.identify", "identify_modes"),
                      ("robobore.modal.virtual", "simulate_hammer_test"),
                      ("robobore.robot.campaign", "simulate_campaign"),
                      ("robobore.robot.identify", "identify_joint_stiffness"),
                      ("robobore.robot.stiffness", "stiffness_at")):
        monkeypatch.setattr(importlib.import_module(mod), name, work_started)
    f = tmp_path / "afile.nc"
    f.write_text("x")
    d = tmp_path / "adir.nc"
    d.mkdir()
    argv = [str(a).replace("{file}", str(f)).replace("{dir}", str(d)) for a in args]
    t0 = time.perf_counter()
    r = _cli(*argv)
    took = time.perf_counter() - t0
    assert r.exit_code == 2, r.output
    assert "error:" in r.output and option in r.output
    assert "Traceback" not in r.output
    print(f"{' '.join(map(str, args[:2]))}: refused in {took:.2f} s")


# ------------------------------------------------------------------ durable atomic writes
def _record_fsyncs(monkeypatch) -> list[str]:
    kinds: list[str] = []
    real = os.fsync

    def spy(fd):
        kinds.append("dir" if stat.S_ISDIR(os.fstat(fd).st_mode) else "file")
        return real(fd)

    monkeypatch.setattr(os, "fsync", spy)
    return kinds


def test_atomic_writes_sync_the_file_and_the_folder(tmp_path, monkeypatch):
    from robobore.io.results import atomic_write_text, write_json

    kinds = _record_fsyncs(monkeypatch)
    p = atomic_write_text(tmp_path / "a.txt", "hello")
    assert p.read_text() == "hello" and kinds == ["file", "dir"]
    kinds.clear()
    write_json(tmp_path / "sub" / "b.json", {"x": np.float64(1.5)})
    assert json.loads((tmp_path / "sub" / "b.json").read_text()) == {"x": 1.5}
    assert kinds == ["file", "dir"]
    assert [q.name for q in tmp_path.rglob(".*")] == []  # no temporary left


def test_netcdf_and_figures_are_atomic_and_durable(tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import xarray as xr

    from robobore.io.results import save_figure, write_netcdf

    kinds = _record_fsyncs(monkeypatch)
    write_netcdf(xr.Dataset({"a": ("t", np.arange(3.0))}), tmp_path / "r.nc", seed=1)
    assert kinds == ["file", "dir"]
    with xr.open_dataset(tmp_path / "r.nc") as ds:
        assert ds.attrs["robobore_seed"] == 1
    kinds.clear()
    fig, ax = plt.subplots()
    ax.plot([0, 1])
    save_figure(fig, tmp_path / "p.png", dpi=50)
    save_figure(fig, tmp_path / "p.svg")
    plt.close(fig)
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in (tmp_path / "p.svg").read_bytes()[:400]
    assert kinds == ["file", "dir", "file", "dir"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["p.png", "p.svg", "r.nc"]


def test_atomic_path_failure_leaves_the_old_file(tmp_path):
    from robobore.io.results import atomic_path

    dest = tmp_path / "keep.txt"
    dest.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(dest) as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer died")
    assert dest.read_text() == "old"
    assert sorted(q.name for q in tmp_path.iterdir()) == ["keep.txt"]


def test_atomic_path_with_a_suffix_for_writers_that_choose_by_extension(tmp_path,
                                                                          monkeypatch):
    """meshio (the FE VTU output) picks the format from the name: the temporary name keeps
    the extension, and the file is synced and renamed."""
    import meshio

    from robobore.io.results import atomic_path

    kinds = _record_fsyncs(monkeypatch)
    m = meshio.Mesh(np.zeros((4, 3)), [("quad", np.array([[0, 1, 2, 3]]))])
    with atomic_path(tmp_path / "m.vtu", suffix=".vtu") as tmp:
        assert tmp.name.endswith(".vtu") and tmp.parent == tmp_path
        m.write(tmp)
    assert meshio.read(tmp_path / "m.vtu").points.shape == (4, 3)
    assert kinds == ["file", "dir"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["m.vtu"]


def test_uff_writer_is_atomic_and_durable(tmp_path, monkeypatch):
    from robobore.modal.example import make_example

    kinds = _record_fsyncs(monkeypatch)
    p = make_example(tmp_path / "h.uff")
    assert p.stat().st_size > 1000
    assert kinds[:2] == ["file", "dir"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["h.uff"]


# ---------------------------------------------------------------------------- size guards
def test_available_memory_and_the_refusal_message(monkeypatch):
    from robobore.io.memory import available_memory_bytes, check_memory

    assert available_memory_bytes() > 1 << 26
    check_memory(1e6, "a small array", "some.key")  # passes
    monkeypatch.setenv("ROBOBORE_MEMORY_LIMIT_BYTES", str(1 << 30))
    assert available_memory_bytes() == 1 << 30
    with pytest.raises(ConfigError) as e:
        check_memory(5 * (1 << 30), "the thing", "thing.size", file="c.toml", value=7)
    msg = str(e.value)
    for part in ("c.toml", "thing.size", "5 GiB", "1 GiB available", "reduce thing.size"):
        assert part in msg, msg


def test_fe_meshes_refused_at_parse_time(tmp_path):
    """A 0.01 um mesh of 50 mm (2D) and a 0.01 um 3D mesh are refused when the config is
    read, before any mesh is built; the bundled FE examples pass."""
    import re
    import tomllib

    from robobore.cutting.fe.config.boring3d import load_boring_config, parse_boring_config
    from robobore.cutting.fe.config.orthogonal import load_fe_config, parse_config
    from robobore.cutting.fe.mesh.memory import fe2d_elements, fe3d_elements

    for f in sorted(EX.glob("fe_orthogonal*.toml")):
        assert fe2d_elements(load_fe_config(f)) < 1e5
    assert fe3d_elements(load_boring_config(EX / "fe_boring_paper.toml")) < 1e6
    d = tomllib.loads((EX / "fe_orthogonal.toml").read_text())
    d["cut"].update(uncut_chip_thickness_um=0.05, length_mm=50.0)
    d["mesh"]["element_size_um"] = 0.01
    with pytest.raises(ConfigError) as e:
        parse_config(d, "huge.toml")
    assert "huge.toml" in str(e.value) and "mesh.element_size_um" in str(e.value)
    assert "2D FE mesh" in str(e.value) and "available" in str(e.value)
    text = re.sub(r"element_size_um\s*=\s*[0-9.]+", "element_size_um = 0.01",
                  (EX / "fe_boring_paper.toml").read_text())
    with pytest.raises(ConfigError) as e:
        parse_boring_config(tomllib.loads(text), "huge3d.toml")
    assert "3D FE mesh" in str(e.value) and "huge3d.toml" in str(e.value)


def test_time_domain_run_refused_before_allocating(monkeypatch):
    import robobore.dynamics.timedomain as td
    from robobore.dynamics.api import run_boring

    def never(*a, **k):
        raise AssertionError("the simulation started")

    monkeypatch.setattr(td, "_simulate_kernel", never)
    with pytest.raises(ConfigError) as e:
        run_boring(EX / "boring_paper.toml", revolutions=20000, samples_per_rev=200000)
    msg = str(e.value)
    assert "simulation.revolutions" in msg and "4e+09 steps" in msg
    assert "boring_paper.toml" in msg and "available" in msg


def test_sweep_grid_refused_above_the_documented_count(tmp_path):
    from robobore.study.conditions import MAX_SWEEP_CONDITIONS, load_sweep_config

    p = tmp_path / "big.toml"
    p.write_text('[sweep]\nname = "big"\n[grid]\nspeed_rpm = {start = 100, stop = 3000, '
                 'num = 10000}\nfeed_mm_per_rev = {start = 0.05, stop = 0.3, num = 10000}\n'
                 'depth_of_cut_mm = {start = 0.1, stop = 1, num = 10000}\n')
    with pytest.raises(ConfigError) as e:
        load_sweep_config(p)
    assert str(p) in str(e.value) and "1e+12 conditions" in str(e.value)
    assert str(MAX_SWEEP_CONDITIONS) in str(e.value)


def test_virtual_hammer_test_refused_when_huge(tmp_path):
    r = _cli("identify", "virtual-hammer-test", tmp_path / "h.uff", "--sample-rate-hz", "1e7",
             "--duration-s", "1e4")
    assert r.exit_code == 2 and "--duration-s" in r.output and "available" in r.output
    assert not (tmp_path / "h.uff").exists()


# ------------------------------------------------------------------ partial failure = fail
def _failing_sweep(tmp_path: Path) -> Path:
    p = tmp_path / "fail.toml"
    p.write_text('[sweep]\nname = "f"\nrunner = "demo"\n[grid]\nspeed_rpm = [200, 400]\n'
                 'feed_mm_per_rev = [0.1]\ndepth_of_cut_mm = [0.1]\n[model]\nduration_s = 1.0\n'
                 '[runner_options]\nfail_speeds_rpm = [400]\n')
    return p


def test_sweep_with_a_failed_condition_exits_1_unless_allowed(tmp_path):
    cfg = _failing_sweep(tmp_path)
    store = tmp_path / "store"
    r = _cli("sweep", cfg, "--out", store, "--workers", "0", "--json")
    assert r.exit_code == 1
    res = json.loads(r.stdout)
    assert res["failed"] == 1 and "400 r/min" in res["failures"][0]["error"]
    idx = json.loads((store / "index.json").read_text())  # the store says which and why
    assert idx["counts"] == {"done": 1, "failed": 1, "pending": 0}
    r = _cli("sweep", cfg, "--out", store, "--workers", "0", "--json", "--allow-failures")
    assert r.exit_code == 0 and json.loads(r.stdout)["failed"] == 1


def test_paper_exits_1_when_a_condition_failed(monkeypatch, tmp_path):
    """The CLI's decision only (the study itself is tested in tests/study/test_paper.py)."""
    import robobore.study.paper as paper

    summary = {"report": str(tmp_path / "report.html"), "conditions": 3, "computed": 2,
               "stable": 2, "vibratory": 0, "wall_time_s": 1.0, "coefficients_mode": "x",
               "qualitative_checks": [], "comparison": None,
               "failed": [{"key": "k", "system": "robot", "error": "ConfigError: boom",
                           "condition": {"speed_rpm": 300.0, "feed_mm_per_rev": 0.1,
                                         "depth_of_cut_mm": 0.1, "pressure_MPa": 0.0}}]}
    from types import SimpleNamespace

    # run_paper's PaperSummary, as far as the CLI reads it (its to_dict())
    monkeypatch.setattr(paper, "run_paper", lambda *a, **k: SimpleNamespace(
        to_dict=lambda: summary))
    r = _cli("paper", "--fast", "--out", tmp_path / "p")
    assert r.exit_code == 1
    assert "1 of 3 conditions failed" in r.output and "boom" in r.output
    r = _cli("paper", "--fast", "--out", tmp_path / "p", "--allow-failures")
    assert r.exit_code == 0
    summary["failed"] = []
    assert _cli("paper", "--fast", "--out", tmp_path / "p").exit_code == 0


def test_per_condition_errors_name_the_config_file(tmp_path):
    from robobore.study.sweep import plan_from_file, run_sweep

    p = tmp_path / "boring.toml"
    p.write_text('[sweep]\nname = "b"\nrunner = "boring"\n[grid]\nspeed_rpm = [300]\n'
                 'feed_mm_per_rev = [0.1]\ndepth_of_cut_mm = [0.05]\n[model]\n'
                 'system = "robot"\n[model.dynamics]\n[model.dynamics.insert]\n'
                 'nose_radius_mm = -1\n')
    out = run_sweep(plan_from_file(p), tmp_path / "store", workers=0)
    assert out.failed == 1
    err = out.failures[0]["error"]
    assert str(p) in err and "<config>" not in err, err


# ------------------------------------------------------------ no traceback at the top level
@pytest.fixture
def bad_inputs(tmp_path) -> dict[str, list[str]]:
    u16 = tmp_path / "u16.toml"
    u16.write_bytes((EX / "lobes_single_point.toml").read_text().encode("utf-16"))
    binary = tmp_path / "bin.toml"
    binary.write_bytes(bytes(range(256)) * 3)
    lst = tmp_path / "list.json"
    lst.write_text("[1, 2]")
    stiff = tmp_path / "stiff.json"
    stiff.write_text('{"directional_stiffness_N_per_m": [1e6, 1e6, 1e6]}')
    u16j = tmp_path / "u16.json"
    u16j.write_bytes('{"a": 1}'.encode("utf-16"))
    npz = tmp_path / "pickled.npz"
    np.savez(npz, frequency_Hz=np.arange(4.0), frf=np.array([{}] * 4, dtype=object),
             frf_type=np.array("accelerance"))
    coef = tmp_path / "coef.json"
    coef.write_text('{"coefficients": {')
    boring = tmp_path / "boring.toml"
    boring.write_text((EX / "boring_paper.toml").read_text()
                      + f'\n[coefficients]\nfile = "{coef}"\n')
    afile = tmp_path / "afile"
    afile.write_text("x")
    return {
        "utf16 toml": ["lobes", str(u16)],
        "binary toml": ["sweep", str(binary)],
        "missing config": ["lobes", str(tmp_path / "nope.toml")],
        "folder as config": ["lobes", str(tmp_path)],
        "list json": ["model", "equivalent", "--stiffness-file", str(lst), "--frequencies-Hz",
                      "7,17,25", "--damping-ratios", "0.03,0.03,0.02"],
        "list for table": ["model", "equivalent", "--stiffness-file", str(stiff),
                           "--frequencies-Hz", "7,17,25", "--damping-ratios", "0.03,0.03,0.02"],
        "utf16 json": ["robot", "stiffness", "--joints-deg", "0,-20,20,0,30,0",
                       "--joint-stiffness-file", str(u16j)],
        "pickled npz": ["identify", "modes", str(npz)],
        "corrupt coefficients": ["simulate", "boring", str(boring)],
        "plot on a file": ["lobes", str(EX / "lobes_single_point.toml"), "--plot", str(afile)],
    }


def test_no_traceback_for_user_mistakes(bad_inputs):
    for name, argv in bad_inputs.items():
        r = _cli(*argv)
        assert r.exit_code == 2, (name, r.output, r.exception)
        assert "Traceback" not in r.output, name
        assert r.output.count("error:") == 1, (name, r.output)
        assert not isinstance(r.exception, Exception) or isinstance(r.exception, SystemExit), (
            name, repr(r.exception))


def test_top_level_catches_errors_and_debug_shows_the_traceback(bad_inputs):
    argv = bad_inputs["utf16 toml"]
    r = _sub(*argv)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "UTF-16" in r.stderr
    r = _sub("--debug", *argv)
    assert r.returncode == 2 and "Traceback (most recent call last)" in r.stderr
    assert "UTF-16" in r.stderr


def test_main_catches_an_os_error_escaping_a_command(monkeypatch, capsys, tmp_path):
    """A RoboboreError or OSError that leaves a command (one not wrapped in handle_errors)
    is still one line and exit code 2 from ``main()``."""
    import typer

    import robobore.cli as cli

    bad = typer.Typer()

    @bad.command()
    def boom() -> None:
        open(tmp_path / "missing" / "x")  # noqa: SIM115 - the OSError is the point

    monkeypatch.setattr(cli, "app", bad)
    monkeypatch.setattr(sys, "argv", ["robobore"])
    with pytest.raises(SystemExit) as e:
        cli.main()
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "No such file or directory" in err and "missing" in err and "Traceback" not in err


def test_handle_errors_turns_os_errors_into_one_line(tmp_path, capsys):
    import typer

    from robobore.clitools import handle_errors

    @handle_errors
    def f():
        raise PermissionError(13, "Permission denied", str(tmp_path / "x"))

    with pytest.raises(typer.Exit) as e:
        f()
    assert e.value.exit_code == 2
    err = capsys.readouterr().err
    assert "Permission denied" in err and str(tmp_path / "x") in err


def test_pickled_npz_refused_clearly(tmp_path):
    from robobore.modal.io import load_npz

    p = tmp_path / "p.npz"
    np.savez(p, frequency_Hz=np.arange(3.0), frf=np.array([{}] * 3, dtype=object),
             frf_type=np.array("accelerance"))
    with pytest.raises(DataError) as e:
        load_npz(p)
    assert "pickled" in str(e.value) and str(p) in str(e.value)


def test_sweep_scheduler_that_is_not_dask_is_one_clear_line(tmp_path):
    """--scheduler pointing at a server that answers with something else than Dask's
    protocol: one line naming the address, no traceback (nor one from the half-built
    client's clean-up at exit)."""
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    stop = threading.Event()

    def serve():
        srv.settimeout(0.2)
        conns = []
        while not stop.is_set():
            try:
                c, _ = srv.accept()
            except OSError:
                continue
            c.sendall(b"\xff\x31\x7a\x00HTTP/1.1 400 Bad Request\r\n\r\n" * 4)
            conns.append(c)
        for c in conns:
            c.close()

    th = threading.Thread(target=serve, daemon=True)
    th.start()
    addr = f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    try:
        r = _sub("sweep", EX / "sweep_demo.toml", "--out", tmp_path / "s", "--scheduler", addr,
                 timeout=120)
    finally:
        stop.set()
        th.join(5)
        srv.close()
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr
    assert addr in r.stderr and "scheduler" in r.stderr
