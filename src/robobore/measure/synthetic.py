"""SYNTHETIC labelled vibration records from robobore's own time-domain simulation.

Ground truth (each record's ``truth``): a tool whose bending mode (frequency, damping,
stiffness drawn per record) cuts with the single-point regenerative process
(:func:`robobore.dynamics.process.single_point_process`) at a spindle speed, number of inserts
and depth of cut drawn per record; :func:`robobore.dynamics.timedomain.simulate` runs the cut
and :func:`robobore.dynamics.chatter.classify` labels it (``chatter`` and its
``chatter_frequency_Hz``). The depth is drawn away from the critical depth at that speed
(the frequency-domain lobes, :func:`robobore.dynamics.stability.lobes_frequency_domain`):
0.3-0.75 of it or 1.3-3 times it, so that the simulation's label is not a marginal case.

The record is what a tool-holder accelerometer would give: the simulated tool-point
acceleration along the mode (sampled at ``8 x`` the record's rate, low-pass filtered and
decimated), plus

* the forced response to spindle runout: force harmonics ``K a e / k`` at ``k n / 60``
  (``k = 1..8``, runout ``e`` 2-10 um) and insert-passing harmonics ``0.3 K a h / j`` at
  ``j N n / 60`` (``j = 1..4``), through the mode's receptance (acceleration), random phases;
* broadband cutting-force noise (2 % of the mean force, white) through the mode (a resonance
  hump in the spectrum);
* mains lines (50 or 60 Hz, with its 3rd and 5th multiples) at 5-50 % of the record's RMS;
* white sensor noise at a signal-to-noise ratio of 20-40 dB;
* an offset and a random gain ``10^U(-3, 3)`` (the detector must not care).

**Speed wander** (``speed_wander`` W > 0): the spindle's speed is ``n (1 + eps(t))``, ``eps``
the sum of three sinusoids of ``U(0.1, 2)`` Hz and random phases scaled to a standard
deviation W (a belt drive, or the drive's regulation under the cutting load). The lines that
turn with the spindle (runout, insert passing, the interruption) follow its angle: each
harmonic ``k`` moves by ``k`` times the relative change. The regenerative simulation, and so
the label, runs at the constant speed (the wander changes the delay by ``eps``, a
negligible change of the lobes at a few per mille). These draws come from
``numpy.random.default_rng((seed, 2))``; with W = 0 the record is that of the steady speed,
bit for bit.

Every random draw comes from ``numpy.random.default_rng(seed)``; the default records are
spindle speeds of 1000-8000 r/min (``speed_range_rpm``).

**Low-speed regime** (:data:`LOW_SPEED`: ``labelled_set(n, seed, **LOW_SPEED)``): turning
and boring cells and laboratory tests at 150-1000 r/min (spindle 2.5-17 Hz), 8 s records
(20-130 revolutions), where a chatter line near the mode lies at rotation-harmonic order
30-1000. With ``interruption_probability`` p, a record's cut is, with probability p,
interrupted once per revolution (a flat, a cross hole or a hard spot round the bore): the chip
force along the mode changes by a fraction ``q ~ U(0.05, 1)`` of its mean (1: the chip
vanishes) over an arc of
``U(2, 10)`` degrees. That rectangular pulse train has force harmonics
``2 q F sin(pi k d) / (pi k)`` (``d`` the arc's share of the revolution) up to the record's
band; through the mode's receptance they put forced lines at high harmonic orders round the
mode, the lines a detector must not take for chatter. The pulse train is built over one
revolution of the simulation's grid (exactly periodic), superposed on the simulated
acceleration like the runout response (the regenerative simulation, and so the label, does
not see it). These draws come from ``numpy.random.default_rng((seed, 1))``, so a record's other
draws are those of the same seed without the interruption (its mains and sensor-noise levels,
set relative to the record's RMS, follow the added lines).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.measure.records import Record, make_record

#: The simulation runs at this multiple of the record's sample rate.
OVERSAMPLE = 8
#: Spindle speeds of the default records [r/min].
DEFAULT_SPEED_RANGE_RPM = (1000.0, 8000.0)
#: The low-speed regime (module docstring): keyword arguments of :func:`simulated_record`.
LOW_SPEED: dict[str, Any] = {"speed_range_rpm": (150.0, 1000.0), "duration_s": 8.0,
                             "interruption_probability": 0.5}


def _mode_acc_response(f: np.ndarray, fn: float, zeta: float, k: float) -> np.ndarray:
    """Acceleration receptance of a SDOF mode [m/s^2/N] at frequencies ``f`` [Hz]."""
    r = f / fn
    w = 2 * np.pi * f
    return -(w ** 2) / (k * (1 - r ** 2 + 2j * zeta * r))


def _interruption_response(force: float, duty: float, phase: float, Ns: int, fsim: float,
                           n: int, fn: float, zeta: float, k: float,
                           angle_t: np.ndarray | None = None) -> np.ndarray:
    """Acceleration [m/s^2] at the record's rate (``fsim / OVERSAMPLE``), ``n`` samples, of
    the mode driven by a force pulse of ``force`` [N] lasting ``duty`` of each revolution
    (``Ns`` simulation steps), starting at ``phase`` of the revolution: its harmonics up to
    0.45 of the record's rate, each through the receptance, summed over one revolution of the
    simulation grid (an inverse FFT, exactly periodic) and repeated. ``angle_t``: the
    spindle's angle at each sample as the time [s] it would take at the nominal speed (a
    wandering speed); the revolution's waveform is then read there, linearly interpolated on
    the simulation grid."""
    f1 = fsim / Ns
    kk = np.arange(1, Ns // 2)
    kk = kk[kk * f1 < 0.45 * fsim / OVERSAMPLE]
    # complex Fourier coefficients of a rectangular pulse train of height ``force``
    c = force * np.sin(np.pi * kk * duty) / (np.pi * kk) * np.exp(
        -1j * np.pi * kk * duty - 2j * np.pi * kk * phase)
    spec = np.zeros(Ns // 2 + 1, dtype=complex)
    spec[kk] = c * _mode_acc_response(kk * f1, fn, zeta, k) * Ns
    one = np.fft.irfft(spec, Ns)
    if angle_t is not None:
        pos = np.mod(angle_t * fsim, Ns)
        return np.interp(pos, np.arange(Ns + 1), np.append(one, one[0]))
    reps = int(math.ceil(n * OVERSAMPLE / Ns)) + 1
    return np.tile(one, reps)[::OVERSAMPLE][:n]


def simulated_record(seed: int, sample_rate_Hz: float = 10000.0, duration_s: float = 3.0,
                     n_channels: int = 1,
                     speed_range_rpm: tuple[float, float] = DEFAULT_SPEED_RANGE_RPM,
                     interruption_probability: float = 0.0,
                     speed_wander: float = 0.0) -> Record:
    """One SYNTHETIC labelled record (module docstring); ``truth`` holds the label and the
    drawn parameters. With ``n_channels`` 3 the record has the accelerometer's three axes
    (the other two see the mode through 5-20 % cross-axis sensitivity, with their own
    noise). ``speed_range_rpm``: the range the spindle speed is drawn from;
    ``interruption_probability``: the chance of a once-per-revolution interruption of the
    cut (module docstring, low-speed regime); ``speed_wander``: the standard deviation of
    the spindle speed's relative wander (module docstring)."""
    from scipy import signal

    from robobore.dynamics import stability
    from robobore.dynamics.chatter import classify
    from robobore.dynamics.process import single_point_process
    from robobore.dynamics.structure import ToolPointStructure
    from robobore.dynamics.timedomain import SimulationSettings, simulate

    n_lo, n_hi = (float(v) for v in speed_range_rpm)
    if not (math.isfinite(n_lo) and math.isfinite(n_hi) and 10.0 <= n_lo < n_hi <= 100000.0):
        raise InputError("spindle speed range out of range", field="speed_range_rpm",
                         value=speed_range_rpm, expected="10 <= low < high <= 100000 r/min")
    p_int = float(interruption_probability)
    if not 0.0 <= p_int <= 1.0:
        raise InputError("interruption probability out of range",
                         field="interruption_probability", value=p_int, expected="0 .. 1")
    wander = float(speed_wander)
    if not (math.isfinite(wander) and 0.0 <= wander <= 0.05):
        raise InputError("speed wander out of range", field="speed_wander", value=wander,
                         expected="0 .. 0.05 (a relative standard deviation of the speed)")
    rng = np.random.default_rng(seed)
    fs = float(sample_rate_Hz)
    fn = float(rng.uniform(500.0, min(2500.0, 0.3 * fs)))
    zeta = float(rng.uniform(0.01, 0.04))
    kst = float(10 ** rng.uniform(6.7, 7.5))
    beta = math.radians(rng.uniform(20.0, 70.0))
    K = 2.0e9  # N/m^2, specific cutting force of a titanium alloy
    feed = 0.1e-3
    N = int(rng.integers(1, 5))
    st = ToolPointStructure.from_modes([{"frequency_Hz": fn, "damping_ratio": zeta,
                                         "stiffness_N_per_m": kst, "direction": [1, 0, 0]}])
    u = np.array([math.cos(beta), math.sin(beta), 0.0])
    pr = single_point_process(K, u, [1.0, 0.0, 0.0], feed, n_inserts=N)
    fsim = OVERSAMPLE * fs
    lo_ns, hi_ns = math.ceil(60 * fsim / n_hi / N), math.floor(60 * fsim / n_lo / N)
    Ns = N * int(rng.integers(lo_ns, hi_ns + 1))
    speed = 60.0 * fsim / Ns
    crit = float(stability.lobes_frequency_domain(st, pr, np.array([speed])).critical_depth_m[0])
    if rng.random() < 0.5:
        factor = float(rng.uniform(0.3, 0.75))
    else:
        factor = float(rng.uniform(1.3, 3.0))
    depth = factor * crit
    revs = int(math.ceil(duration_s * speed / 60.0)) + 1
    ds = simulate(st, pr, SimulationSettings(speed, depth, revs, Ns))
    v = classify(ds)
    acc = ds["acceleration"].values[:, 0]
    clean = signal.decimate(acc, OVERSAMPLE, ftype="fir", zero_phase=True)
    n = int(round(duration_s * fs))
    clean = np.pad(clean, (0, max(0, n - clean.size)), mode="edge")[:n]
    t = np.arange(n) / fs
    angle_t = t  # the spindle's angle, as the time it takes at the nominal speed [s]
    if wander > 0.0:  # own generator: the record's other draws stay those of its seed
        rng3 = np.random.default_rng((seed, 2))
        fw = rng3.uniform(0.1, 2.0, 3)
        pw = rng3.uniform(0.0, 2 * np.pi, 3)
        eps = wander * math.sqrt(2.0 / 3.0) * np.sin(
            2 * np.pi * fw[:, None] * t[None, :] + pw[:, None]).sum(axis=0)
        angle_t = t + np.concatenate(([0.0], np.cumsum(0.5 * (eps[1:] + eps[:-1])))) / fs
    f1 = speed / 60.0
    # forced response to runout and insert passing
    e = rng.uniform(2e-6, 10e-6)
    forced = np.zeros(n)
    gain_x = u[0]  # the force's component along the mode
    for kk in range(1, 9):
        fk = kk * f1
        if fk >= 0.45 * fs:
            break
        H = _mode_acc_response(np.array([fk]), fn, zeta, kst)[0]
        forced += np.abs(H) * gain_x * K * depth * e / kk * np.cos(
            2 * np.pi * fk * angle_t + rng.uniform(0, 2 * np.pi))
    for j in range(1, 5):
        fj = j * N * f1
        if fj >= 0.45 * fs:
            break
        H = _mode_acc_response(np.array([fj]), fn, zeta, kst)[0]
        forced += np.abs(H) * gain_x * 0.3 * K * depth * (feed / N) / j * np.cos(
            2 * np.pi * fj * angle_t + rng.uniform(0, 2 * np.pi))
    interruption = None
    if p_int > 0.0:  # own generator: the record's other draws stay those of its seed
        rng2 = np.random.default_rng((seed, 1))
        if rng2.random() < p_int:
            q = float(rng2.uniform(0.05, 1.0))
            arc = float(rng2.uniform(2.0, 10.0))
            forced += _interruption_response(q * gain_x * K * depth * (feed / N), arc / 360.0,
                                             float(rng2.uniform(0.0, 1.0)), Ns, fsim, n,
                                             fn, zeta, kst,
                                             angle_t if wander > 0.0 else None)
            interruption = {"force_fraction": q, "arc_deg": arc}
    # broadband cutting-force noise through the mode (frequency-domain filtering)
    fnoise = 0.02 * K * depth * (feed / N) * rng.standard_normal(n)
    Fw = np.fft.rfft(fnoise)
    fr = np.fft.rfftfreq(n, 1.0 / fs)
    hump = np.fft.irfft(Fw * _mode_acc_response(fr, fn, zeta, kst) * gain_x, n)
    x = clean + forced + hump
    rms = float(np.sqrt(np.mean((x - x.mean()) ** 2))) or 1.0
    mains = 50.0 if rng.random() < 0.5 else 60.0
    a_m = rng.uniform(0.05, 0.5) * rms
    ph = rng.uniform(0, 2 * np.pi)
    lines = a_m * (np.sin(2 * np.pi * mains * t + ph) + np.sin(2 * np.pi * 3 * mains * t) / 3
                   + np.sin(2 * np.pi * 5 * mains * t) / 5)
    snr_db = rng.uniform(20.0, 40.0)
    chans = []
    for c in range(n_channels):
        cross = 1.0 if c == 0 else rng.uniform(0.05, 0.2)
        y = cross * x + lines
        y = y + rms * 10 ** (-snr_db / 20) * rng.standard_normal(n)
        chans.append(y)
    gain = 10 ** rng.uniform(-3, 3)
    X = gain * (np.vstack(chans) + rng.uniform(-1, 1) * rms)
    names = ["acc"] if n_channels == 1 else [f"acc_{a}" for a in "xyz"[:n_channels]]
    truth: dict[str, Any] = {
        "chatter": bool(v.chatter), "chatter_frequency_Hz": v.chatter_frequency_Hz,
        "speed_rpm": speed, "n_inserts": N, "mode_Hz": fn, "damping_ratio": zeta,
        "stiffness_N_per_m": kst, "depth_mm": depth * 1e3,
        "critical_depth_mm": crit * 1e3, "depth_over_critical": factor,
        "vibration_growth": v.vibration_growth, "mains_Hz": mains, "snr_dB": snr_db,
        "gain": gain, "seed": seed, "generator": "robobore.measure.synthetic.simulated_record",
        "speed_range_rpm": [n_lo, n_hi], "interruption": interruption,
        "speed_wander": wander,
    }
    return make_record(X, fs, names, ["" for _ in names],
                       source=f"<SYNTHETIC record seed {seed}>", kind="SYNTHETIC", truth=truth)


def labelled_set(n: int, seed: int = 0, **kw: Any) -> list[Record]:
    """``n`` SYNTHETIC records, seeds ``seed .. seed + n - 1`` (:func:`simulated_record`)."""
    return [simulated_record(seed + i, **kw) for i in range(n)]


__all__ = ["simulated_record", "labelled_set", "OVERSAMPLE", "LOW_SPEED",
           "DEFAULT_SPEED_RANGE_RPM"]
