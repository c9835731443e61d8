"""Chatter detection on measured vibration, sound or force records.

The question: did the cut chatter, from when, and at which frequency? The method is the
spectral one used for machine tools (Altintas & Chan 1992, sound; Schmitz et al. 2002/2003,
once-per-revolution sampling: a stable cut's signal is periodic with the spindle, chatter is
not; Kuljanic et al. 2009 and Lamraoui et al. 2014, energy away from the rotation
harmonics; the "chatter energy ratio" of CutPro-type detectors), made independent of the
signal's level and units:

1. **Spectra.** Each channel is cut into windows (Hann, 50 % overlap) and each window's
   power spectrum is divided by its own energy above ``f_low`` (so a gain, a unit or a
   different sensor changes nothing).
2. **What a stable cut contains.** The forced vibration of a cut that does not chatter is
   periodic with the spindle: lines at the rotation harmonics ``k n / 60`` (the insert-passing
   harmonics ``k N n / 60`` are among them). Those bands are excluded, after the spindle
   frequency is found on the record's averaged spectrum (long windows): given
   (``speed_rpm``), it is refined within +-:data:`SPEED_TOLERANCE` on the lines among its
   first ten harmonics (none there: no harmonic is in the record, none is excluded); not
   given, it is the
   harmonic comb that explains the most spectral lines beyond chance (each line weighted by
   its prominence; a comb of spacing ``f0`` matches a line by chance with probability
   ``2 tol / f0``, which is subtracted; of the combs within 80 % of the best score the
   highest fundamental wins, since a sub-multiple matches the same lines), searched up to
   :data:`MAX_SPINDLE_HZ`, with lines at two or more of its first ten harmonics and at three
   or more harmonics in all (a cluster of lines round one frequency counts once), and, for a
   comb below the record's strongest line, at least two lines that are not harmonics of that
   line (a saturated chatter vibration has harmonics of its own; a sub-multiple of it does not
   make a spindle). In each window only the harmonics it shows as lines are excluded, as
   wide as their skirts (:func:`line_extent`), the spindle frequency re-refined in the window
   (:func:`window_harmonic_bands`). A speed that wanders moves harmonic ``k`` by ``k``
   times its relative change: the record's speed spread (:func:`speed_spread`, the scatter of
   the windows' own spindle frequencies) widens each harmonic's band to its wandering range
   where that band stays attributable (below). Fixed lines that do not move with the speed
   are excluded too: mains (50 and 60 Hz families, each detected by its fundamental line, then every
   multiple up to the 20th present as a line weaker than the fundamental: mains distortion
   decays with the order) and any lines given.

   **High harmonic orders** (low spindle speeds: at 300 r/min a chatter line at 2 kHz lies at
   order 400). A line is attributed to the spindle only where that is better than chance
   (:func:`attributable`): its harmonic band ``2 tol`` covers at most :data:`CHANCE_MAX` of
   the harmonic spacing (the chance ``2 tol / f0`` that :func:`comb_score` subtracts; a band
   that covers most of the spacing holds the harmonic and nearly any line beside it). The
   harmonics are then placed on the record-length spectrum (resolution ``1 / T``,
   :func:`fine_harmonic_bands`): the spindle frequency refined there on the first
   harmonics, then order by order, each harmonic ``k`` placed to ``k s_f0`` (the refined
   frequency's standard error), a line the harmonic when within three standard errors. The
   harmonics so placed at orders the windows cannot attribute are excluded in every window
   (as wide as their skirts on that spectrum, two window bins at least); a line that a window
   attributes to a harmonic is the spindle's only when the strongest line of the
   record-length spectrum in its band is a harmonic there (a chatter line beside a harmonic
   that the window does not resolve stays a candidate). Schmitz's once-per-revolution
   criterion is the same test in time: a forced line keeps its phase to the rotation from
   revolution to revolution, a chatter line precesses, and over the record that is a
   frequency off ``k f0`` by more than about ``1 / T``.
3. **Windows.** :data:`DEFAULT_WINDOW_S` or :data:`WINDOW_REVS` revolutions, the longer, and
   at most a third of the record (five windows at 50 % overlap), but where the record shows
   spindle harmonics no fewer than :data:`MIN_WINDOW_REVS` revolutions (harmonics 8 bins
   apart: a band of +-2 bins covers half the spacing); a record too short for
   :data:`PERSIST_WINDOWS` such windows gets :data:`PERSIST_WINDOWS` shorter ones, the
   harmonics then placed on the record-length spectrum only (:func:`window_length`).
4. **Chatter in a window.** The largest remaining peak (inside the bands of the structural
   modes when modes are given) and its energy above the local spectral floor (the median of
   the remaining spectrum within +-5 % of its frequency) as a share of the window's energy.
   The window chatters when that share is at least :data:`SHARE_LIMIT` and the peak stands
   :data:`PROMINENCE_DB` above the floor: a narrow line, not a broadband resonance hump.
5. **Persistence.** The record chatters when :data:`PERSIST_WINDOWS` consecutive windows
   chatter at the same frequency (within 2 %): self-excited vibration persists once it has
   grown; one window of an impact or a transient does not make chatter. Onset: the start of
   the first such run.
6. **Chatter frequency.** The line of the last chattering window (the developed chatter: a
   growing vibration can move from one lobe's frequency to another's), on the averaged
   spectrum of the chattering windows at that line (within 2 %), refined by quadratic
   interpolation of the log power over the three bins round the maximum (the error is a few
   hundredths of a bin with the Hann window).

Limits: a chatter line that falls on a spindle harmonic or a mains multiple (within the
band widths) cannot be told from it and is missed; a spindle speed that wanders by more than
about 0.5 % (standard deviation) leaves the windows' search, and its harmonics above order 10
or so smear past their bands; a lightly damped mode
driven by broadband noise looks like a line. A harmonic of order ``k`` can be placed only
with the spindle frequency known to better than about ``1 / (2 k)`` relative: from the
record's own first harmonics; a given speed (+-1.5 %) is not that precise, and a forced
line at a high order where the record shows no first harmonics is not excluded (it can be
called chatter when it holds a fifth of the energy 20 dB above the floor).

References: Y. Altintas, P. K. Chan, In-process detection and suppression of machine tool
chatter, Precision Engineering 14 (1992); T. L. Schmitz, K. Medicus, B. Dutterer, Exploring
once-per-revolution audio signal variance as a chatter indicator, Machining Science and
Technology 6 (2002); T. L. Schmitz, Chatter recognition by a statistical evaluation of the
synchronously sampled audio signal, J. Sound Vib. 262 (2003); E. Kuljanic, G. Totis, M.
Sortino, Development of an intelligent multisensor chatter detection system in milling,
MSSP 23 (2009); M. Lamraoui et al., Indicators for monitoring chatter in milling based on
instantaneous angular speeds, MSSP 44 (2014).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robobore.errors import DataError, InputError
from robobore.measure.records import Record

#: Share of a window's energy that the chatter peak (above the local floor) must hold.
SHARE_LIMIT = 0.2
#: How far the chatter peak must stand above the local spectral floor [dB]. A resonance
#: driven by broadband cutting noise peaks a few dB above its own hump (the periodogram of a
#: noise band fluctuates exponentially from bin to bin); on the SYNTHETIC records of
#: robobore.measure.synthetic such humps reach 18.4 dB, chatter lines 34 dB and more.
PROMINENCE_DB = 20.0
#: Consecutive chattering windows (at one frequency) that make the record chatter.
PERSIST_WINDOWS = 3
#: Relative tolerance of a given spindle speed (the speed found is refined within it).
SPEED_TOLERANCE = 0.015
#: Half-width of a harmonic or fixed-line band: the larger of this many bins and
#: :data:`LINE_REL_WIDTH` times the line frequency.
LINE_BINS = 2.0
LINE_REL_WIDTH = 0.001
#: How far the spindle frequency may wander from the record's within one window.
WINDOW_SPEED_TOLERANCE = 0.005
#: A window's own spindle frequency is taken when it matches this many more lines.
WINDOW_REALIGN_LINES = 3
#: Widest half-width of an excluded line, as a fraction of its frequency.
MAX_LINE_REL_WIDTH = 0.005
#: A spectral line stands this far above the local floor [dB].
LINE_DB = 10.0
#: A spindle comb matches this many lines among its first LOW_HARMONICS harmonics.
LOW_HARMONICS = 10
LOW_HARMONIC_LINES = 2
#: Highest spindle frequency looked for when the speed is not given [Hz] (30 000 r/min).
MAX_SPINDLE_HZ = 500.0
#: A comb within this fraction of the best comb's score and of a higher fundamental wins.
COMB_SHARE = 0.8
#: Highest multiple of a mains fundamental taken for a fixed line (pickup harmonics fade with
#: the order; a line at a higher multiple is more likely the process's own).
MAINS_MAX_ORDER = 20
#: Mains families looked for as fixed lines [Hz].
MAINS_HZ = (50.0, 60.0)
#: Shortest default window [s] (2 Hz resolution: a resonance hump of 1 % damping at 500 Hz
#: spans 5 bins, a chatter line about 1.5); longer when :data:`WINDOW_REVS` need more.
DEFAULT_WINDOW_S = 0.5
#: Revolutions in a default window (the harmonics 16 bins apart).
WINDOW_REVS = 16.0
#: Fewest revolutions in a window where the record shows spindle harmonics: the harmonics are
#: then 8 bins apart and a band of +-:data:`LINE_BINS` bins covers half their spacing (the
#: most at which attributing a line to the spindle is better than chance, :data:`CHANCE_MAX`).
MIN_WINDOW_REVS = 4.0 * LINE_BINS
#: A line is attributed to the spindle only where its harmonic band ``2 tol`` covers at most
#: this share of the harmonic spacing ``f0``: a band that covers more holds the harmonic and
#: nearly any line beside it, and the frequency cannot tell them apart.
CHANCE_MAX = 0.5
#: Line-position error of a clean line on the Hann spectrum after the parabolic refinement, in
#: bins (the least error assumed for a line on the record-length spectrum).
FINE_LINE_BINS = 0.1
#: A line on the record-length spectrum is the harmonic when within this many standard
#: errors of ``k f0``.
FINE_SIGMAS = 3.0
#: Fewest windows with their own spindle frequency for the record's speed spread.
SPREAD_MIN_WINDOWS = 3
#: Half-width of a wandering harmonic, in standard deviations of the spindle frequency.
SPREAD_SIGMAS = 3.0


@dataclass(frozen=True)
class DetectSettings:
    """Options of :func:`detect_chatter` (see the module docstring)."""

    speed_rpm: float | None = None
    n_inserts: int = 1
    modes_Hz: tuple[float, ...] = ()
    window_s: float | None = None
    fixed_lines_Hz: tuple[float, ...] = ()
    mains_Hz: tuple[float, ...] = MAINS_HZ
    share_limit: float = SHARE_LIMIT
    prominence_dB: float = PROMINENCE_DB
    persist_windows: int = PERSIST_WINDOWS

    def check(self, record: Record) -> None:
        src = record.source
        if self.speed_rpm is not None:
            n = float(self.speed_rpm)
            if not (math.isfinite(n) and 1.0 <= n <= 100000.0):
                raise InputError("spindle speed out of range", field="--speed-rpm", value=n,
                                 expected="1 .. 100000 r/min")
            f1 = n / 60.0
            if record.sample_rate_Hz < 2.0 * f1:
                raise DataError("sample rate below twice the spindle frequency", file=src,
                                field="sample_rate_Hz", value=record.sample_rate_Hz,
                                expected=f"at least {2 * f1:.6g} Hz for {n:g} r/min "
                                         f"(first harmonic {f1:.6g} Hz)")
        if not 1 <= int(self.n_inserts) <= 100:
            raise InputError("number of inserts out of range", field="--n-inserts",
                             value=self.n_inserts, expected="1 .. 100")
        nyq = 0.5 * record.sample_rate_Hz
        for f in self.modes_Hz:
            if not (math.isfinite(f) and 0 < f < nyq):
                raise InputError("mode frequency outside the record's band", file=src,
                                 field="modes", value=f, expected=f"0 < f < {nyq:.6g} Hz "
                                 "(half the sample rate)")
        if self.window_s is not None:
            w = float(self.window_s)
            lo = 16.0 / record.sample_rate_Hz
            if not (math.isfinite(w) and lo <= w <= record.duration_s):
                raise InputError("window length out of range", file=src, field="--window-s",
                                 value=w, expected=f"{lo:.3g} .. {record.duration_s:.6g} s "
                                 "(16 samples to the record's length)")


@dataclass(frozen=True)
class ChatterDetection:
    """The verdict on one record (see :meth:`to_dict` for the JSON contract)."""

    chatter: bool
    chatter_frequency_Hz: float | None
    onset_s: float | None
    channel: str
    spindle_frequency_Hz: float | None
    speed_rpm: float | None
    speed_source: str
    speed_spread: float
    n_inserts: int
    nonharmonic_energy_share: float
    chatter_energy_share: float
    peak_prominence_dB: float
    chatter_growth_dB: float | None
    nearest_mode_Hz: float | None
    fixed_lines_Hz: tuple[float, ...]
    window_s: float
    windows: tuple[dict[str, Any], ...]
    reasons: tuple[str, ...]
    record: dict[str, Any]
    settings: dict[str, Any]
    spectrogram: dict[str, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON contract: ``chatter``, ``chatter_frequency_Hz``, ``onset_s``, ``windows``
        (each ``t0_s``, ``t1_s``, ``chatter``, ``peak_Hz``, ``peak_share``,
        ``nonharmonic_share``, ``prominence_dB``; with chatter ``chatter_line_dB``: the
        chatter line's power relative to its largest), ``chatter_growth_dB`` (that largest
        over the first window's), the spindle frequency used and where it came from, the
        energy shares, the fixed lines excluded, ``speed_spread`` (the spindle frequency's
        relative standard deviation over the windows, :func:`speed_spread`; 0 for a steady
        speed or where the windows do not show it), the record and settings."""
        d = {k: v for k, v in self.__dict__.items() if k != "spectrogram"}
        d["windows"] = list(self.windows)
        d["reasons"] = list(self.reasons)
        d["fixed_lines_Hz"] = list(self.fixed_lines_Hz)
        d["insert_passing_Hz"] = (None if self.spindle_frequency_Hz is None
                                  else self.spindle_frequency_Hz * self.n_inserts)
        d["method"] = ("energy of the largest peak away from the spindle harmonics and fixed "
                       "lines, share of the window's energy, persistent over consecutive "
                       "windows (robobore.measure.detect)")
        return d


# ----------------------------------------------------------------------------- spectra
def window_spectra(x: np.ndarray, fs: float, nwin: int, hop: int
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hann power spectra of overlapping windows.

    ``x``: (n_channels, n_samples). Returns ``(f (n_f,), t0 (n_win,), P (n_channels, n_win,
    n_f))``; each window's mean and linear trend are removed first.
    """
    from scipy import fft

    n = x.shape[1]
    nwin = int(min(nwin, n))
    starts = np.arange(0, n - nwin + 1, max(1, int(hop)))
    view = np.lib.stride_tricks.sliding_window_view(x, nwin, axis=1)
    w = np.hanning(nwin)
    f = np.fft.rfftfreq(nwin, 1.0 / fs)
    P = np.empty((x.shape[0], starts.size, f.size))
    chunk = max(1, int(2**22 // max(1, nwin * x.shape[0])))  # ~32 MiB of samples at a time
    c = np.arange(nwin) - 0.5 * (nwin - 1)
    c2 = float(np.sum(c * c))
    for c0 in range(0, starts.size, chunk):
        seg = view[:, starts[c0:c0 + chunk], :]
        slope = (seg @ c)[..., None] / c2  # linear trend (drift, a ramp) removed
        seg = (seg - seg.mean(axis=2, keepdims=True) - slope * c) * w
        spec = fft.rfft(seg, axis=2, workers=1)
        P[:, c0:c0 + chunk] = spec.real ** 2 + spec.imag ** 2
    return f, starts / fs, P


def _floor(P: np.ndarray, half: int) -> np.ndarray:
    from scipy.ndimage import median_filter

    return median_filter(P, size=2 * half + 1, mode="nearest")


def _parabolic(logp: np.ndarray, k: int) -> float:
    """Offset (bins) of the maximum of the parabola through bins k-1, k, k+1."""
    if k <= 0 or k >= logp.size - 1:
        return 0.0
    a, b, c = logp[k - 1], logp[k], logp[k + 1]
    den = a - 2 * b + c
    return 0.0 if den >= 0 else float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))


def spectral_lines(f: np.ndarray, P: np.ndarray, lo_bin: int = 1
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Lines of an averaged spectrum: local maxima :data:`LINE_DB` above the local median
    floor. Returns ``(frequency_Hz (refined), prominence (ratio))``."""
    fl = _floor(P, 25) + 1e-300
    r = P / fl
    lp = np.log(P + 1e-300)
    k = np.arange(max(lo_bin, 1), P.size - 1)
    pk = k[(P[k] >= P[k - 1]) & (P[k] > P[k + 1]) & (r[k] >= 10 ** (LINE_DB / 10))]
    df = f[1] - f[0]
    freqs = np.array([(i + _parabolic(lp, int(i))) * df for i in pk])
    return freqs, r[pk]


def _line_tol(freqs: np.ndarray, df: float) -> np.ndarray:
    return np.maximum(0.75 * df, LINE_REL_WIDTH * freqs)


def comb_score(f0: float, freqs: np.ndarray, weights: np.ndarray, tol: np.ndarray
               ) -> tuple[float, np.ndarray]:
    """Lines explained by the harmonics of ``f0`` beyond chance: ``sum w [matched] -
    sum w min(1, 2 tol / f0)``; returns ``(score, matched mask)``."""
    k = np.round(freqs / f0)
    matched = (k >= 1) & (np.abs(freqs - k * f0) <= tol)
    chance = np.minimum(1.0, 2.0 * tol / f0)
    return float(weights[matched].sum() - (weights * chance).sum()), matched


def _refine_f0(f0: float, freqs: np.ndarray, w: np.ndarray, matched: np.ndarray) -> float:
    k = np.round(freqs[matched] / f0)
    ww = w[matched]
    return float(np.sum(ww * k * freqs[matched]) / np.sum(ww * k * k)) if k.size else f0


def find_spindle(f: np.ndarray, P: np.ndarray, speed_rpm: float | None, f_lo: float,
                 f_hi: float, exclude: list[float] | None = None
                 ) -> tuple[float | None, str, int]:
    """Spindle frequency [Hz] from an averaged spectrum: given speed refined within
    +-:data:`SPEED_TOLERANCE`, or the best harmonic comb (module docstring). A comb must
    match at least :data:`LOW_HARMONIC_LINES` lines among its first :data:`LOW_HARMONICS`
    harmonics (runout and insert passing put lines there; a cluster of chatter sidebands far
    up the comb does not make a spindle). ``exclude``: fixed lines left out. Returns
    ``(f0 or None, source, matched lines)``."""
    df = f[1] - f[0]
    freqs, prom = spectral_lines(f, P, int(max(1, f_lo / df)))
    keep = freqs <= f_hi
    for ln in exclude or []:
        keep &= np.abs(freqs - ln) > max(2.0 * df, LINE_REL_WIDTH * ln)
    freqs, prom = freqs[keep], prom[keep]
    w = np.minimum(np.log10(prom), 3.0)
    tol = _line_tol(freqs, df)

    def ok(c: float, m: np.ndarray) -> bool:
        k = np.round(freqs[m] / c)  # distinct harmonics: a cluster of lines is one
        return len(set(k[k <= LOW_HARMONICS].tolist())) >= LOW_HARMONIC_LINES

    def low(c: float) -> np.ndarray:
        return freqs <= (LOW_HARMONICS + 0.5) * c

    if speed_rpm is not None:
        nom = speed_rpm / 60.0
        grid = nom * (1 + np.linspace(-SPEED_TOLERANCE, SPEED_TOLERANCE, 121))
        best, best_s = None, -math.inf
        for g in grid:
            lw = low(g)
            s, m = comb_score(g, freqs[lw], w[lw], tol[lw])
            if m.sum() >= 1 and (s > best_s + 1e-9 or (
                    abs(s - best_s) <= 1e-9 and abs(g - nom) < abs(best - nom))):
                best, best_s = g, s
        if best is None:
            return nom, "given; no harmonic lines in the record (none excluded)", 0
        lw = low(best)
        _, m = comb_score(best, freqs[lw], w[lw], tol[lw])
        f0 = _refine_f0(best, freqs[lw], w[lw], m)
        if abs(f0 / nom - 1) > SPEED_TOLERANCE:
            f0 = best
        return float(f0), "given, refined on the record's harmonics", int(m.sum())
    if freqs.size < 3:
        return None, "not found (fewer than 3 spectral lines)", 0
    strongest = int(np.argmax(prom))
    fs_ = freqs[strongest]
    r = freqs / fs_
    # the strongest line's own harmonics: a self-excited vibration's, not the spindle's
    family = (np.round(r) >= 1) & (np.abs(freqs - np.round(r) * fs_) <= tol)
    order = np.argsort(-w)[:15]
    top = freqs[order]
    cands = [fl / k for fl in top for k in range(1, LOW_HARMONICS + 1)]
    cands += [abs(a - b) for i, a in enumerate(top) for b in top[i + 1:]]
    fmin = max(3.0 * df, f_lo, 0.5)
    found = []
    for c in cands:
        if not fmin <= c <= min(f_hi / 3.0, MAX_SPINDLE_HZ):
            continue
        s, m = comb_score(c, freqs, w, tol)
        lw = low(c)
        c2 = _refine_f0(c, freqs[lw], w[lw], m[lw])
        s2, m2 = comb_score(c2, freqs, w, tol)
        if s2 >= s:
            s, m, c = s2, m2, c2
        own = int(np.sum(m & ~family)) >= LOW_HARMONIC_LINES or abs(c - fs_) <= tol[strongest]
        if ok(c, m) and own:
            found.append((s, c, m))
    best_s, best_f, best_m = -math.inf, None, None
    if found:
        top_s = max(v[0] for v in found)
        # a sub-multiple of the spindle frequency matches its lines too: the highest
        # fundamental whose comb explains nearly as much wins (the octave-error rule)
        best_s, best_f, best_m = max((v for v in found if v[0] >= COMB_SHARE * top_s),
                                     key=lambda v: v[1])
    if best_f is None or len(set(np.round(freqs[best_m] / best_f).tolist())) < 3 or best_s < 1.5:
        return None, "not found (no harmonic comb with its low harmonics)", 0
    return float(best_f), "estimated from the record's harmonic comb", int(best_m.sum())


def fixed_lines(f: np.ndarray, P: np.ndarray, mains: tuple[float, ...],
                given: tuple[float, ...]) -> list[float]:
    """Fixed lines to exclude: each mains family whose fundamental is a line, with its
    multiples that are lines; plus the given lines."""
    df = f[1] - f[0]
    freqs, _ = spectral_lines(f, P, 1)
    out = [float(g) for g in given]
    if freqs.size == 0:
        return out
    lvl = np.interp(freqs, f, P)
    for m in mains:
        kmax = int(f[-1] / m)
        present: list[float] = []
        p1 = 0.0
        for k in range(1, min(kmax, MAINS_MAX_ORDER) + 1):
            tol = max(2.0 * df, LINE_REL_WIDTH * k * m)
            sel = np.abs(freqs - k * m) <= tol
            if not sel.any():
                if k == 1:
                    break
                continue
            j = int(np.flatnonzero(sel)[np.argmin(np.abs(freqs[sel] - k * m))])
            if k == 1:
                p1 = float(lvl[j])
            elif lvl[j] > p1:  # mains harmonics are weaker than the fundamental
                continue
            present.append(float(freqs[j]))
        out.extend(present)
    return out


def line_extent(f: np.ndarray, P: np.ndarray, center: float) -> float:
    """Half-width [Hz] of the line at ``center`` in a spectrum: how far its skirts descend
    while :data:`LINE_DB` above the local floor on either side (a spindle whose speed wanders
    widens its harmonics; a rise is the next line), at most :data:`MAX_LINE_REL_WIDTH` of the
    frequency plus a bin."""
    df = f[1] - f[0]
    fl = _floor(P, 25) + 1e-300
    above = P >= fl * 10 ** (LINE_DB / 10)
    k = int(np.clip(round(center / df), 0, f.size - 1))
    cap = int(np.ceil(MAX_LINE_REL_WIDTH * center / df)) + 1
    lo = k  # down the line's skirts while above the floor; a rise is another line
    while lo > 0 and k - lo < cap and above[lo - 1] and P[lo - 1] <= P[lo]:
        lo -= 1
    hi = k
    while hi < f.size - 1 and hi - k < cap and above[hi + 1] and P[hi + 1] <= P[hi]:
        hi += 1
    return float(max(k - lo, hi - k) * df + df)


def harmonic_bands(f: np.ndarray, P: np.ndarray, f0: float, f_lo: float,
                   exclude: list[float]) -> list[tuple[float, float]]:
    """``(centre, half-width)`` [Hz] of the harmonics of ``f0`` that the averaged spectrum
    shows as lines (:func:`line_extent`); harmonics absent from the record leave nothing to
    exclude. ``exclude``: fixed lines, not taken for harmonics."""
    df = f[1] - f[0]
    freqs, _ = spectral_lines(f, P, max(1, int(f_lo / df)))
    tol = _line_tol(freqs, df)
    k = np.round(freqs / f0)
    on = (k >= 1) & (np.abs(freqs - k * f0) <= tol) & attributable(tol, f0)
    for ln in exclude:
        on &= np.abs(freqs - ln) > max(2.0 * df, LINE_REL_WIDTH * ln)
    return [(float(c), line_extent(f, P, float(c))) for c in freqs[on]]


def window_harmonic_bands(f: np.ndarray, P: np.ndarray, f0: float, f_lo: float,
                          exclude: list[float], fine: FineLines | None = None,
                          spread: float = 0.0,
                          lines: tuple[np.ndarray, np.ndarray] | None = None
                          ) -> list[tuple[float, float]]:
    """:func:`harmonic_bands` of one window, the spindle frequency re-refined in it within
    +-:data:`WINDOW_SPEED_TOLERANCE` of the record's ``f0`` (a speed that wanders over the
    record is nearly constant over one window) when that aligns at least
    :data:`WINDOW_REALIGN_LINES` more of the window's lines with the harmonics. Only lines
    that :func:`attributable` allows; with ``fine`` (the lines of the record-length spectrum,
    :func:`fine_harmonic_bands`), a line whose band holds a stronger line of the record-length
    spectrum that is not a harmonic there is that line's (a chatter line beside a harmonic
    that the window does not resolve), not the spindle's.

    ``spread``: the spindle frequency's relative standard deviation over the record
    (:func:`speed_spread`). A harmonic ``k`` then wanders over ``k f0 (1 +- 3 spread)``
    (:data:`SPREAD_SIGMAS`): a line within that of ``k f0`` is matched to it, and the whole
    range is excluded, at the orders where that band is attributable (:func:`_spread_tol`);
    such a band is not checked against ``fine`` (a line within a harmonic's wandering range
    cannot be told from it, on either spectrum). ``lines``: the window's
    :func:`spectral_lines` above ``f_lo``, where the caller has them."""
    df = f[1] - f[0]
    freqs, prom = lines if lines is not None else spectral_lines(f, P, max(1, int(f_lo / df)))
    if freqs.size == 0:
        return []
    for ln in exclude:
        keep = np.abs(freqs - ln) > max(2.0 * df, LINE_REL_WIDTH * ln)
        freqs, prom = freqs[keep], prom[keep]
    w = np.minimum(np.log10(np.maximum(prom, 1.0)), 3.0)
    steady = _line_tol(freqs, df)
    tol = _spread_tol(steady, SPREAD_SIGMAS * spread * freqs, f0)
    fi = f0
    _, m0 = comb_score(f0, freqs, w, tol)
    grid = f0 * (1 + np.linspace(-WINDOW_SPEED_TOLERANCE, WINDOW_SPEED_TOLERANCE, 81))
    counts = [int(comb_score(g, freqs, w, tol)[1].sum()) for g in grid]
    j = max(range(grid.size), key=lambda i: (counts[i], -abs(grid[i] - f0)))
    # the speed moved when several harmonics realign, not when one line (a chatter line
    # near a harmonic) does
    if counts[j] >= int(m0.sum()) + WINDOW_REALIGN_LINES:
        _, mj = comb_score(grid[j], freqs, w, tol)
        f2 = _refine_f0(grid[j], freqs, w, mj)
        fi = f2 if abs(f2 / f0 - 1) <= WINDOW_SPEED_TOLERANCE else grid[j]
    _, m = comb_score(fi, freqs, w, tol)
    m &= attributable(tol, fi)
    if fine is not None and fine.freqs.size:
        # a band widened to the harmonic's wandering range is not checked: the harmonic is
        # smeared over that range on the record-length spectrum too
        for i in np.flatnonzero(m & (tol <= steady)):
            near = np.abs(fine.freqs - freqs[i]) <= tol[i]
            if near.any():
                j = np.flatnonzero(near)[np.argmax(fine.power[near])]
                m[i] = bool(fine.harmonic[j])
    bands = []
    for c in freqs[m]:
        hw = line_extent(f, P, float(c))
        if spread > 0.0:  # the harmonic's whole wandering range, where attributable
            kf = float(np.round(c / fi)) * fi
            wander = abs(c - kf) + SPREAD_SIGMAS * spread * kf
            if attributable(wander, fi):
                hw = max(hw, wander)
        bands.append((float(c), hw))
    return bands


def _spread_tol(tol: np.ndarray, wander: np.ndarray, f0: float) -> np.ndarray:
    """A harmonic band widened by the speed's wander where the widened band is still
    attributable (:func:`attributable`); beyond that order the band stays ``tol``, as for a
    steady speed (a band over half the spacing cannot tell the harmonic from a line beside
    it, wandering or not)."""
    wide = np.maximum(tol, wander)
    return np.where(attributable(wide, f0), wide, tol)


def window_spindle(f: np.ndarray, P: np.ndarray, f0: float, f_lo: float,
                   exclude: list[float],
                   lines: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> tuple[float, float] | None:
    """One window's own spindle frequency and its standard error [Hz]: least squares of
    ``f = k f_w`` on the window's lines at its first :data:`LOW_HARMONICS` harmonics, ``f_w``
    searched within +-:data:`WINDOW_SPEED_TOLERANCE` of the record's ``f0`` (the value that
    matches the most such lines, the nearest ``f0`` among equals). None where fewer than three
    harmonics are lines. The standard error is the lines' scatter about their harmonics (at
    least :data:`FINE_LINE_BINS` bins) over ``sqrt(sum k^2)``. ``lines``: as in
    :func:`window_harmonic_bands`."""
    df = f[1] - f[0]
    freqs = (lines if lines is not None else spectral_lines(f, P, max(1, int(f_lo / df))))[0]
    for ln in exclude:
        freqs = freqs[np.abs(freqs - ln) > max(2.0 * df, LINE_REL_WIDTH * ln)]
    freqs = freqs[freqs <= (LOW_HARMONICS + 0.5) * f0 * (1 + WINDOW_SPEED_TOLERANCE)]
    if freqs.size < 3:
        return None
    tol = _line_tol(freqs, df)

    def matched(g: float) -> np.ndarray:
        k = np.round(freqs / g)
        return (k >= 1) & (k <= LOW_HARMONICS) & (np.abs(freqs - k * g) <= tol)

    grid = f0 * (1 + np.linspace(-WINDOW_SPEED_TOLERANCE, WINDOW_SPEED_TOLERANCE, 81))
    counts = [int(matched(g).sum()) for g in grid]
    j = max(range(grid.size), key=lambda i: (counts[i], -abs(grid[i] - f0)))
    m = matched(grid[j])
    k = np.round(freqs[m] / grid[j])
    if len(set(k.tolist())) < 3:
        return None
    fw = _refine_f0(grid[j], freqs, np.ones(freqs.size), m)
    if abs(fw / f0 - 1.0) > WINDOW_SPEED_TOLERANCE:
        return None
    res = freqs[m] - k * fw
    s = max(FINE_LINE_BINS * df, float(np.sqrt(np.sum(res ** 2) / max(1, res.size - 1))))
    return fw, s / float(np.sqrt(np.sum(k * k)))


def speed_spread(f: np.ndarray, P: np.ndarray, f0: float, f_lo: float,
                 exclude: list[float],
                 lines: list[tuple[np.ndarray, np.ndarray]] | None = None) -> float:
    """Relative standard deviation of the spindle frequency over the record, from the
    windows' own spindle frequencies (:func:`window_spindle`; ``P``: (n_win, n_f)): their
    robust scatter (1.4826 times the median absolute deviation) less their typical
    standard error, in quadrature; 0 where fewer than :data:`SPREAD_MIN_WINDOWS` windows, or
    fewer than half of them, give one (the forced lines of a cut are in every window; a comb
    that only some windows show is not a spindle to measure). A spindle whose speed wanders
    (a belt, the drive's regulation under the cutting load) moves every harmonic ``k`` by
    ``k`` times its relative change. ``lines``: each window's :func:`spectral_lines`."""
    est = [window_spindle(f, P[i], f0, f_lo, exclude, None if lines is None else lines[i])
           for i in range(P.shape[0])]
    est = [e for e in est if e is not None]
    if len(est) < max(SPREAD_MIN_WINDOWS, 0.5 * P.shape[0]):
        return 0.0
    r = np.array([e[0] for e in est]) / f0
    se = np.array([e[1] for e in est]) / f0
    sd = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    return float(np.sqrt(max(0.0, sd ** 2 - float(np.median(se ** 2)))))


@dataclass(frozen=True)
class FineLines:
    """The lines of the record-length spectrum: frequency [Hz], power (normalised), whether
    each is a spindle harmonic there (:func:`fine_harmonic_bands`)."""

    freqs: np.ndarray
    power: np.ndarray
    harmonic: np.ndarray


def attributable(tol: np.ndarray, f0: float) -> np.ndarray:
    """Where a line can be attributed to the spindle by its frequency: its harmonic band
    ``2 tol`` covers at most :data:`CHANCE_MAX` of the harmonic spacing ``f0`` (the chance
    that a line beside the harmonic falls in it; :func:`comb_score` subtracts the same)."""
    return 2.0 * np.asarray(tol) <= CHANCE_MAX * f0


def fine_harmonic_bands(f: np.ndarray, P: np.ndarray, f0: float, f_lo: float,
                        exclude: list[float], coarse_df: float, spread: float = 0.0
                        ) -> tuple[list[tuple[float, float]], FineLines, float]:
    """Harmonics placed on the record-length spectrum ``(f, P)`` at the orders where the
    windows' tolerance (:func:`_line_tol` at resolution ``coarse_df``) cannot attribute a line
    to the spindle (:func:`attributable`).

    The spindle frequency is refined order by order: the lines attributable to the harmonics
    of ``f0`` (its first :data:`LOW_HARMONICS`, where two or more are lines) fix it (least
    squares of ``f = k f0``); its standard error ``s_f0 = s / sqrt(sum k^2)`` (``s`` the
    lines' scatter about their harmonics, 1.4826 times their median absolute deviation, at
    least :data:`FINE_LINE_BINS` bins) places the higher harmonics to ``k s_f0``, which
    attributes lines of higher order, and so on while the set grows. A line is the harmonic
    ``k`` when within :data:`FINE_SIGMAS` ``sqrt(s^2 + (k s_f0)^2)`` of ``k f0`` (at least
    0.75 bin) and that band is attributable. ``spread`` (the spindle frequency's relative
    standard deviation over the record, :func:`speed_spread`) widens the band to the
    harmonic's wandering range ``3 k f0 spread`` (:data:`SPREAD_SIGMAS`) where that stays
    attributable (:func:`_spread_tol`), as in the windows: a wandering harmonic is smeared over
    that range, its strongest bin anywhere in it. Returns ``(bands (centre, half-width),
    lines, s_f0)``; the bands are the high-order harmonics only (the windows attribute the
    others, checked against ``lines``)."""
    df = f[1] - f[0]
    freqs, _ = spectral_lines(f, P, max(1, int(f_lo / df)))
    for ln in exclude:
        freqs = freqs[np.abs(freqs - ln) > max(2.0 * df, LINE_REL_WIDTH * ln)]
    power = np.interp(freqs, f, P)
    none = FineLines(freqs, power, np.zeros(freqs.size, dtype=bool))
    if freqs.size < 2:
        return [], none, math.nan
    # the record's f0 re-refined on this spectrum's low harmonics (as a given speed is)
    f_start, _, n_low = find_spindle(f, P, 60.0 * f0, f_lo, 0.95 * f[-1], exclude)
    if n_low > 0:
        f0 = float(f_start)
    k = np.round(freqs / f0)
    tol = _line_tol(freqs, df)
    use = (k >= 1) & (np.abs(freqs - k * f0) <= tol) & attributable(tol, f0)
    if int(np.sum(use & (k <= LOW_HARMONICS))) >= 2:  # start from the first harmonics
        use &= k <= LOW_HARMONICS
    fr, s_f0 = f0, math.nan
    for _ in range(20):
        if int(use.sum()) < 2:
            break
        ku = np.round(freqs[use] / fr)
        f_new = float(np.sum(ku * freqs[use]) / np.sum(ku * ku))
        if abs(f_new / f0 - 1.0) > SPEED_TOLERANCE:
            break
        fr = f_new
        s_line = max(FINE_LINE_BINS * df,  # robust scatter: a stray line does not widen it
                     1.4826 * float(np.median(np.abs(freqs[use] - ku * fr))))
        s_f0 = s_line / float(np.sqrt(np.sum(ku * ku)))
        k = np.round(freqs / fr)
        tol = np.maximum(0.75 * df, FINE_SIGMAS * np.sqrt(s_line ** 2 + (k * s_f0) ** 2))
        tol = _spread_tol(tol, SPREAD_SIGMAS * spread * k * fr, fr)
        new = (k >= 1) & (np.abs(freqs - k * fr) <= tol) & attributable(tol, fr)
        if np.array_equal(new, use) or int(new.sum()) < 2:
            break
        use = new
    if not math.isfinite(s_f0):
        return [], none, s_f0
    coarse = ~attributable(_line_tol(freqs, coarse_df), fr)
    bands = [(float(c), line_extent(f, P, float(c))) for c in freqs[use & coarse]]
    return bands, FineLines(freqs, power, use.copy()), s_f0


def exclusion_mask(f: np.ndarray, bands: list[tuple[float, float]], f_lo: float,
                   fine_bands: list[tuple[float, float]] = ()) -> np.ndarray:
    """True where a frequency bin is excluded: below ``f_lo``, within a band ``(centre,
    half-width)`` (widened to :data:`LINE_BINS` bins and :data:`LINE_REL_WIDTH` of the
    frequency at least), within a band of ``fine_bands`` (harmonics placed on the
    record-length spectrum, :func:`fine_harmonic_bands`: widened to :data:`LINE_BINS` bins
    only), or in the anti-alias roll-off (the top 5 % below Nyquist)."""
    df = f[1] - f[0]
    mask = f < f_lo
    for c, hw in bands:
        mask |= np.abs(f - c) <= max(hw, LINE_BINS * df, LINE_REL_WIDTH * c)
    for c, hw in fine_bands:
        mask |= np.abs(f - c) <= max(hw, LINE_BINS * df)
    mask[-max(1, int(0.05 * f.size)):] = True
    return mask


# ----------------------------------------------------------------------------- windows
def _window_measures(f: np.ndarray, P: np.ndarray, excl: np.ndarray, allowed: np.ndarray,
                     f_lo: float) -> dict[str, np.ndarray]:
    """Per window (P, excl: (n_win, n_f)): nonharmonic share, peak bin, peak share,
    prominence."""
    df = f[1] - f[0]
    band = f >= f_lo
    tot = P[:, band].sum(axis=1) + 1e-300
    keeps = ~excl  # (n_win, n_f)
    nonh = (P * (keeps & band)).sum(axis=1) / tot
    nw = P.shape[0]
    pk = np.zeros(nw, dtype=int)
    share = np.zeros(nw)
    prom = np.zeros(nw)
    for i in range(nw):
        keep = keeps[i]
        idx = np.flatnonzero(keep & allowed)
        if idx.size == 0:
            continue
        row = P[i]
        k = int(idx[np.argmax(row[idx])])
        pk[i] = k
        fk = f[k]
        half = int(max(25, 0.05 * fk / df))
        lo, hi = max(0, k - half), min(row.size, k + half + 1)
        nb = row[lo:hi][keep[lo:hi]]
        floor = float(np.median(nb)) if nb.size else 0.0
        bw = int(max(2, round(0.005 * fk / df)))
        b0, b1 = max(0, k - bw), min(row.size, k + bw + 1)
        seg = row[b0:b1][keep[b0:b1]]
        share[i] = float(np.clip(seg - floor, 0.0, None).sum() / tot[i])
        prom[i] = 10 * math.log10(row[k] / floor) if floor > 0 else 300.0
    return {"nonharmonic": nonh, "peak": pk, "share": share, "prominence": prom}


def window_length(record: Record, s: DetectSettings, f0: float | None, n_matched: int
                  ) -> float:
    """Window length [s]: ``--window-s``, else :data:`DEFAULT_WINDOW_S` or
    :data:`WINDOW_REVS` revolutions, the longer, shortened to a third of the record (five
    windows at 50 % overlap: the persistence test can start after an onset) but, where the
    record shows spindle harmonics, to no fewer than :data:`MIN_WINDOW_REVS` revolutions;
    a record too short for :data:`PERSIST_WINDOWS` such windows gets :data:`PERSIST_WINDOWS`
    shorter ones (the harmonics are then placed on the record-length spectrum only, and the
    verdict's reasons say so)."""
    dur = record.duration_s
    if s.window_s is not None:
        return min(float(s.window_s), dur)
    if f0 is None:
        return min(DEFAULT_WINDOW_S, dur)
    win = max(DEFAULT_WINDOW_S, WINDOW_REVS / f0)
    if win <= dur / 3.0:
        return win
    least = MIN_WINDOW_REVS / f0 if n_matched > 0 else min(DEFAULT_WINDOW_S, win)
    win = max(dur / 3.0, least)
    need = max(1, int(s.persist_windows))
    if n_matched > 0 and win * (need + 1) / 2.0 > dur * (1 + 1e-9):
        return 2.0 * dur / (need + 1)
    return min(win, dur)


def detect_chatter(record: Record, settings: DetectSettings | None = None,
                   progress=None) -> ChatterDetection:
    """Chatter verdict and timeline of a record (module docstring for the method).

    ``record``: a :class:`~robobore.measure.records.Record` (all its channels are analysed;
    reduce it with ``record.channel(name)`` for one). The verdict does not depend on the
    signal's level or units.
    """
    s = settings or DetectSettings()
    s.check(record)
    from robobore.io.memory import check_memory

    # the spectra of the 50 %-overlapping windows and their normalised copies: about four
    # times the record in float64
    check_memory(4.0 * 8.0 * record.signals.size, f"chatter detection on {record.n_channels} "
                 f"x {record.n_samples} samples", "the record's length (split it into shorter "
                 "files)", file=record.source)
    x = record.signals
    fs = record.sample_rate_Hz
    n = record.n_samples
    # --- the spindle and the fixed lines on long windows (fine resolution)
    long_s = min(2.0, record.duration_s / 4)
    if s.speed_rpm is not None:  # at least 8 revolutions (the first harmonics resolved)
        long_s = max(long_s, min(record.duration_s, 8.0 * 60.0 / s.speed_rpm))
    nlong = int(min(n, max(256, round(long_s * fs))))
    fL, _, PL = window_spectra(x, fs, nlong, max(1, nlong // 2))
    lowL = 2
    PLn = PL / (PL[:, :, lowL:].sum(axis=2, keepdims=True) + 1e-300)
    avgL = PLn.mean(axis=(0, 1))
    f_hi = 0.95 * 0.5 * fs
    lines = fixed_lines(fL, avgL, tuple(s.mains_Hz), tuple(s.fixed_lines_Hz))
    f0, f0_src, n_matched = find_spindle(fL, avgL, s.speed_rpm, float(fL[lowL]), f_hi, lines)
    # harmonics are excluded where the record shows them; a given speed whose harmonics are
    # not in the record leaves nothing to exclude (and its +-1.5 % would misplace the bands)
    fixed_bands = [(ln, line_extent(fL, avgL, ln)) for ln in lines]
    if progress is not None:
        progress(0.3)
    # --- windows
    win_s = window_length(record, s, f0, n_matched)
    nwin = max(16, int(round(win_s * fs)))
    f, t0, P = window_spectra(x, fs, nwin, max(1, nwin // 2))
    df = f[1] - f[0]
    f_lo = max(4.0 * df, 0.5 * f0 if f0 else 0.0)
    Pall = P / (P[:, :, f >= f_lo].sum(axis=2, keepdims=True) + 1e-300)
    Pall = Pall.mean(axis=0)  # (n_win, n_f): the channels' normalised spectra
    # how far the speed wanders over the record (each harmonic k moves k times as far)
    # each window's lines, found once for its speed and its harmonic bands
    wlines = ([spectral_lines(f, Pall[i], max(1, int(f_lo / df))) for i in range(t0.size)]
              if n_matched > 0 else None)
    spread = speed_spread(f, Pall, f0, f_lo, lines, wlines) if n_matched > 0 else 0.0
    # high harmonic orders, where the windows' bands cannot attribute a line to the spindle:
    # the harmonics placed on the record-length spectrum (fine resolution)
    fine: list[tuple[float, float]] = []
    fine_lines = None
    if n_matched > 0:
        fF, _, PF = window_spectra(x, fs, n, n)
        PF = PF[:, 0, :] / (PF[:, 0, fF >= f_lo].sum(axis=1, keepdims=True) + 1e-300)
        fine, fine_lines, s_f0 = fine_harmonic_bands(fF, PF.mean(axis=0), f0, f_lo, lines,
                                                     df, spread)
        if not math.isfinite(s_f0):  # no harmonics placed there: the windows' bands stand
            fine_lines = None
    excl = np.empty((t0.size, f.size), dtype=bool)
    for i in range(t0.size):
        wb = (window_harmonic_bands(f, Pall[i], f0, f_lo, lines, fine_lines, spread,
                                    wlines[i]) if n_matched > 0 else [])
        excl[i] = exclusion_mask(f, wb + fixed_bands, f_lo, fine)
    allowed = np.ones(f.size, dtype=bool)
    if s.modes_Hz:
        reach = 1.5 * f0 if f0 else 0.0
        allowed[:] = False
        for fm in s.modes_Hz:
            allowed |= np.abs(f - fm) <= max(0.15 * fm, reach)
    per = [_window_measures(f, P[c], excl, allowed, f_lo) for c in range(x.shape[0])]
    if progress is not None:
        progress(0.8)
    nw = t0.size
    shares = np.array([m["share"] for m in per])  # (n_ch, n_win)
    best_ch = np.argmax(shares, axis=0)
    sel = lambda key: np.array([per[c][key][i] for i, c in enumerate(best_ch)])  # noqa: E731
    share, prom, pkb, nonh = sel("share"), sel("prominence"), sel("peak"), sel("nonharmonic")
    flag = (share >= s.share_limit) & (prom >= s.prominence_dB)
    pk_hz = f[pkb]
    need = min(int(s.persist_windows), nw)
    run_start, run_len, best = None, 0, None
    for i in range(nw):
        if flag[i] and run_len > 0 and abs(pk_hz[i] - pk_hz[i - 1]) <= max(
                3 * df, 0.02 * pk_hz[i - 1]):
            run_len += 1
        elif flag[i]:
            run_start, run_len = i, 1
        else:
            run_start, run_len = None, 0
        if run_len >= need and best is None:
            best = run_start
    chatter = best is not None
    wins = [{"t0_s": float(record.t0_s + t0[i]),
                     "t1_s": float(record.t0_s + t0[i] + nwin / fs),
                     "chatter": bool(flag[i]), "peak_Hz": float(pk_hz[i]),
                     "peak_share": float(share[i]), "nonharmonic_share": float(nonh[i]),
                     "prominence_dB": float(prom[i]),
                     "channel": record.channels[int(best_ch[i])]} for i in range(nw)]
    reasons = []
    fc = None
    onset = None
    line_db = None
    growth_db = None
    ch_idx = int(np.bincount(best_ch).argmax())
    if chatter:
        # the developed chatter: the line of the record's last chattering window (a growing
        # vibration can move from one lobe's frequency to another's as it grows)
        ref = float(pk_hz[max(i for i in range(best, nw) if flag[i])])
        use = [i for i in range(best, nw) if flag[i]
               and abs(pk_hz[i] - ref) <= max(3 * df, 0.02 * ref)]
        ch_idx = int(np.bincount(best_ch[use]).argmax())
        Pn = P[ch_idx, use] / (P[ch_idx, use][:, f >= f_lo].sum(axis=1, keepdims=True) + 1e-300)
        avg = Pn.mean(axis=0)
        near = (np.mean(excl[use], axis=0) < 0.5) & (np.abs(f - ref) <= max(3 * df, 0.02 * ref))
        if not near.any():
            near = np.abs(f - ref) <= max(3 * df, 0.02 * ref)
        k = int(np.flatnonzero(near)[np.argmax(avg[near])])
        fc = float((k + _parabolic(np.log(avg + 1e-300), k)) * df)
        onset = float(record.t0_s + t0[best])
        # the line's power per window (the same bins, raw: a ratio in time is level-free)
        bw = int(max(2, round(0.005 * fc / df)))
        kb = int(round(fc / df))
        line = P[ch_idx][:, max(0, kb - bw):kb + bw + 1].sum(axis=1) + 1e-300
        line_db = 10 * np.log10(line / line.max())
        growth_db = float(10 * np.log10(line.max() / line[0]))
        reasons.append(f"chatter: a line at {fc:.5g} Hz away from the spindle harmonics holds "
                       f"{100 * float(np.median(share[use])):.3g} % of the energy "
                       f"({float(np.median(prom[use])):.3g} dB above the floor) in "
                       f"{len(use)} of {nw} windows from t = {onset:.4g} s")
    else:
        nflag = int(flag.sum())
        reasons.append("stable: no line away from the spindle harmonics holds "
                       f"{100 * s.share_limit:.3g} % of the energy {s.prominence_dB:g} dB above "
                       f"the floor in {need} consecutive windows ({nflag} of {nw} windows "
                       "flagged)")
    if line_db is not None:
        for i, w in enumerate(wins):
            w["chatter_line_dB"] = float(line_db[i])
    windows = tuple(wins)
    if f0 is None:
        reasons.append("spindle harmonics not found: only fixed lines excluded")
    elif n_matched > 0 and s.window_s is None and nwin / fs * f0 < MIN_WINDOW_REVS - 1e-9:
        reasons.append(f"short record ({record.duration_s:.4g} s, {record.duration_s * f0:.3g} "
                       f"revolutions): windows of {nwin / fs * f0:.3g} revolutions (fewer than "
                       f"{MIN_WINDOW_REVS:g}) do not resolve the spindle harmonics; they are "
                       f"placed on the record-length spectrum only ({2 * MIN_WINDOW_REVS:g} "
                       f"revolutions, {2 * MIN_WINDOW_REVS / f0:.3g} s, resolve them in "
                       "the windows)")
    use_w = [i for i in range(nw) if flag[i]] if chatter else list(range(nw))
    mode = None
    if s.modes_Hz and fc is not None:
        mode = float(min(s.modes_Hz, key=lambda m: abs(m - fc)))
    return ChatterDetection(
        chatter=chatter, chatter_frequency_Hz=fc, onset_s=onset,
        channel=record.channels[ch_idx],
        spindle_frequency_Hz=f0, speed_rpm=None if f0 is None else 60.0 * f0,
        speed_source=f0_src, speed_spread=spread, n_inserts=int(s.n_inserts),
        nonharmonic_energy_share=float(np.mean(nonh)),
        chatter_energy_share=float(np.median(share[use_w])) if use_w else 0.0,
        peak_prominence_dB=float(np.median(prom[use_w])) if use_w else 0.0,
        chatter_growth_dB=growth_db, nearest_mode_Hz=mode,
        fixed_lines_Hz=tuple(sorted(round(v, 4) for v in lines)),
        window_s=nwin / fs, windows=windows, reasons=tuple(reasons),
        record=record.to_dict(),
        settings={"share_limit": s.share_limit, "prominence_dB": s.prominence_dB,
                  "persist_windows": need, "window_overlap": 0.5,
                  "speed_rpm_given": s.speed_rpm, "modes_Hz": list(s.modes_Hz),
                  "mains_Hz": list(s.mains_Hz), "speed_tolerance": SPEED_TOLERANCE},
        spectrogram={"f": f, "t": record.t0_s + t0 + 0.5 * nwin / fs,
                     "P": P[ch_idx] / (P[ch_idx].sum(axis=1, keepdims=True) + 1e-300)},
    )


__all__ = ["DetectSettings", "ChatterDetection", "detect_chatter", "window_spectra",
           "spectral_lines", "find_spindle", "fixed_lines", "harmonic_bands",
           "window_harmonic_bands", "line_extent", "attributable", "fine_harmonic_bands",
           "window_spindle", "speed_spread",
           "window_length",
           "exclusion_mask", "comb_score",
           "SHARE_LIMIT", "PROMINENCE_DB", "PERSIST_WINDOWS", "SPEED_TOLERANCE", "MAINS_HZ"]
