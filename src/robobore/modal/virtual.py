"""Virtual (SYNTHETIC) impact-hammer test with a documented ground truth.

The structure is a proportionally damped modal model (real, mass-normalised mode shapes)::

    H_rec[o, j](w) = sum_r phi_out[o, r] phi_in[j, r] / (w_r^2 - w^2 + 2 j zeta_r w_r w)   (m/N)

``phi_out`` ``(n_outputs, n_modes)`` are the mode shapes at the accelerometers (in their
measuring directions) and ``phi_in`` ``(n_inputs, n_modes)`` at the hammer points/directions,
both in 1/sqrt(kg). Accelerance is ``-w^2 H_rec``.

Hammer pulse: half-sine of width ``T_c`` (tip: soft 8 ms, medium 4 ms, hard 1.5 ms, typical
for a 1 kg impact hammer on a robot structure), peak force drawn around ``peak_force_N``
(+-20 %), peak time jittered by a fraction of a sample. Response: exact linear filtering of
the sampled force by the FRF on a zero-padded grid (``pad`` x the record length, so that the
circular wrap-around is below ``exp(-zeta w T_pad)``), then truncated to the record: for a
force that is zero outside the pulse this gives exactly ``A = H F`` at the record's DFT lines
(band-limited, ideally anti-aliased acquisition). Noise: white Gaussian, standard deviation =
``noise`` x RMS of the noise-free channel over the record, independently on the force and on
every response channel. Optional defects: a double hit (second pulse 40 % of the first,
15-40 ms later) and a response overload (clipping at 60 % of the channel's peak).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.modal.frf import HammerRecords
from robobore.modal.frf_data import FRFData

TIP_WIDTH_S = {"soft": 8e-3, "medium": 4e-3, "hard": 1.5e-3}


def _as_shape(v: Any) -> np.ndarray:
    """Real or complex shape array; complex entries may come as ``{"re", "im"}`` dicts."""
    a = np.asarray(v, dtype=object) if not isinstance(v, np.ndarray) else v
    if a.dtype == object:
        a = np.vectorize(lambda x: complex(x["re"], x["im"]) if isinstance(x, dict)
                         else complex(x), otypes=[complex])(a)
    if np.iscomplexobj(a):
        a = a.astype(complex)
        return a.real.copy() if not np.any(a.imag) else a
    return a.astype(float)


def _shape_list(a: np.ndarray) -> Any:
    if np.iscomplexobj(a):
        return [[{"re": float(z.real), "im": float(z.imag)} for z in row] for row in a]
    return a.tolist()


@dataclass(frozen=True)
class ModalTruth:
    """Ground-truth modal model of a virtual structure (SYNTHETIC).

    frequencies_Hz, damping_ratios: ``(n_modes,)`` undamped natural frequencies (Hz) and
    viscous damping ratios. phi_out ``(n_outputs, n_modes)``, phi_in ``(n_inputs, n_modes)``:
    mass-normalised mode-shape values (1/sqrt(kg)); complex shapes give non-proportionally
    damped (complex) modes with receptance residues ``phi_o phi_j / (2 j w_d)``.
    """

    frequencies_Hz: np.ndarray
    damping_ratios: np.ndarray
    phi_out: np.ndarray
    phi_in: np.ndarray
    output_names: tuple[str, ...] = ()
    input_names: tuple[str, ...] = ()
    description: str = ""

    def __post_init__(self) -> None:
        f = np.asarray(self.frequencies_Hz, float)
        z = np.asarray(self.damping_ratios, float)
        po = np.atleast_2d(_as_shape(self.phi_out))
        pi = np.atleast_2d(_as_shape(self.phi_in))
        nm = f.size
        if z.shape != (nm,) or po.shape[1] != nm or pi.shape[1] != nm:
            raise InputError("modal truth shapes do not agree", field="phi_out/phi_in",
                             value=f"{f.shape}, {z.shape}, {po.shape}, {pi.shape}",
                             expected="(n_modes,), (n_modes,), (n_out, n_modes), (n_in, n_modes)")
        if np.any(f <= 0) or np.any(z <= 0) or np.any(z >= 1):
            raise InputError("modal truth needs f > 0 Hz and 0 < zeta < 1",
                             field="frequencies_Hz/damping_ratios", value=(f.tolist(), z.tolist()),
                             expected="positive frequencies in Hz, damping ratios in (0, 1)")
        for k, v in (("frequencies_Hz", f), ("damping_ratios", z), ("phi_out", po),
                     ("phi_in", pi)):
            object.__setattr__(self, k, v)
        object.__setattr__(self, "output_names", tuple(self.output_names)
                           or tuple(f"o{k + 1}" for k in range(po.shape[0])))
        object.__setattr__(self, "input_names", tuple(self.input_names)
                           or tuple(f"i{k + 1}" for k in range(pi.shape[0])))

    @property
    def n_modes(self) -> int:
        return self.frequencies_Hz.size

    @property
    def is_complex(self) -> bool:
        """Complex (non-proportionally damped) mode shapes."""
        return bool(np.iscomplexobj(self.phi_out) or np.iscomplexobj(self.phi_in))

    def poles(self) -> np.ndarray:
        """``(n_modes,)`` complex poles (rad/s), positive imaginary part."""
        wn = 2 * np.pi * self.frequencies_Hz
        z = self.damping_ratios
        return -z * wn + 1j * wn * np.sqrt(1 - z**2)

    def frf(self, frequency_Hz: np.ndarray, frf_type: str = "accelerance") -> np.ndarray:
        """Exact FRF ``(n_outputs, n_inputs, n_f)``."""
        w = 2 * np.pi * np.asarray(frequency_Hz, float)
        if not self.is_complex:
            wn = 2 * np.pi * self.frequencies_Hz
            den = (wn[:, None] ** 2 - w[None, :] ** 2
                   + 2j * (self.damping_ratios * wn)[:, None] * w)
            h = np.einsum("or,jr,rk->ojk", self.phi_out, self.phi_in, 1.0 / den)
        else:
            # pole-residue form, residue phi_o phi_j / (2 j w_d) (equal to the real-mode
            # expression above when the shapes are real)
            lam = self.poles()
            R = np.einsum("or,jr->ojr", self.phi_out, self.phi_in) / (2j * lam.imag)
            jw = 1j * w[None, :]
            h = (np.einsum("ojr,rk->ojk", R, 1.0 / (jw - lam[:, None]))
                 + np.einsum("ojr,rk->ojk", R.conj(), 1.0 / (jw - lam.conj()[:, None])))
        p = {"receptance": 0, "mobility": 1, "accelerance": 2}[frf_type]
        return h * (1j * w) ** p

    def frf_data(self, frequency_Hz: np.ndarray, frf_type: str = "accelerance") -> FRFData:
        return FRFData(np.asarray(frequency_Hz, float), self.frf(frequency_Hz, frf_type),
                       frf_type, None, self.output_names, self.input_names)

    def with_inputs(self, rows: list[int]) -> ModalTruth:
        """The same structure tested with a subset of the hammer inputs."""
        return ModalTruth(self.frequencies_Hz, self.damping_ratios, self.phi_out,
                          self.phi_in[rows], self.output_names,
                          tuple(self.input_names[r] for r in rows), self.description)

    def to_dict(self) -> dict[str, Any]:
        return {"frequencies_Hz": self.frequencies_Hz.tolist(),
                "damping_ratios": self.damping_ratios.tolist(),
                "phi_out": _shape_list(self.phi_out), "phi_in": _shape_list(self.phi_in),
                "output_names": list(self.output_names), "input_names": list(self.input_names),
                "description": self.description}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ModalTruth:
        return cls(np.asarray(d["frequencies_Hz"]), np.asarray(d["damping_ratios"]),
                   _as_shape(d["phi_out"]), _as_shape(d["phi_in"]),
                   tuple(d.get("output_names", ())), tuple(d.get("input_names", ())),
                   d.get("description", ""))


#: The virtual robot of the bundled example (shared with the virtual campaign,
#: :mod:`robobore.robot.campaign`): robot, test posture (the paper's boring posture), tool
#: point in the flange frame, modal frequencies (undamped, Hz) and damping ratios.
EXAMPLE_ROBOT = "irb6600-175-2.55"
EXAMPLE_POSTURE_DEG = (-48.38, 54.82, 6.86, -54.16, 107.43, -21.95)
EXAMPLE_TCP_M = (0.0, 0.0, 0.0)
EXAMPLE_FREQUENCIES_HZ = (6.9, 16.8, 24.6, 25.34, 47.5)
EXAMPLE_DAMPING_RATIOS = (0.035, 0.028, 0.020, 0.022, 0.050)
#: Share of the tool-point static compliance C_dd (d = X, Y, Z) carried by the two local
#: modes 4 (spindle housing) and 5 (wrist), with the sign of their tool-point shape.
LOCAL_MODE_SHARES = ((0.003, 0.006, -0.006), (0.003, 0.003, 0.002))
#: Shapes of modes 1-5 at the spindle housing (x, y) and the wrist (x, z), as multiples of
#: the dominant tool-point value of modes 1-3 (modes 1-3: relative to their own dominant
#: value; modes 4-5, local modes: relative to the mean of the three dominant values).
_OTHER_RATIOS = np.array([
    [0.667, 0.125, 0.107, 0.667, -0.556],  # spindle_x
    [0.111, 0.688, 0.214, 0.778, -0.667],  # spindle_y
    [0.333, 0.063, 0.036, -0.333, 0.889],  # wrist_x
    [0.028, 0.094, 0.429, -0.444, 0.333],  # wrist_z
])


def tool_point_compliance(joint_stiffness_Nm_per_rad: Any = None,
                          posture_deg: Any = EXAMPLE_POSTURE_DEG, robot: str = EXAMPLE_ROBOT,
                          tcp_m: Any = EXAMPLE_TCP_M) -> np.ndarray:
    """Translational static compliance at the tool point, boring frame, 3x3 [m/N].

    ``C = R^T (J diag(1/k) J^T)_tt R`` with the geometric Jacobian at ``posture_deg``,
    the joint stiffness (default: the virtual campaign's ground truth,
    :data:`robobore.robot.campaign.IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD`) and ``R`` the
    boring frame (:func:`robobore.robot.stiffness.process_frame`). ``1 / C_dd`` is the
    directional stiffness of :func:`robobore.robot.stiffness.directional_stiffness_xyz`.
    """
    from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD
    from robobore.robot.description import get_robot
    from robobore.robot.kinematics import fk_jacobian
    from robobore.robot.stiffness import compliance_matrix, process_frame

    k = (IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD if joint_stiffness_Nm_per_rad is None
         else joint_stiffness_Nm_per_rad)
    rob = get_robot(robot)
    T, J = fk_jacobian(rob, np.radians(np.asarray(posture_deg, float)), tcp_m)
    R = process_frame(T[:3, :3], "boring")
    C = compliance_matrix(J, k)[:3, :3]
    return R.T @ C @ R


def _rotation(v: np.ndarray) -> np.ndarray:
    """Rotation matrix of the rotation vector ``v`` (Rodrigues)."""
    th = float(np.linalg.norm(v))
    if th == 0.0:
        return np.eye(3)
    a = v / th
    W = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(th) * W + (1 - np.cos(th)) * (W @ W)


def _most_diagonal_factor(S: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``A`` with ``A A^T = S`` whose diagonal carries the largest smallest share
    ``min_d A_dd^2 / C_dd``: ``A = S^(1/2) Q`` over rotations ``Q`` (orthogonal Procrustes
    start, then Nelder-Mead on the rotation vector; deterministic)."""
    from scipy.optimize import minimize

    w, V = np.linalg.eigh(S)
    Sh = (V * np.sqrt(w)) @ V.T
    D = np.diag(np.sqrt(np.diag(C)))
    U, _, Vt = np.linalg.svd(Sh.T @ D)
    Q0 = U @ Vt
    if np.linalg.det(Q0) < 0:
        Q0 = Q0 @ np.diag([1.0, 1.0, -1.0])

    def share(v: np.ndarray) -> float:
        A = Sh @ Q0 @ _rotation(v)
        return -float(np.min(np.diag(A) ** 2 / np.diag(C)))

    res = minimize(share, np.zeros(3), method="Nelder-Mead",
                   options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 4000})
    A = Sh @ Q0 @ _rotation(res.x)
    return A * np.sign(np.diag(A))[None, :]


def robot_boring_truth(joint_stiffness_Nm_per_rad: Any = None,
                       posture_deg: Any = EXAMPLE_POSTURE_DEG,
                       robot: str = EXAMPLE_ROBOT, tcp_m: Any = EXAMPLE_TCP_M) -> ModalTruth:
    """Ground truth of the bundled SYNTHETIC robotic-boring hammer test: the modes of the
    same virtual robot as the bundled stiffness campaign.

    Five modes ``[6.9, 16.8, 24.6, 25.34, 47.5]`` Hz, damping ``[0.035, 0.028, 0.020, 0.022,
    0.050]`` (modes 1-2 near the paper's resonances at 400 and 1000 r/min; 3-4 a close pair
    3.0 % apart). Seven accelerometers ``tool_x/y/z`` (boring frame X horizontal, Y vertical,
    Z bore axis), ``spindle_x/y``, ``wrist_x/z``; three hammer inputs at the tool point.

    Stiffness and mass model (one robot): the static compliance of the modal model at the
    tool point, ``sum_r phi_r phi_r^T / w_r^2``, EQUALS the campaign robot's compliance
    ``C`` (:func:`tool_point_compliance`: the joint stiffness through the Jacobian at the test
    posture), so the hammer test's driving-point static stiffness ``1 / H_dd(0)`` is the
    campaign's directional stiffness in every direction. Modes 4 and 5 are local modes
    (spindle housing, wrist) carrying the small shares :data:`LOCAL_MODE_SHARES` of ``C_dd``
    at the tool; modes 1-3 carry the rest, ``S = C - sum_{4,5} phi phi^T / w^2``, with
    tool-point shapes ``Phi_3 = A Omega`` (``Omega = diag(w_1..w_3)``), ``A A^T = S``, ``A``
    the factor whose diagonal is largest (:func:`_most_diagonal_factor`): mode 1 is mostly
    X, mode 2 Y, mode 3 Z. The implied tool-point mass matrix of modes 1-3 is
    ``M = Phi_3^-T Phi_3^-1`` (``Phi_3^T K Phi_3 = Omega^2`` with ``K = S^-1``). The tool
    point of this robot is coupled (compliance correlation X-Z 0.44 at this posture), so no
    single mode carries all of a direction's compliance: the dominant mode's own modal
    stiffness ``w_r^2 / phi_dr^2`` is the directional stiffness divided by its share (the
    README gives the values). Spindle and wrist shapes: :data:`_OTHER_RATIOS`.
    """
    f = np.asarray(EXAMPLE_FREQUENCIES_HZ, float)
    w = 2 * np.pi * f
    C = tool_point_compliance(joint_stiffness_Nm_per_rad, posture_deg, robot, tcp_m)
    c = np.diag(C)
    local = np.array(LOCAL_MODE_SHARES, float).T  # (3 directions, 2 modes), signed shares
    a45 = np.sign(local) * np.sqrt(np.abs(local) * c[:, None])  # shape / w [m/sqrt(N)..]
    S = C - a45 @ a45.T
    if np.linalg.eigvalsh(S).min() <= 0:
        raise InputError("the local modes take more than the tool-point compliance",
                         field="LOCAL_MODE_SHARES", value=LOCAL_MODE_SHARES,
                         expected="small shares of the compliance")
    A = _most_diagonal_factor(S, C)
    tool = np.column_stack([A * w[:3][None, :], a45 * w[3:][None, :]])
    dom = np.diag(tool[:, :3])
    scale = np.concatenate([dom, np.full(2, dom.mean())])
    other = _OTHER_RATIOS * scale[None, :]
    phi_out = np.vstack([tool, other])
    return ModalTruth(
        f, np.asarray(EXAMPLE_DAMPING_RATIOS, float), phi_out, tool.copy(),
        ("tool_x", "tool_y", "tool_z", "spindle_x", "spindle_y", "wrist_x", "wrist_z"),
        ("hammer_x", "hammer_y", "hammer_z"),
        "SYNTHETIC robotic boring system: the virtual campaign robot "
        "(robobore.modal.virtual.robot_boring_truth)",
    )


#: SYNTHETIC machine-tool tool-point truth (:func:`tool_point_truth`): modes (Hz), damping
#: ratios and the driving-point modal peaks ``phi_tip^2 / (2 zeta w^2)`` (m/N).
TOOL_POINT_FREQUENCIES_HZ = (1072.0, 1961.0, 2610.0, 2734.0, 3180.0)
TOOL_POINT_DAMPING_RATIOS = (0.030, 0.060, 0.012, 0.010, 0.004)
TOOL_POINT_PEAKS_M_PER_N = (0.35e-6, 0.24e-6, 0.22e-6, 0.15e-6, 0.01e-6)
#: shapes at the holder, the spindle front/rear and the housing, as multiples of the tip's
_TOOL_POINT_RATIOS = np.array([
    [0.8, 0.15, 0.9, 1.6, 8.0],  # holder
    [0.5, -0.08, -0.4, 2.1, -6.0],  # spindle_front
    [0.2, 0.04, 0.6, -1.8, 4.0],  # spindle_rear
    [0.1, 0.02, 0.2, 1.5, 3.0],  # housing
])


def tool_point_truth() -> ModalTruth:
    """SYNTHETIC end mill, holder and spindle, hammer at the tool tip, five responses (tip,
    holder, spindle front/rear, housing): four tool modes in 1-3 kHz and a lightly damped
    housing mode (3180 Hz, zeta 0.4 %) that is large away from the tool and small at the tip.

    Driving-point peaks :data:`TOOL_POINT_PEAKS_M_PER_N`: the 1961 Hz mode is well damped
    (6 %) and an end-mill mode (large at the tip only); its tip peak is higher than those of
    the lightly damped 2610 and 2734 Hz modes. The 2734 Hz mode is a spindle mode, weak at
    the tip but large at every other response, so it is better supported in the
    stabilisation diagram than the 2610 Hz mode (at 3 % noise). The three modes that dominate
    the tool point are 1072, 1961 and 2610 Hz."""
    f = np.asarray(TOOL_POINT_FREQUENCIES_HZ, float)
    z = np.asarray(TOOL_POINT_DAMPING_RATIOS, float)
    w = 2 * np.pi * f
    tip = np.sqrt(np.asarray(TOOL_POINT_PEAKS_M_PER_N) * 2 * z * w**2)
    phi_out = np.vstack([tip, _TOOL_POINT_RATIOS * tip[None, :]])
    return ModalTruth(f, z, phi_out, tip[None, :],
                      ("tip", "holder", "spindle_front", "spindle_rear", "housing"),
                      ("hammer_tip",),
                      "SYNTHETIC tool point of a machining centre "
                      "(robobore.modal.virtual.tool_point_truth)")


def truth_table(truth: ModalTruth | None = None) -> dict[str, Any]:
    """Stiffness figures of a tool-point truth (hammer inputs at the tool X, Y, Z):
    driving-point static stiffness ``1 / H_dd(0)`` [N/m] per direction, each mode's
    driving-point modal mass ``1 / phi^2`` [kg] and stiffness ``w^2 / phi^2`` [N/m], and the
    share of ``H_dd(0)`` carried by each mode."""
    t = truth or robot_boring_truth()
    w = 2 * np.pi * t.frequencies_Hz
    phi = np.real(t.phi_in)  # (3 directions, n_modes)
    comp = phi**2 / w[None, :] ** 2
    return {"static_stiffness_N_per_m": dict(zip("xyz", (1 / comp.sum(axis=1)).tolist(),
                                                 strict=True)),
            "modal_mass_kg": (1 / phi**2).tolist(),
            "modal_stiffness_N_per_m": (w[None, :] ** 2 / phi**2).tolist(),
            "compliance_share": (comp / comp.sum(axis=1, keepdims=True)).tolist()}


def hammer_pulse(n: int, fs: float, t_peak_s: float, width_s: float, peak_N: float
                 ) -> np.ndarray:
    """Sampled half-sine pulse ``(n,)`` N of width ``width_s`` centred on ``t_peak_s``."""
    t = np.arange(n) / fs - (t_peak_s - width_s / 2)
    f = np.where((t >= 0) & (t <= width_s), np.sin(np.pi * np.clip(t, 0, width_s) / width_s),
                 0.0)
    return peak_N * f


def simulate_hammer_test(truth: ModalTruth, *, n_hits: int = 5, sample_rate_Hz: float = 512.0,
                         duration_s: float = 8.0, tip: str = "soft", peak_force_N: float = 200.0,
                         noise_force: float = 0.01, noise_response: float = 0.01,
                         pretrigger_s: float = 0.05, pad: int = 4,
                         double_hits: list[tuple[int, int]] | None = None,
                         overloads: list[tuple[int, int]] | None = None,
                         seed: int | np.random.Generator | None = 0) -> HammerRecords:
    """Simulate a roving-hammer test: every input hit ``n_hits`` times, all outputs recorded.

    Parameters
    ----------
    truth: modal model (SYNTHETIC ground truth).
    sample_rate_Hz, duration_s: acquisition; records ``(n_samples = fs * T)``.
    tip: ``soft`` | ``medium`` | ``hard`` (pulse width, TIP_WIDTH_S) or a width in s.
    noise_force, noise_response: noise std as a fraction of each channel's RMS.
    double_hits, overloads: ``(input, hit)`` pairs (0-based) to corrupt, for testing checks.
    seed: int or Generator.

    Returns
    -------
    HammerRecords (acceleration in m/s^2, force in N), labelled SYNTHETIC in ``meta``.
    """
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    if isinstance(tip, str):
        if tip not in TIP_WIDTH_S:
            raise InputError("unknown hammer tip", field="tip", value=tip,
                             expected="soft, medium, hard or a pulse width in s")
        width = TIP_WIDTH_S[tip]
    else:
        width = float(tip)
    if n_hits < 1:
        raise InputError("need at least one hit", field="n_hits", value=n_hits,
                         expected="an integer >= 1")
    if sample_rate_Hz <= 2 * truth.frequencies_Hz.max():
        raise InputError("sample rate too low for the modes", field="sample_rate_Hz",
                         value=sample_rate_Hz,
                         expected=f"> {2 * truth.frequencies_Hz.max():g} Hz (Nyquist)")
    if width * sample_rate_Hz < 1.0:
        # a pulse shorter than a sample is not a realistic record
        width = 1.0 / sample_rate_Hz
    n = int(round(duration_s * sample_rate_Hz))
    if n < 64:
        raise InputError("record too short", field="duration_s", value=duration_s,
                         expected=">= 64 samples")
    npad = pad * n
    freq = np.fft.rfftfreq(npad, 1.0 / sample_rate_Hz)
    H = truth.frf(freq, "accelerance")  # (no, ni, nf)
    no, ni = H.shape[:2]
    double_hits = set(double_hits or [])
    overloads = set(overloads or [])
    force = np.zeros((ni, n_hits, n))
    resp = np.zeros((ni, n_hits, no, n))
    for j in range(ni):
        for h in range(n_hits):
            t0 = pretrigger_s + rng.uniform(-0.5, 0.5) / sample_rate_Hz
            peak = peak_force_N * rng.uniform(0.8, 1.2)
            f = hammer_pulse(npad, sample_rate_Hz, t0, width, peak)
            if (j, h) in double_hits:
                f = f + hammer_pulse(npad, sample_rate_Hz, t0 + rng.uniform(0.015, 0.04),
                                     width, 0.4 * peak)
            a = np.fft.irfft(H[:, j, :] * np.fft.rfft(f)[None, :], n=npad, axis=-1)[:, :n]
            f = f[:n]
            fr = np.sqrt(np.mean(f**2))
            ar = np.sqrt(np.mean(a**2, axis=1, keepdims=True))
            force[j, h] = f + noise_force * fr * rng.standard_normal(n)
            a = a + noise_response * ar * rng.standard_normal((no, n))
            if (j, h) in overloads:  # the ADC clips the (noisy) signal at its range
                lim = 0.6 * np.abs(a).max(axis=1, keepdims=True)
                a = np.clip(a, -lim, lim)
            resp[j, h] = a
    return HammerRecords(sample_rate_Hz, force, resp, "acceleration", truth.output_names,
                         truth.input_names, pretrigger_s=pretrigger_s,
                         meta={"synthetic": True, "truth": truth.to_dict(),
                               "noise_force": noise_force, "noise_response": noise_response,
                               "tip_width_s": width, "n_hits": n_hits})


__all__ = ["ModalTruth", "robot_boring_truth", "simulate_hammer_test", "hammer_pulse",
           "TIP_WIDTH_S", "tool_point_compliance", "truth_table", "EXAMPLE_POSTURE_DEG",
           "EXAMPLE_FREQUENCIES_HZ", "EXAMPLE_DAMPING_RATIOS", "LOCAL_MODE_SHARES",
           "tool_point_truth", "TOOL_POINT_FREQUENCIES_HZ", "TOOL_POINT_DAMPING_RATIOS",
           "TOOL_POINT_PEAKS_M_PER_N"]
