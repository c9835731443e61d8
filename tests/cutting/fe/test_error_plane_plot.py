"""benchmarks/plot_fe_error_plane.py: it reads the rows of the chosen point only, and merges
runs whose errors agree within the tolerance (constructed row files)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

_PATH = Path(__file__).parents[3] / "benchmarks" / "plot_fe_error_plane.py"
_spec = importlib.util.spec_from_file_location("plot_fe_error_plane", _PATH)
pep = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pep)  # type: ignore[union-attr]


def _row(h, vc, fc, ff):
    return {"h_um": h, "vc_m_per_min": vc, "Fc_err_pct": fc, "Ff_err_pct": ff}


def test_rows_at_the_point_and_their_clusters(tmp_path):
    (tmp_path / "a.json").write_text(json.dumps([_row(60.0, 5.0, 7.5, -45.5),
                                                 _row(80.0, 5.0, 3.8, -54.0)]))
    (tmp_path / "b.json").write_text(json.dumps([_row(60.0, 5.0, 7.9, -45.1)]))
    (tmp_path / "c.json").write_text(json.dumps({"rows": [_row(60.0, 5.0, 28.2, -6.2)]}))
    (tmp_path / "d.json").write_text(json.dumps({"rake_deg": 15.0}))  # not a row file
    rows = pep.rows_at(tmp_path, 60.0, 5.0)
    assert [r[0] for r in rows] == ["a", "b", "c"]
    cl = pep.clusters(rows, tol=1.0)
    assert [c[0] for c in cl] == [["a", "b"], ["c"]]
    assert abs(cl[0][1] - 7.7) < 1e-12 and abs(cl[0][2] + 45.3) < 1e-12
    assert [c[0] for c in pep.clusters(rows, tol=0.1)] == [["a"], ["b"], ["c"]]
