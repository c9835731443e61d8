"""Complex mode indicator function (Shih, Tsuei, Allemang & Brown 1988, MSSP 2(4)).

``CMIF_k(w)`` are the singular values of the FRF matrix ``H(w)`` (``n_outputs x n_inputs``)
at each frequency line, ``k = 1..min(n_o, n_i)``. Peaks of the first curve mark modes; a
peak in the second curve at the same frequency marks a repeated or close mode (as many
curves peak as modes are there). Optional tracking re-orders the singular values between
lines by the MAC of the left singular vectors, so that curves follow modes through
crossings instead of being sorted by size.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.modal.frf_data import FRFData


@dataclass(frozen=True)
class CMIF:
    """Singular values ``(n_sv, n_f)`` on ``frequency_Hz`` and the peaks of curve 1."""

    frequency_Hz: np.ndarray
    values: np.ndarray
    peaks_Hz: np.ndarray
    peak_curves: np.ndarray  # (n_peaks,) how many curves peak there (multiplicity hint)

    def at(self, f_Hz: float) -> np.ndarray:
        """Singular values at the line nearest ``f_Hz``."""
        return self.values[:, int(np.argmin(np.abs(self.frequency_Hz - f_Hz)))]

    def to_dict(self) -> dict[str, Any]:
        return {"peaks_Hz": self.peaks_Hz.tolist(), "peak_curves": self.peak_curves.tolist()}


def cmif(data: FRFData, track: bool = False, prominence: float = 0.05) -> CMIF:
    """CMIF of ``data.frf`` ``(n_o, n_i, n_f)``.

    Parameters
    ----------
    track: follow curves by singular-vector MAC instead of sorting by size.
    prominence: peak prominence, as a fraction of the decades spanned by curve 1 (log scale).
    """
    from scipy.signal import find_peaks

    H = data.frf.transpose(2, 0, 1)  # (nf, no, ni)
    if track:
        U, s, _ = np.linalg.svd(H, full_matrices=False)
        s = s.copy()
        for k in range(1, s.shape[0]):
            m = np.abs(np.einsum("ia,ib->ab", U[k - 1].conj(), U[k])) ** 2
            perm = np.argmax(m, axis=1)
            if np.unique(perm).size == perm.size:
                U[k] = U[k][:, perm]
                s[k] = s[k][perm]
    else:
        s = np.linalg.svd(H, compute_uv=False)
    values = s.T  # (n_sv, nf)
    ls = np.log10(np.maximum(values, np.finfo(float).tiny))
    span = float(ls[0].max() - ls[0].min()) or 1.0
    pk, _ = find_peaks(ls[0], prominence=prominence * span)
    mult = np.ones(pk.size, int)
    for c in range(1, values.shape[0]):
        pc, _ = find_peaks(ls[c], prominence=prominence * span)
        for n, p in enumerate(pk):
            if pc.size and np.min(np.abs(pc - p)) <= 2:
                mult[n] += 1
    return CMIF(data.frequency_Hz, values, data.frequency_Hz[pk], mult)


__all__ = ["CMIF", "cmif"]
