"""Joint-stiffness identification from a laser-tracker campaign.

Method (Dumas, Caro, Garnier, Furet, Robotics and Computer-Integrated Manufacturing 27(4),
2011; Chen et al., the seed paper, eq. 9-12):

1. For every posture and loaded step, the rigid-body motion of the >= 3 reflectors relative
   to load step 0 is fitted (Kabsch 1976 / Horn 1987: SVD of the cross-covariance, with a
   reflection guard ``det = +1``), giving the small displacement screw of the flange: the
   translation ``dp`` of the reference point (flange origin) and the rotation vector ``phi``.
2. The lumped joint-spring model gives ``dX = J diag(c) J^T W`` with ``c_i = 1/k_i`` the joint
   compliances, ``J`` the geometric Jacobian at the reference point and ``W = [F; (p_load -
   p_ref) x F]`` the external wrench about that point. It is linear in ``c``:
   ``dX = sum_i c_i J_i (J_i . W)``, i.e. regressor column i is ``J_i (J_i . W)``.
3. Weighted (generalised) least squares: the covariance of the fitted screws follows from
   the tracker noise through the linearised rigid fit (``dX = L e``, ``L = pinv(D)``, ``D``
   the small-motion design of the reflector layout); the steps of a posture share the noise
   of their reference step, so their covariance is ``(I + 1 1^T) kron (L Sigma L^T)``. The
   system is whitened with its Cholesky factor and solved with non-negative least squares
   (``scipy.optimize.nnls``, column-scaled).
4. Covariance of ``c``: ``s^2 (A^T A)^-1`` with ``s^2`` the weighted residual variance
   (``chi^2/dof``; or 1 when the tracker noise ``sigma_m`` is given as known). 95 % intervals
   of ``c`` use Student's t (dof = equations - unknowns) and are inverted to intervals of
   ``k``; the standard error of ``k`` is the delta method, ``se_k = se_c / c^2``.
5. Observability: condition number of the column-scaled whitened regressor. A joint whose
   column is (numerically) zero - no torque at that joint in any test, e.g. joint 6 when the
   force passes through the spindle axis - or that is collinear with the others (condition
   number above ``cond_limit``) is reported *unidentifiable* and gets ``None``; so does a
   joint whose compliance ends at the non-negativity bound (stiffer than the campaign can
   resolve).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import optimize, stats

from robobore.errors import IdentificationError, InputError
from robobore.robot.campaign import Campaign
from robobore.robot.campaign_io import validate_campaign
from robobore.robot.description import check_joint_limits, get_robot
from robobore.robot.kinematics import fk_jacobian, rotation_vector
from robobore.robot.stiffness import JointStiffness, process_frame

STRUCTURAL_ZERO = 1e-8  # column norm relative to the largest: "no excitation"
#: chi-square (6 dof) 99.9 % quantile: a measurement whose whitened residual exceeds it is
#: flagged ``suspect`` (a reflector knocked in its nest, a wrong force reading ...).
SUSPECT_CHI2_6DOF = 22.458
#: level of the whole-fit residual test: a fit whose weighted residual exceeds the
#: chi-square quantile of this level for the stated tracker noise is reported (a wrong
#: robot, tool point or reflector file explains it better than noise does)
RESIDUAL_TEST_LEVEL = 0.999


def kabsch(P0: np.ndarray, P1: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Best rigid motion ``P1 ~ R P0 + t`` (least squares), batched.

    P0, P1: (..., m, 3). Returns R (..., 3, 3) proper rotation (reflection guard), t (..., 3),
    and the rms fit residual (...) in the units of the points.
    """
    P0 = np.asarray(P0, float)
    P1 = np.asarray(P1, float)
    g0 = P0.mean(axis=-2, keepdims=True)
    g1 = P1.mean(axis=-2, keepdims=True)
    H = np.swapaxes(P0 - g0, -1, -2) @ (P1 - g1)  # (..., 3, 3)
    U, _, Vt = np.linalg.svd(H)
    V = np.swapaxes(Vt, -1, -2)
    d = np.sign(np.linalg.det(V @ np.swapaxes(U, -1, -2)))
    d = np.where(d == 0, 1.0, d)
    D = np.zeros(H.shape)
    D[..., 0, 0] = 1.0
    D[..., 1, 1] = 1.0
    D[..., 2, 2] = d
    R = V @ D @ np.swapaxes(U, -1, -2)
    t = g1[..., 0, :] - np.einsum("...ij,...j->...i", R, g0[..., 0, :])
    fit = np.einsum("...ij,...mj->...mi", R, P0) + t[..., None, :]
    rms = np.sqrt(np.mean(np.sum((fit - P1) ** 2, axis=-1), axis=-1))
    return R, t, rms


def screw_map(points: np.ndarray, ref_point: np.ndarray) -> np.ndarray:
    """Linearised rigid fit ``[dp_ref; phi] = L vec(delta)``, L (6, 3m).

    For small motions a point k moves by ``delta_k = dp_ref + phi x (p_k - p_ref)``; ``L`` is
    the pseudo-inverse of that design (equal to the small-motion limit of the Kabsch fit).
    """
    P = np.asarray(points, float)
    m = P.shape[0]
    D = np.zeros((3 * m, 6))
    for k in range(m):
        r = P[k] - ref_point
        D[3 * k:3 * k + 3, :3] = np.eye(3)
        D[3 * k:3 * k + 3, 3:] = -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]],
                                            [-r[1], r[0], 0]])
    return np.linalg.pinv(D)


@dataclass
class _Design:
    """Everything that does not depend on the measured noise: structure, regressor, weights."""

    labels: list[str]
    q_rad: np.ndarray  # (P, n)
    # (posture, step, reference rows, rows, first row) per loaded step
    meas: list[tuple[int, int, list[int], list[int], int]]
    A: np.ndarray  # (N_eq, n) physical regressor
    whiten: list[np.ndarray]  # per posture: inverse Cholesky factor (6S x 6S) of its block
    ref_point: np.ndarray  # (P, 3)
    J: np.ndarray  # (P, 6, n) at the reference point
    force: np.ndarray  # (M, 3)
    step_of: list[int]
    known_sigma: float | None
    unused_postures: list[str]  # postures with only the unloaded step (reported, not used)


def _build_design(c: Campaign, robot, sigma_m: float | None) -> _Design:
    labels = c.postures()
    n = robot.n_joints
    rows_of: dict[tuple[str, int], list[int]] = {}
    for i in range(c.n_rows):
        rows_of.setdefault((c.posture[i], int(c.load_step[i])), []).append(i)
    q = np.zeros((len(labels), n))
    for p, lab in enumerate(labels):
        i0 = rows_of[(lab, 0)][0]
        q[p] = np.radians(c.q_deg[i0])
        check_joint_limits(robot, q[p], file=c.source, rows=[c.row_number(i0)])
    T, J = fk_jacobian(robot, q)  # reference point: flange origin
    ref_point = T[:, :3, 3]
    meas = []
    unused: list[str] = []
    A_blocks = []
    W_blocks = []
    forces = []
    steps = []
    for p, lab in enumerate(labels):
        ref = sorted(rows_of[(lab, 0)], key=lambda i: c.reflector[i])
        loaded_steps = sorted(st for (lb, st) in rows_of if lb == lab and st > 0)
        if not loaded_steps:
            unused.append(lab)
            continue
        L = screw_map(c.xyz_m[ref], ref_point[p])
        M = L @ L.T  # unit per-coordinate variance
        S = len(loaded_steps)
        for st in loaded_steps:
            ids = sorted(rows_of[(lab, st)], key=lambda i: c.reflector[i])
            F = c.force_N[ids[0]]
            Wr = np.concatenate([F, np.cross(c.load_point_m[ids[0]] - ref_point[p], F)])
            tau = J[p].T @ Wr  # (n,) joint torques
            A_blocks.append(J[p] * tau[None, :])
            meas.append((p, st, ref, ids, c.row_number(ids[0])))
            forces.append(F)
            steps.append(st)
        cov = np.kron(np.eye(S) + np.ones((S, S)), M)
        Lc = np.linalg.cholesky(cov)
        W_blocks.append(np.linalg.inv(Lc))
    if not meas:
        raise IdentificationError(f"{c.source}: no loaded step in any posture; nothing to "
                                  "identify (every posture needs load steps > 0)")
    A = np.concatenate(A_blocks, axis=0)
    N = A.shape[0]
    if N < n + 1:
        raise IdentificationError(
            f"{c.source}: too few equations: {N} (6 per loaded step) for {n} joint "
            f"compliances; at least {n + 1} are needed (more postures / load steps)")
    return _Design(labels, q, meas, A, W_blocks, ref_point, J, np.asarray(forces), steps, sigma_m,
                   unused)


def _screws(c: Campaign, d: _Design, xyz: np.ndarray) -> np.ndarray:
    """Measured screws (B, N_eq) for reflector positions xyz (B, N_rows, 3)."""
    out = []
    for p, _st, ref, ids, _row in d.meas:
        R, t, _ = kabsch(xyz[:, ref], xyz[:, ids])
        c0 = d.ref_point[p]
        dp = np.einsum("bij,j->bi", R, c0) + t - c0
        out.append(np.concatenate([dp, rotation_vector(R)], axis=-1))
    return np.stack(out, axis=1).reshape(xyz.shape[0], -1)


def _whiten(d: _Design, X: np.ndarray) -> np.ndarray:
    """Apply the block-diagonal whitening to the last axis of X (..., N_eq)."""
    out = np.empty_like(X)
    o = 0
    for B in d.whiten:
        k = B.shape[0]
        out[..., o:o + k] = X[..., o:o + k] @ B.T
        o += k
    return out


@dataclass
class _Solution:
    c: np.ndarray  # (B, n) compliances, nan where inactive
    se_c: np.ndarray  # (B, n)
    active: np.ndarray  # (n,) bool used in the fit
    status: list[str]
    s2: np.ndarray  # (B,)
    dof: int
    cond_all: float
    cond_active: float
    col_norm_rel: np.ndarray
    cov_c: np.ndarray  # (B, n, n), zeros outside active
    resid_w: np.ndarray  # (B, N_eq) whitened residuals
    resid: np.ndarray  # (B, N_eq) physical residuals
    chi2_dof: np.ndarray  # (B,) weighted residual variance (sigma^2 if unknown, else chi2/dof)


def _solve(d: _Design, y: np.ndarray, cond_limit: float) -> _Solution:
    n = d.A.shape[1]
    Aw = _whiten(d, d.A.T).T
    yw = _whiten(d, y)
    if d.known_sigma is not None:
        Aw = Aw / d.known_sigma
        yw = yw / d.known_sigma
    norms = np.linalg.norm(Aw, axis=0)
    rel = norms / norms.max() if norms.max() > 0 else np.zeros(n)
    status = ["identified"] * n
    active = rel > STRUCTURAL_ZERO
    for i in np.flatnonzero(~active):
        status[i] = "unidentifiable: not loaded (no torque in any test)"
    if not active.any():
        raise IdentificationError("no joint is loaded by the campaign's forces")

    def _cond(mask: np.ndarray) -> tuple[float, np.ndarray]:
        As = Aw[:, mask] / norms[mask]
        _, s, Vt = np.linalg.svd(As, full_matrices=False)
        return (float(s[0] / s[-1]) if s[-1] > 0 else math.inf), Vt[-1]

    cond_all, _ = _cond(active)
    cond_act, v = cond_all, None
    while active.sum() > 1:
        cond_act, v = _cond(active)
        if cond_act <= cond_limit:
            break
        idx = np.flatnonzero(active)
        j = int(idx[np.argmax(np.abs(v))])
        active[j] = False
        status[j] = f"unidentifiable: combination of the others (cond {cond_act:.3g})"
    idx = np.flatnonzero(active)
    As = Aw[:, idx] / norms[idx]
    B = y.shape[0]
    N = Aw.shape[0]
    dof = N - idx.size
    c = np.full((B, n), np.nan)
    for b in range(B):
        xs, _ = optimize.nnls(As, yw[b])
        c[b, idx] = xs / norms[idx]
    cz = np.where(np.isnan(c), 0.0, c)
    resid_w = yw - cz @ Aw.T
    resid = y - cz @ d.A.T
    chi2_dof = np.sum(resid_w ** 2, axis=1) / dof
    s2 = chi2_dof if d.known_sigma is None else np.ones(B)
    G = np.linalg.inv(As.T @ As)  # scaled
    cov_act = G / np.outer(norms[idx], norms[idx])
    cov = np.zeros((B, n, n))
    cov[:, idx[:, None], idx[None, :]] = s2[:, None, None] * cov_act[None]
    se = np.sqrt(np.einsum("bii->bi", cov))
    se[:, ~active] = np.nan
    return _Solution(c, se, active, status, s2, dof, cond_all, cond_act, rel, cov, resid_w,
                     resid, chi2_dof)


@dataclass(frozen=True)
class StiffnessIdentification:
    """Result of :func:`identify_joint_stiffness` (what ``identify stiffness`` prints)."""

    joint: JointStiffness
    compliance_rad_per_Nm: tuple[float | None, ...]
    compliance_std_rad_per_Nm: tuple[float | None, ...]
    condition_number: float
    condition_number_identified: float
    column_norm_relative: tuple[float, ...]
    dof: int
    n_equations: int
    noise_sigma_estimated_m: float | None
    chi2_per_dof: float | None
    residual_rms_translation_m: float
    residual_rms_rotation_rad: float
    residuals: tuple[dict[str, Any], ...]
    sigma_known_m: float | None
    directional: dict[str, Any] = field(default_factory=dict)
    source: str = ""
    synthetic: bool = False
    notes: tuple[str, ...] = ()
    #: the chi-square test of the weighted residual against the stated tracker noise
    residual_test: dict[str, Any] = field(default_factory=dict)
    #: what the result describes (:mod:`robobore.io.identity`)
    identity: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        j = self.joint.to_dict()
        out = {
            "joint_stiffness_Nm_per_rad": j["joint_stiffness_Nm_per_rad"],
            "joint_stiffness_std_Nm_per_rad": j["joint_stiffness_std_Nm_per_rad"],
            "joint_stiffness_ci95_low_Nm_per_rad": j["joint_stiffness_ci95_low_Nm_per_rad"],
            "joint_stiffness_ci95_high_Nm_per_rad": j["joint_stiffness_ci95_high_Nm_per_rad"],
            "joint_status": j["joint_status"],
        }
        out.update(self.directional)
        out.update({
            "robot": self.joint.robot,
            "source": self.source,
            "synthetic": self.synthetic,
            "compliance_rad_per_Nm": list(self.compliance_rad_per_Nm),
            "compliance_std_rad_per_Nm": list(self.compliance_std_rad_per_Nm),
            "observability": {
                "condition_number_scaled": self.condition_number,
                "condition_number_identified": self.condition_number_identified,
                "column_norm_relative": list(self.column_norm_relative),
            },
            "n_equations": self.n_equations,
            "dof": self.dof,
            "noise_sigma_estimated_m": self.noise_sigma_estimated_m,
            "chi2_per_dof": self.chi2_per_dof,
            "sigma_known_m": self.sigma_known_m,
            "residual_rms_translation_m": self.residual_rms_translation_m,
            "residual_rms_rotation_rad": self.residual_rms_rotation_rad,
            "residuals": list(self.residuals),
            "residual_test": dict(self.residual_test),
            "notes": list(self.notes),
            "identity": dict(self.identity),
        })
        return out


def _k_from_c(c: np.ndarray, se: np.ndarray, tq: float):
    """k, se_k (delta method), 95 % interval of k from c, se_c (arrays, nan-aware)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        k = 1.0 / c
        se_k = se / c ** 2
        lo = 1.0 / (c + tq * se)
        hi_c = c - tq * se
        hi = np.where(hi_c > 0, 1.0 / hi_c, np.inf)
    return k, se_k, lo, hi


def identify_batch(
    campaign: Campaign, robot: Any, xyz_batch: np.ndarray, *, sigma_m: float | None = None,
    cond_limit: float = 1e6,
) -> dict[str, np.ndarray]:
    """Vectorised identification for many noise realisations of one campaign layout.

    ``xyz_batch`` (B, N_rows, 3) replaces the campaign's reflector positions (rows in the
    campaign's order). Returns arrays (B, n): ``k``, ``se_k``, ``ci_low``, ``ci_high``
    (inf = unbounded), ``c``, ``se_c``, plus ``active`` (n,), ``dof``. Used by the coverage
    test and by Monte-Carlo studies; the design is built once.
    """
    robot = get_robot(robot)
    d = _build_design(campaign, robot, sigma_m)
    y = _screws(campaign, d, np.asarray(xyz_batch, float))
    sol = _solve(d, y, cond_limit)
    tq = float(stats.norm.ppf(0.975)) if sigma_m is not None else float(
        stats.t.ppf(0.975, sol.dof))
    k, se_k, lo, hi = _k_from_c(sol.c, sol.se_c, tq)
    return {"k": k, "se_k": se_k, "ci_low": lo, "ci_high": hi, "c": sol.c, "se_c": sol.se_c,
            "active": sol.active, "dof": sol.dof, "cov_c": sol.cov_c}


def identify_joint_stiffness(
    campaign: Campaign,
    robot: Any,
    *,
    sigma_m: float | None = None,
    cond_limit: float = 1e6,
    frame: str | np.ndarray = "boring",
    tcp_m: Any = None,
) -> StiffnessIdentification:
    """Identify the joint stiffnesses of ``robot`` from ``campaign`` (see module docstring).

    ``sigma_m``: known tracker noise (1-sigma per coordinate, m); default None = estimate the
    scale from the weighted residuals. ``frame``/``tcp_m``: where the directional stiffness
    at the campaign's first posture is evaluated (with its 95 % interval).
    """
    robot = get_robot(robot)
    validate_campaign(campaign, robot=robot)
    d = _build_design(campaign, robot, sigma_m)
    y = _screws(campaign, d, campaign.xyz_m[None])
    sol = _solve(d, y, cond_limit)
    tq = float(stats.norm.ppf(0.975)) if sigma_m is not None else float(
        stats.t.ppf(0.975, sol.dof))
    c, se = sol.c[0], sol.se_c[0]
    k, se_k, lo, hi = _k_from_c(c, se, tq)
    status = list(sol.status)
    kk: list[float | None] = []
    for i in range(robot.n_joints):
        if not sol.active[i]:
            kk.append(None)
        elif not c[i] > 0:
            status[i] = "unidentifiable: compliance at bound 0 (too stiff to resolve)"
            kk.append(None)
        else:
            kk.append(float(k[i]))
            if not np.isfinite(hi[i]):
                status[i] = "weak: 95 % interval unbounded above"

    def _opt(a: np.ndarray, ok: list[bool]) -> tuple[float | None, ...]:
        return tuple(float(a[i]) if ok[i] and np.isfinite(a[i]) else None
                     for i in range(a.size))

    ok = [x is not None for x in kk]
    synthetic = bool(campaign.truth and campaign.truth.get("synthetic")) or "synthetic" in \
        campaign.source.lower()
    js = JointStiffness(
        robot=robot.name,
        k_Nm_per_rad=tuple(kk),
        std_Nm_per_rad=_opt(se_k, ok),
        ci95_low_Nm_per_rad=_opt(lo, ok),
        ci95_high_Nm_per_rad=_opt(hi, ok),
        status=tuple(status),
        source=f"identified from {campaign.source}",
        synthetic=synthetic,
    )
    # residuals per measurement
    res = []
    r = sol.resid[0].reshape(-1, 6)
    rw = sol.resid_w[0].reshape(-1, 6)
    for (p, st, ref, ids, row), rr, rrw in zip(d.meas, r, rw, strict=True):
        nres = np.linalg.norm(rrw) / math.sqrt(6 * sol.s2[0])
        _, _, fit_rms = kabsch(campaign.xyz_m[ref], campaign.xyz_m[ids])
        res.append({
            "posture": d.labels[p], "load_step": st, "first_row": row,
            "translation_residual_m": float(np.linalg.norm(rr[:3])),
            "rotation_residual_rad": float(np.linalg.norm(rr[3:])),
            "normalised_residual": float(nres),
            "rigid_fit_rms_m": float(fit_rms),
            "suspect": bool(nres ** 2 * 6 > SUSPECT_CHI2_6DOF),
        })
    rt = math.sqrt(float(np.mean(r[:, :3] ** 2)))
    rr_ = math.sqrt(float(np.mean(r[:, 3:] ** 2)))
    directional = directional_with_interval(robot, d.q_rad[0], c, sol.cov_c[0], sol.active, tq,
                                            frame=frame, tcp_m=tcp_m)
    directional["directional_posture_deg"] = np.degrees(d.q_rad[0]).tolist()
    by_frame = {}
    for fr in ("tool", "boring", "base"):
        try:
            by_frame[fr] = directional_with_interval(
                robot, d.q_rad[0], c, sol.cov_c[0], sol.active, tq, frame=fr, tcp_m=tcp_m
            )["directional_stiffness_N_per_m"]
        except InputError:  # boring frame undefined for a vertical feed axis
            by_frame[fr] = None
    directional["directional_stiffness_by_frame_N_per_m"] = by_frame
    test = residual_test(campaign, sol.chi2_dof[0], sol.dof, sigma_m)
    notes = [f"posture {lab!r} has no loaded step: it was not used" for lab in
             d.unused_postures]
    if not test["passed"]:
        notes.append(test["message"])
    from robobore.io.identity import make_identity

    ident = make_identity(
        "joint stiffness", robot=robot.name, robot_hash=robot.description_hash(),
        robot_file=robot.file or None,
        joints_deg=np.degrees(d.q_rad[0]).tolist(), tcp_m=directional["directional_tcp_m"],
        frame=directional["directional_frame"], synthetic=synthetic, source=campaign.source)
    return StiffnessIdentification(
        joint=js,
        compliance_rad_per_Nm=_opt(c, ok),
        compliance_std_rad_per_Nm=_opt(se, ok),
        condition_number=sol.cond_all,
        condition_number_identified=sol.cond_active,
        column_norm_relative=tuple(float(x) for x in sol.col_norm_rel),
        dof=sol.dof,
        n_equations=int(d.A.shape[0]),
        noise_sigma_estimated_m=None if sigma_m is not None else float(
            math.sqrt(sol.chi2_dof[0])),
        chi2_per_dof=None if sigma_m is None else float(sol.chi2_dof[0]),
        residual_rms_translation_m=rt,
        residual_rms_rotation_rad=rr_,
        residuals=tuple(res),
        sigma_known_m=sigma_m,
        directional=directional,
        source=campaign.source,
        synthetic=synthetic,
        notes=tuple(notes),
        residual_test=test,
        identity=ident,
    )


def residual_test(campaign: Campaign, s2: float, dof: int, sigma_m: float | None
                  ) -> dict[str, Any]:
    """Chi-square test of the weighted residual against the stated tracker noise.

    ``s2`` is the weighted residual variance: chi^2/dof when ``sigma_m`` (the known noise)
    is given, else the estimated per-coordinate noise variance [m^2]. Without ``sigma_m``
    the reference is the documented default tracker model
    (:class:`robobore.robot.campaign.TrackerNoise`: AT901 class, half of the MPE
    15 um + 6 um/m, from its default position), RMS over the campaign's reflector
    positions. The fit passes when ``chi^2 = dof * s^2 / sigma^2`` is below the chi-square
    quantile at ``RESIDUAL_TEST_LEVEL`` with ``dof`` degrees of freedom."""
    from robobore.robot.campaign import TrackerNoise

    if sigma_m is not None:
        sigma, how, chi2 = float(sigma_m), "the given tracker noise", float(s2) * dof
    else:
        sigma = float(np.sqrt(np.mean(TrackerNoise().sigma(campaign.xyz_m) ** 2)))
        how = "the default tracker model (AT901 class, half of 15 um + 6 um/m)"
        chi2 = float(s2) * dof / sigma ** 2
    limit = float(stats.chi2.ppf(RESIDUAL_TEST_LEVEL, dof))
    est = math.sqrt(chi2 / dof) * sigma
    passed = bool(chi2 <= limit)
    msg = "" if passed else (
        f"{campaign.source}: the fit's residual (noise {est * 1e6:.3g} um per coordinate) "
        f"exceeds what {how} of {sigma * 1e6:.3g} um explains (chi-square {chi2:.4g} > "
        f"{limit:.4g}, the {RESIDUAL_TEST_LEVEL:.1%} quantile with {dof} dof): a wrong "
        "robot, tool point or reflector file? (a noisier tracker: give --sigma-um)")
    return {"sigma_reference_m": sigma, "sigma_reference": how, "chi2": chi2, "dof": dof,
            "chi2_limit": limit, "level": RESIDUAL_TEST_LEVEL,
            "noise_equivalent_m": est, "passed": passed, "message": msg}


def directional_with_interval(
    robot: Any, q_rad: np.ndarray, c: np.ndarray, cov_c: np.ndarray, active: np.ndarray,
    tq: float, *, frame: str | np.ndarray = "boring", tcp_m: Any = None,
) -> dict[str, Any]:
    """Directional stiffness {x, y, z} [N/m] with 95 % intervals from the compliance fit.

    ``u^T C_tt u = g^T c`` with ``g_i = (u . Jv_i)^2`` is linear in ``c``, so its variance is
    ``g^T Cov(c) g`` exactly and the interval of ``k_u = 1/(g^T c)`` is the inverted interval
    of ``g^T c``. Axes that an unidentified joint moves (``g_i`` not negligible) get None.
    """
    T, J = fk_jacobian(robot, q_rad, tcp_m)
    R = process_frame(T[:3, :3], frame)
    vals: dict[str, float | None] = {}
    los: dict[str, float | None] = {}
    his: dict[str, float | None] = {}
    cz = np.where(np.isfinite(c), c, 0.0)
    usable = active & np.isfinite(c) & (cz > 0)
    for name, u in zip("xyz", R.T, strict=True):
        g = (u @ J[:3]) ** 2
        if np.any(g[~usable] > 1e-12 * g.max()):
            vals[name] = los[name] = his[name] = None
            continue
        s = float(g @ cz)
        se = float(math.sqrt(max(g @ cov_c @ g, 0.0)))
        vals[name] = 1.0 / s
        los[name] = 1.0 / (s + tq * se)
        his[name] = 1.0 / (s - tq * se) if s - tq * se > 0 else None
    Jv = J[:3]
    if np.any(np.sum(Jv[:, ~usable] ** 2, axis=0) > 1e-12 * np.sum(Jv ** 2, axis=0).max()):
        kp, V = None, None
    else:
        Ctt = (Jv * cz) @ Jv.T
        lam, Vm = np.linalg.eigh(0.5 * (Ctt + Ctt.T))
        if np.linalg.det(Vm) < 0:
            Vm[:, 2] *= -1.0
        kp, V = (1.0 / lam).tolist(), Vm.tolist()
    return {
        "principal_stiffness_N_per_m": kp,
        "principal_directions_world": V,
        "directional_stiffness_N_per_m": vals,
        "directional_stiffness_ci95_low_N_per_m": los,
        "directional_stiffness_ci95_high_N_per_m": his,
        "directional_frame": frame if isinstance(frame, str) else "user",
        "directional_tcp_m": [0.0, 0.0, 0.0] if tcp_m is None else list(map(float, tcp_m)),
        "directional_R_world_process": R.tolist(),
    }


__all__ = [
    "kabsch",
    "screw_map",
    "identify_joint_stiffness",
    "identify_batch",
    "directional_with_interval",
    "residual_test",
    "StiffnessIdentification",
]
