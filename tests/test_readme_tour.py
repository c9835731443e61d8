"""Every row of the README's tour runs exactly as written (issue 31).

The tour table is parsed from README.md; each backquoted ``robobore ...`` command of a row is
run in a temporary folder (``examples/`` linked there) through ``python -m robobore``. Rows
whose stage cell is marked ``(long)`` or ``(GPU)`` are skipped; every other row must exit 0,
and a command with ``--json`` must print valid JSON. Names that stand for the user's own
files (see the README under the table) are made with robobore's own commands:

* ``FILE`` (a campaign CSV): ``robobore robot campaign``; ``NAME``: the bundled robot;
* ``s.json`` / ``m.json``: ``robobore identify stiffness|modes --example --json``;
* ``test.uff``: ``robobore identify virtual-hammer-test``;
* ``measured.csv``: the bundled SYNTHETIC measurements of the paper example;
* ``RESULTS_DIR``: the output folder of the main-job row (``results``; run if missing);
* ``CONFIG.toml``: the demo sweep under another name; ``HOST:8786``: a Dask scheduler
  started here; ``DIR``: a folder name.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
SKIP_MARK = re.compile(r"\((long|GPU)\)")
pytestmark = pytest.mark.slow


def tour_rows() -> list[tuple[str, list[str]]]:
    """(stage, commands) of every row of the README's tour table, in order."""
    text = README.read_text()
    m = re.search(r"^## Tour\s*$(.*?)(?=^## )", text, flags=re.S | re.M)
    assert m, "README.md has no '## Tour' section"
    rows = []
    for line in m.group(1).splitlines():
        if not line.startswith("|") or set(line) <= set("|- "):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        if cells[0] == "stage":
            continue
        cmds = [c for c in re.findall(r"`([^`]+)`", cells[1]) if c.startswith("robobore ")]
        rows.append((cells[0], cmds))
    return rows


ROWS = tour_rows()


def test_the_tour_table_is_found_and_rows_are_runnable_or_marked():
    assert len(ROWS) >= 15
    for stage, cmds in ROWS:
        assert cmds or SKIP_MARK.search(stage), f"row '{stage}' has no robobore command"


def _run(args: list[str], cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess:
    env = dict(os.environ, NUMBA_NUM_THREADS=os.environ.get("NUMBA_NUM_THREADS", "1"),
               PYTHONPATH=os.pathsep.join([str(ROOT / "src"),
                                           os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "robobore", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


class Tour:
    """The temporary folder of the tour and its placeholder files (made on demand)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        (root / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
        self.cluster = None

    def ok(self, args: list[str]) -> subprocess.CompletedProcess:
        r = _run(args, self.root)
        assert r.returncode == 0, f"robobore {' '.join(args)}\n{r.stdout}\n{r.stderr}"
        return r

    def file(self, name: str) -> str:
        p = self.root / name
        if p.exists():
            return name
        if name == "s.json":
            p.write_text(self.ok(["identify", "stiffness", "--example", "--json"]).stdout)
        elif name == "m.json":
            p.write_text(self.ok(["identify", "modes", "--example", "--json"]).stdout)
        elif name == "campaign.csv":
            self.ok(["robot", "campaign", name])
        elif name == "test.uff":
            self.ok(["identify", "virtual-hammer-test", name])
        elif name == "measured.csv":
            shutil.copy(ROOT / "src/robobore/data/paper_example/measured_synthetic.csv", p)
        elif name == "results":
            self.ok(["paper", "--out", name, "--fast"])
        elif name == "CONFIG.toml":
            text = (ROOT / "examples" / "sweep_demo.toml").read_text()
            p.write_text(text.replace('name = "demo"', 'name = "tour"', 1))
        return name

    def scheduler(self) -> str:
        if self.cluster is None:
            from dask.distributed import LocalCluster

            self.cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                        protocol="tcp://", host="127.0.0.1",
                                        dashboard_address=None)
        return self.cluster.scheduler_address

    def args(self, command: str) -> list[str]:
        """The command as written, with the placeholders replaced by real files."""
        names = {"FILE": "campaign.csv", "RESULTS_DIR": "results", "CONFIG.toml": "CONFIG.toml"}
        out = []
        for tok in shlex.split(command)[1:]:
            if tok in names:
                tok = self.file(names[tok])
            elif tok == "NAME":
                tok = "irb6600-175-2.55"
            elif tok == "DIR":
                tok = "plots"
            elif tok in ("s.json", "m.json", "test.uff", "measured.csv"):
                self.file(tok)
            elif "HOST:8786" in tok:
                tok = tok.replace("tcp://HOST:8786", self.scheduler())
            out.append(tok)
        return out


@pytest.fixture(scope="module")
def tour(tmp_path_factory):
    t = Tour(tmp_path_factory.mktemp("tour"))
    yield t
    if t.cluster is not None:
        t.cluster.close()


@pytest.mark.parametrize("stage, cmds", ROWS, ids=[f"{i:02d}-{s}" for i, (s, _) in
                                                   enumerate(ROWS)])
def test_tour_row_runs_as_written(tour, stage, cmds):
    if SKIP_MARK.search(stage):
        pytest.skip(f"marked {SKIP_MARK.search(stage).group(0)} in the README")
    for command in cmds:
        args = tour.args(command)
        r = tour.ok(args)
        if "--json" in args:
            json.loads(r.stdout)
