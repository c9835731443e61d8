"""SYNTHETIC measurements: a virtual experiment made from simulated summaries.

The paper's measured data are not available, so examples and tests that need a "measured"
CSV make one here, from documented ground truth: each measured amplitude is the simulated
one times ``(1 + e)`` with ``e`` drawn from a normal distribution of standard deviation
``rel_noise`` (truncated to ``|e| <= 3 rel_noise`` and to keep values >= 0), and the
measured ``stable`` flag is the simulated one, flipped with probability ``flip_stable``.
The file starts with a comment line saying SYNTHETIC and giving the parameters.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from robobore.io.results import atomic_write_text
from robobore.study.conditions import CONDITION_FIELDS
from robobore.study.summary import AMPLITUDE_QUANTITIES


def synthetic_measured_csv(
    records: Iterable[tuple[dict[str, Any], dict[str, Any]]],
    path: str | Path,
    *,
    rel_noise: float = 0.08,
    flip_stable: float = 0.0,
    seed: int | np.random.Generator = 0,
    quantities: tuple[str, ...] | None = None,
) -> Path:
    """Write a SYNTHETIC measured CSV (see module doc) from ``(condition, summary)`` pairs.

    ``quantities``: the columns to write (default: every summary quantity present in the
    first record). Returns the path (written atomically).
    """
    if rel_noise < 0 or not 0 <= flip_stable <= 1:
        raise ValueError("rel_noise must be >= 0 and flip_stable in [0, 1]")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    recs = list(records)
    if quantities is None:
        first = recs[0][1] if recs else {}
        quantities = tuple(q for q in (*AMPLITUDE_QUANTITIES, "stable") if q in first)
    seed_text = str(seed) if isinstance(seed, int) else "a given generator"
    buf = io.StringIO()
    buf.write(f"# SYNTHETIC measurements made by robobore.study.synthetic from simulated "
              f"results: amplitude x (1 + e), e ~ N(0, {rel_noise:g}) truncated at 3 sigma; "
              f"stable flag flipped with probability {flip_stable:g}; seed {seed_text}\n")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([*CONDITION_FIELDS, *quantities])
    for cond, summ in recs:
        row = [repr(float(cond[f])) for f in CONDITION_FIELDS]
        for q in quantities:
            v = summ.get(q)
            if v is None:
                row.append("")
            elif q == "stable":
                flip = rng.random() < flip_stable
                row.append("true" if bool(v) != flip else "false")
            else:
                e = float(np.clip(rng.normal(0.0, rel_noise), -3 * rel_noise, 3 * rel_noise))
                row.append(repr(max(0.0, float(v) * (1.0 + e))))
        w.writerow(row)
    return atomic_write_text(path, buf.getvalue())


__all__ = ["synthetic_measured_csv"]
