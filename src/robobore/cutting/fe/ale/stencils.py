"""Host-side stencil of the ALE pass (:mod:`robobore.cutting.fe.ale.rezone`): the element
neighbours across each edge that the remap needs (:func:`edge_neighbours`).
"""

from __future__ import annotations

import numpy as np


def edge_neighbours(conn: np.ndarray) -> np.ndarray:
    """(n_elem, 4): element across edge k (nodes k -> k+1), -1 on the boundary."""
    ne = conn.shape[0]
    out = -np.ones((ne, 4), dtype=np.int64)
    seen: dict[tuple[int, int], tuple[int, int]] = {}
    for e in range(ne):
        for k in range(4):
            a, b = int(conn[e, k]), int(conn[e, (k + 1) % 4])
            key = (a, b) if a < b else (b, a)
            if key in seen:
                e2, k2 = seen.pop(key)
                out[e, k] = e2
                out[e2, k2] = e
            else:
                seen[key] = (e, k)
    return out
