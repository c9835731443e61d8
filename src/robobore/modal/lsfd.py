"""Least-squares frequency-domain (LSFD) estimation of mode shapes and residues.

With the poles ``lambda_m`` and participation vectors ``L_m`` (``n_inputs``) fixed, the
poly-reference pole-residue model (Peeters et al. 2004, eq. 15; Heylen et al. ch. A.3) is
linear in the mode shapes ``psi_m`` (``n_outputs``, complex) and the residual terms::

    H_rec[o, j](w) = sum_m ( psi_om L_jm / (jw - lambda_m)
                             + conj(psi_om L_jm) / (jw - conj(lambda_m)) )
                     + LR_oj / (jw)^2          (lower residual: modes below the band, mass line)
                     + UR_oj                   (upper residual: modes above the band, stiffness)

For mobility/accelerance every term is multiplied by ``(jw)^1`` / ``(jw)^2``, so the fitted
residues ``R_ojm = psi_om L_jm`` are always *receptance* residues (m/N/s), whatever FRF type
was measured. The design matrix is the same for every output, so one real least-squares
solve with ``n_outputs`` right-hand sides gives all shapes; ``LR`` and ``UR`` are real.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robobore.errors import IdentificationError
from robobore.modal.frf_data import FRF_POWER, FRFData


@dataclass(frozen=True)
class LSFDResult:
    """Mode shapes, residues, residuals and fit quality.

    mode_shapes ``(n_outputs, n_modes)`` complex (scaled so that ``residues = psi L^T``);
    residues ``(n_outputs, n_inputs, n_modes)`` complex receptance residues (m/N/s);
    lower/upper residuals ``(n_outputs, n_inputs)`` real; synthesised FRF ``(n_o, n_i, n_f)``
    (same type as the data) on ``frequency_Hz``; fit_percent ``(n_o, n_i)``:
    ``100 (1 - ||H - H_syn||^2 / ||H||^2)`` over the band.
    """

    mode_shapes: np.ndarray
    residues: np.ndarray
    lower_residual: np.ndarray
    upper_residual: np.ndarray
    frequency_Hz: np.ndarray
    synthesised: np.ndarray
    fit_percent: np.ndarray


def _basis(jw: np.ndarray, poles: np.ndarray, L: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Complex basis ``(n_i, n_f, 2 n_m)``: columns for Re(psi) and Im(psi) of every mode."""
    b1 = L.T[:, None, :] * (c[:, None] / (jw[:, None] - poles[None, :]))[None]  # (ni, nf, nm)
    b2 = np.conj(L).T[:, None, :] * (c[:, None] / (jw[:, None] - np.conj(poles)[None, :]))[None]
    return np.concatenate([b1 + b2, 1j * (b1 - b2)], axis=2)


def lsfd(data: FRFData, poles: np.ndarray, participation: np.ndarray,
         residuals: bool = True) -> LSFDResult:
    """Fit mode shapes with fixed poles ``(n_m,)`` (rad/s) and participation ``(n_m, n_i)``.

    ``data`` should already be limited to the analysis band (lines at 0 Hz are skipped).
    """
    f = data.frequency_Hz
    keep = f > 0
    f = f[keep]
    H = data.frf[:, :, keep]
    no, ni, nf = H.shape
    poles = np.asarray(poles, complex).ravel()
    L = np.asarray(participation, complex).reshape(poles.size, ni)
    nm = poles.size
    jw = 2j * np.pi * f
    c = jw ** FRF_POWER[data.frf_type]
    B = _basis(jw, poles, L, c)  # (ni, nf, 2nm)
    ncol = 2 * nm + (2 * ni if residuals else 0)
    A = np.zeros((ni, nf, ncol), complex)
    A[:, :, : 2 * nm] = B
    if residuals:
        for j in range(ni):
            A[j, :, 2 * nm + j] = c / jw**2
            A[j, :, 2 * nm + ni + j] = c
    A = A.reshape(ni * nf, ncol)
    Y = H.transpose(1, 2, 0).reshape(ni * nf, no)  # (ni*nf, no)
    Ar = np.concatenate([A.real, A.imag], axis=0)
    Yr = np.concatenate([Y.real, Y.imag], axis=0)
    # column scaling for conditioning
    sc = np.linalg.norm(Ar, axis=0)
    sc[sc == 0] = 1.0
    sol, *_ = np.linalg.lstsq(Ar / sc, Yr, rcond=None)
    sol = sol / sc[:, None]  # (ncol, no)
    if not np.all(np.isfinite(sol)):
        raise IdentificationError("LSFD produced non-finite mode shapes")
    psi = (sol[:nm] + 1j * sol[nm: 2 * nm]).T  # (no, nm)
    lr = np.zeros((no, ni))
    ur = np.zeros((no, ni))
    if residuals:
        lr = sol[2 * nm: 2 * nm + ni].T
        ur = sol[2 * nm + ni:].T
    syn = (A @ sol).reshape(ni, nf, no).transpose(2, 0, 1)
    err = np.sum(np.abs(H - syn) ** 2, axis=2)
    ref = np.sum(np.abs(H) ** 2, axis=2)
    fit = 100.0 * (1.0 - err / np.where(ref > 0, ref, 1.0))
    residues = psi[:, None, :] * L.T[None, :, :]
    return LSFDResult(psi, residues, lr, ur, f, syn, fit)


def modal_peak_compliance(residues: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """``|H_m(j w_d,m)|`` (m/N): the receptance of each mode's own term
    ``R/(jw - lambda) + conj(R)/(jw - conj(lambda))`` at its damped frequency, per FRF;
    residues ``(n_o, n_i, n_m)`` receptance residues, poles ``(n_m,)`` rad/s -> ``(n_o, n_i,
    n_m)``. For a lightly damped real mode this is the modal peak ``phi_o phi_j / (2 zeta
    w_n^2)``."""
    lam = np.asarray(poles, complex).ravel()
    jw = 1j * np.abs(lam.imag)
    term = residues / (jw - lam) + np.conj(residues) / (jw - np.conj(lam))
    return np.abs(term)


def mpc(shape: np.ndarray) -> float:
    """Modal phase collinearity (Pappa, Elliott & Schenk 1993), 1 for a real (normal) mode.

    ``MPC = ((l1 - l2)/(l1 + l2))^2`` with ``l1, l2`` the eigenvalues of the 2x2 covariance
    of the real and imaginary parts of the mode shape.
    """
    v = np.asarray(shape, complex).ravel()
    x, y = v.real, v.imag
    sxx, syy, sxy = x @ x, y @ y, x @ y
    tr = sxx + syy
    if tr == 0:
        return 0.0
    disc = np.sqrt((sxx - syy) ** 2 + 4 * sxy**2)
    l1, l2 = (tr + disc) / 2, (tr - disc) / 2
    return float(((l1 - l2) / (l1 + l2)) ** 2)


def normalise_shape(shape: np.ndarray) -> np.ndarray:
    """Rotate a complex shape to be as real as possible and scale its largest entry to 1."""
    v = np.asarray(shape, complex).ravel()
    if not np.any(v):
        return v
    # angle maximising sum(Re(v e^{-j t})^2): half the angle of sum(v^2)
    t = 0.5 * np.angle(np.sum(v**2))
    v = v * np.exp(-1j * t)
    k = int(np.argmax(np.abs(v)))
    return v / v[k].real if v[k].real != 0 else v / np.abs(v[k])


__all__ = ["LSFDResult", "lsfd", "mpc", "normalise_shape", "modal_peak_compliance"]
