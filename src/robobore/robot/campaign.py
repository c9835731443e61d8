"""Laser-tracker stiffness campaigns: the data object and a virtual-campaign generator.

A campaign is a set of postures; at each posture the robot holds its commanded joint
angles while a load is applied in steps (step 0 = unloaded reference) and a laser tracker
measures >= 3 reflectors fixed to the flange. The contract CSV (``campaign_io``) holds one
row per (posture, load step, reflector), positions in the robot base frame.

The generator (:func:`simulate_campaign`) produces such a campaign from a documented ground
truth: a robot, true joint stiffnesses, postures, loads and a tracker noise model. The
"physics" of the virtual robot is the lumped joint-spring model with rigid links, solved
*nonlinearly*: the deflection ``dq`` satisfies ``Ktheta dq = J(q + dq)^T W`` with the force
applied at a point fixed to the flange (a loading bar / lever arm or the pressure foot), and
the reflector positions are the exact forward kinematics at ``q + dq``. Identification
(:mod:`robobore.robot.identify`) uses the linearised model, so the synthetic data also test
that the linearisation error is negligible.

Noise model (Leica AT901 class laser tracker, manufacturer's specification): maximum
permissible error of a 3D point ``MPE = +-(15 um + 6 um/m * distance to the tracker)``,
typical results half of that. ASSUMPTION: each coordinate gets independent Gaussian noise
with standard deviation ``sigma = typical_fraction * MPE`` (default fraction 0.5), unless the
user gives ``sigma_m`` directly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robobore.errors import ConfigError, InputError
from robobore.robot.description import check_joint_limits, get_robot
from robobore.robot.kinematics import fk, fk_jacobian

#: Ground truth used for the bundled synthetic IRB 6600 campaign and the tests, N m/rad.
#: ASSUMPTION, not a measurement of any real robot: values of the order published for
#: 150-250 kg payload robots (Dumas, Caro, Garnier, Furet, "Joint stiffness identification of
#: six-revolute industrial serial robots", Robotics and Computer-Integrated Manufacturing
#: 27(4), 2011, KUKA KR240-2: a few 1e6 N m/rad for axes 1-3 and a few 1e5 N m/rad for the
#: wrist axes 4-6).
IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD: tuple[float, ...] = (
    3.0e6, 4.0e6, 2.5e6, 5.0e5, 4.5e5, 3.0e5,
)

#: The paper's boring posture (joint angles, deg), first posture of the default campaign.
PAPER_POSTURE_DEG: tuple[float, ...] = (-48.38, 54.82, 6.86, -54.16, 107.43, -21.95)

#: Five more postures spread over the IRB 6600 workspace (deg), within joint limits and away
#: from singularities (condition number of J below 50 at the flange).
DEFAULT_POSTURES_DEG: tuple[tuple[float, ...], ...] = (
    PAPER_POSTURE_DEG,
    (-30.0, 40.0, 0.0, -40.0, 95.0, 10.0),
    (-60.0, 30.0, 20.0, -70.0, 110.0, -40.0),
    (-20.0, 60.0, -10.0, -20.0, 80.0, 30.0),
    (-70.0, 45.0, 15.0, 45.0, -70.0, 60.0),
    (0.0, 25.0, 30.0, 90.0, 60.0, -60.0),
)

#: Force directions (world frame, normalised when used), one per default posture: a cable
#: pulled through a load cell in a different direction at each posture, so that every joint
#: sees torque in several directions.
DEFAULT_FORCE_DIRECTIONS: tuple[tuple[float, float, float], ...] = (
    (-1.0, 0.3, -0.5),
    (0.3, -1.0, 0.4),
    (0.5, 0.5, -1.0),
    (-0.6, -0.6, 0.5),
    (1.0, -0.2, -0.3),
    (-0.2, 0.8, 0.6),
)

#: Default lever arm: load point in the flange frame, m (0.30 m along the spindle axis and
#: 0.25 m sideways, e.g. the end of a loading bar clamped to the end-effector).
DEFAULT_LOAD_POINT_FLANGE_M: tuple[float, float, float] = (0.25, 0.0, 0.30)

#: Default reflector layout in the flange frame, m: three nests on a 0.12 m radius, 20 mm in
#: front of the flange face, at 0, 120 and 240 deg (non-collinear).
DEFAULT_REFLECTORS_FLANGE_M: tuple[tuple[float, float, float], ...] = tuple(
    (0.12 * math.cos(math.radians(a)), 0.12 * math.sin(math.radians(a)), 0.02)
    for a in (0.0, 120.0, 240.0)
)

#: Paper's pressure-foot steps, MPa (Chen et al.: P = 0, 0.3, 0.4, 0.5, 0.6 MPa).
PAPER_PRESSURES_MPA: tuple[float, ...] = (0.0, 0.3, 0.4, 0.5, 0.6)


@dataclass(frozen=True)
class TrackerNoise:
    """Laser-tracker noise model (per-coordinate Gaussian, independent).

    Either ``sigma_m`` (1-sigma per coordinate, m) directly, or the MPE model
    ``sigma = typical_fraction * (mpe_const_m + mpe_per_m * distance)`` with the distance from
    ``tracker_position_m`` (world frame, m). Defaults: Leica AT901 class.
    """

    sigma_m: float | None = None
    mpe_const_m: float = 15e-6
    mpe_per_m: float = 6e-6
    typical_fraction: float = 0.5
    tracker_position_m: tuple[float, float, float] = (3.5, -3.0, 1.0)

    def __post_init__(self) -> None:
        if self.sigma_m is not None and not (self.sigma_m >= 0 and math.isfinite(self.sigma_m)):
            raise ConfigError("tracker noise must be >= 0", field="sigma_m", value=self.sigma_m,
                              expected="a non-negative number in m")

    def sigma(self, points_m: np.ndarray) -> np.ndarray:
        """1-sigma per coordinate [m] for points (..., 3) -> (...)."""
        p = np.asarray(points_m, float)
        if self.sigma_m is not None:
            return np.full(p.shape[:-1], float(self.sigma_m))
        dist = np.linalg.norm(p - np.asarray(self.tracker_position_m), axis=-1)
        return self.typical_fraction * (self.mpe_const_m + self.mpe_per_m * dist)

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        return asdict(self)


@dataclass(frozen=True, eq=False)
class Campaign:
    """A stiffness campaign in the contract layout, one entry per CSV row.

    Arrays (N rows): ``load_step`` (N,) int, ``q_deg`` (N, 6), ``force_N`` (N, 3) external
    force on the robot (world frame), ``load_point_m`` (N, 3) its point of application at the
    unloaded pose (world frame), ``xyz_m`` (N, 3) reflector positions (world frame),
    ``pressure_MPa`` (N,) or None. ``posture`` and ``reflector`` are string labels per row.
    ``rows`` are the 1-based data-row numbers in the source file (for error messages).
    """

    posture: tuple[str, ...]
    load_step: np.ndarray
    q_deg: np.ndarray
    force_N: np.ndarray
    load_point_m: np.ndarray
    reflector: tuple[str, ...]
    xyz_m: np.ndarray
    pressure_MPa: np.ndarray | None = None
    source: str = "<campaign>"
    rows: tuple[int, ...] | None = None
    truth: dict[str, Any] | None = field(default=None)

    @property
    def n_rows(self) -> int:
        return len(self.posture)

    def row_number(self, i: int) -> int:
        return self.rows[i] if self.rows is not None else i + 1

    def postures(self) -> list[str]:
        """Posture labels in order of first appearance."""
        return list(dict.fromkeys(self.posture))


@dataclass(frozen=True)
class CampaignSpec:
    """Everything that defines a virtual campaign (the documented ground truth).

    ``load_levels_N``: force magnitudes per step (step 0 must be 0) along
    ``force_directions`` (one world-frame direction per posture). In pressure-foot mode
    (``pressures_MPa`` given) the magnitudes are ``P * piston_area_m2`` and the CSV gets a
    ``pressure_MPa`` column. ``load_point_flange_m`` is the load point in the flange frame.
    """

    robot: str = "irb6600-175-2.55"
    joint_stiffness_Nm_per_rad: tuple[float, ...] = IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD
    postures_deg: tuple[tuple[float, ...], ...] = DEFAULT_POSTURES_DEG
    force_directions: tuple[tuple[float, float, float], ...] | None = DEFAULT_FORCE_DIRECTIONS
    load_levels_N: tuple[float, ...] = (0.0, 250.0, 500.0, 750.0, 1000.0)
    pressures_MPa: tuple[float, ...] | None = None
    piston_area_m2: float = 1.0e-3 / 0.6  # 0.6 MPa -> 1 kN (46 mm piston)
    load_point_flange_m: tuple[float, float, float] = DEFAULT_LOAD_POINT_FLANGE_M
    reflectors_flange_m: tuple[tuple[float, float, float], ...] = DEFAULT_REFLECTORS_FLANGE_M
    noise: TrackerNoise = field(default_factory=TrackerNoise)
    seed: int = 0

    def magnitudes_N(self) -> np.ndarray:
        if self.pressures_MPa is not None:
            return np.asarray(self.pressures_MPa, float) * 1e6 * self.piston_area_m2
        return np.asarray(self.load_levels_N, float)

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        return asdict(self)


def pressure_foot_spec(**kw: Any) -> CampaignSpec:
    """The paper's loading: a pressure foot on the spindle axis, P = 0, 0.3 ... 0.6 MPa.

    The foot reaction pushes the tool back along -z of the flange (force direction
    ``None`` = "along -tool z at each posture"), applied on the spindle axis 0.35 m in front
    of the flange. Such a load has no moment about the wrist centre, so joints 4-6 are NOT
    identifiable from it (the identification reports them as such).
    """
    base = dict(
        pressures_MPa=PAPER_PRESSURES_MPA,
        force_directions=None,
        load_point_flange_m=(0.0, 0.0, 0.35),
    )
    base.update(kw)
    return CampaignSpec(**base)


def _validate_spec(spec: CampaignSpec, robot: Any) -> np.ndarray:
    n = robot.n_joints
    q = np.radians(np.asarray(spec.postures_deg, float))
    if q.ndim != 2 or q.shape[1] != n or q.shape[0] < 1:
        raise ConfigError("postures must be a list of joint-angle tuples", field="postures_deg",
                          expected=f"(n_postures, {n}) angles in deg")
    check_joint_limits(robot, q)
    mags = spec.magnitudes_N()
    if mags.size < 2 or mags[0] != 0.0:
        raise ConfigError("load step 0 must be the unloaded reference (0) and at least one "
                          "loaded step must follow", field="load_levels_N",
                          value=mags.tolist(), expected="[0, F1, F2, ...] in N")
    if spec.force_directions is not None and len(spec.force_directions) < q.shape[0]:
        raise ConfigError("one force direction per posture is needed",
                          field="force_directions",
                          expected=f"{q.shape[0]} world-frame vectors")
    refl = np.asarray(spec.reflectors_flange_m, float)
    if refl.ndim != 2 or refl.shape[1] != 3 or refl.shape[0] < 3:
        raise ConfigError("at least 3 reflectors are needed", field="reflectors_flange_m",
                          expected="(m >= 3, 3) positions in m in the flange frame")
    if collinear(refl):
        raise ConfigError("reflectors are collinear", field="reflectors_flange_m",
                          value=refl.tolist(), expected="3 or more non-collinear points, m")
    return q


def collinear(points: np.ndarray, rel_tol: float = 1e-3) -> bool:
    """True if points (m, 3) are (nearly) on one line: s2/s1 of the centred cloud < rel_tol."""
    P = np.asarray(points, float)
    if P.shape[0] < 3:
        return True
    s = np.linalg.svd(P - P.mean(axis=0), compute_uv=False)
    return bool(s[0] == 0.0 or s[1] / s[0] < rel_tol)


def deflect(
    robot: Any, q_rad: np.ndarray, k: np.ndarray, force_N: np.ndarray, point_flange_m: np.ndarray,
    *, tol_rad: float = 1e-14, max_iter: int = 50,
) -> np.ndarray:
    """Joint deflection ``dq`` (rad) solving ``diag(k) dq = J(q + dq)^T [F; 0]``.

    The force ``F`` (world frame, N, fixed direction: a dead load) acts at a point fixed in
    the flange frame, ``J`` is the geometric Jacobian at that point. Newton iteration with
    the exact tangent ``diag(k) - K_G`` (K_G from the analytic dJ/dq, Chen & Kao 2000).
    """
    from robobore.errors import NumericalError
    from robobore.robot.stiffness import geometric_stiffness

    W = np.concatenate([np.asarray(force_N, float), np.zeros(3)])
    k = np.asarray(k, float)
    dq = np.zeros(robot.n_joints)
    for _ in range(max_iter):
        _, J = fk_jacobian(robot, q_rad + dq, point_flange_m)
        r = k * dq - J.T @ W
        step = np.linalg.solve(np.diag(k) - geometric_stiffness(robot, q_rad + dq, W,
                                                                point_flange_m), r)
        dq = dq - step
        if np.max(np.abs(step)) < tol_rad:
            return dq
    raise NumericalError("joint-spring equilibrium did not converge (load too large for the "
                         "joint stiffnesses?)")


def simulate_clean(spec: CampaignSpec) -> dict[str, Any]:
    """Noise-free campaign from ``spec``: structured arrays for the generator and tests.

    Returns a dict with ``q_rad`` (P, n), ``force_N`` (P, S, 3), ``load_point_m`` (P, 3)
    (unloaded pose), ``xyz_m`` (P, S, m, 3) exact reflector positions, ``sigma_m``
    (P, S, m) per-coordinate noise, ``dq_rad`` (P, S, n) true joint deflections, ``pressure``
    (S,) MPa or None.
    """
    robot = get_robot(spec.robot)
    q = _validate_spec(spec, robot)
    k = np.asarray(spec.joint_stiffness_Nm_per_rad, float)
    if k.shape != (robot.n_joints,) or np.any(k <= 0) or not np.all(np.isfinite(k)):
        raise ConfigError("true joint stiffnesses must be positive",
                          field="joint_stiffness_Nm_per_rad", value=k.tolist(),
                          expected=f"{robot.n_joints} positive values in N m/rad")
    mags = spec.magnitudes_N()
    P, S = q.shape[0], mags.size
    refl = np.asarray(spec.reflectors_flange_m, float)
    m = refl.shape[0]
    lp_f = np.asarray(spec.load_point_flange_m, float)
    T0 = fk(robot, q)  # (P, 4, 4)
    force = np.zeros((P, S, 3))
    xyz = np.zeros((P, S, m, 3))
    dq_all = np.zeros((P, S, robot.n_joints))
    load_point = np.einsum("pij,j->pi", T0[:, :3, :3], lp_f) + T0[:, :3, 3]
    refl_h = np.concatenate([refl, np.ones((m, 1))], axis=1)
    for p in range(P):
        if spec.force_directions is None:
            d = -T0[p, :3, 2]  # pushes back along -tool z
        else:
            d = np.asarray(spec.force_directions[p], float)
            d = d / np.linalg.norm(d)
        for s in range(S):
            F = mags[s] * d + 0.0  # no negative zeros in the CSV
            force[p, s] = F
            dq = np.zeros(robot.n_joints) if mags[s] == 0 else deflect(robot, q[p], k, F, lp_f)
            dq_all[p, s] = dq
            T = fk(robot, q[p] + dq)
            xyz[p, s] = (refl_h @ T.T)[:, :3]
    return {
        "robot": robot,
        "q_rad": q,
        "force_N": force,
        "load_point_m": load_point,
        "xyz_m": xyz,
        "sigma_m": spec.noise.sigma(xyz),
        "dq_rad": dq_all,
        "pressure": None if spec.pressures_MPa is None else np.asarray(spec.pressures_MPa, float),
    }


def campaign_from_arrays(clean: dict[str, Any], xyz_m: np.ndarray, *, source: str,
                         truth: dict[str, Any] | None = None) -> Campaign:
    """Flatten structured arrays (P, S, m, ...) into a contract-layout :class:`Campaign`."""
    q = clean["q_rad"]
    P, S, m, _ = xyz_m.shape
    pi, si, ri = np.meshgrid(np.arange(P), np.arange(S), np.arange(m), indexing="ij")
    pi, si, ri = pi.ravel(), si.ravel(), ri.ravel()
    pressure = clean["pressure"]
    return Campaign(
        posture=tuple(str(p + 1) for p in pi),
        load_step=si.astype(np.int64),
        q_deg=np.degrees(q[pi]),
        force_N=clean["force_N"][pi, si],
        load_point_m=clean["load_point_m"][pi],
        reflector=tuple(f"R{r + 1}" for r in ri),
        xyz_m=xyz_m.reshape(-1, 3).copy(),
        pressure_MPa=None if pressure is None else pressure[si].astype(float),
        source=source,
        truth=truth,
    )


def simulate_campaign(spec: CampaignSpec | None = None,
                      rng: np.random.Generator | int | None = None) -> Campaign:
    """A virtual (SYNTHETIC) campaign: exact reflector positions + tracker noise.

    ``rng`` (Generator or seed) defaults to ``spec.seed``. ``Campaign.truth`` carries the
    ground truth (not written to the CSV).
    """
    spec = spec or CampaignSpec()
    clean = simulate_clean(spec)
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(
        spec.seed if rng is None else rng)
    noisy = clean["xyz_m"] + gen.standard_normal(clean["xyz_m"].shape) * clean["sigma_m"][..., None]
    truth = {
        "synthetic": True,
        "joint_stiffness_Nm_per_rad": list(spec.joint_stiffness_Nm_per_rad),
        "spec": spec.to_dict(),
    }
    return campaign_from_arrays(clean, noisy, source="<virtual campaign>", truth=truth)


def noisy_batch(clean: dict[str, Any], n_repeats: int, rng: np.random.Generator | int
                ) -> np.ndarray:
    """``n_repeats`` noisy copies of the reflector positions, (B, N_rows, 3), row order of
    :func:`campaign_from_arrays` (vectorised Monte Carlo for coverage studies)."""
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    xyz = clean["xyz_m"]
    noise = gen.standard_normal((n_repeats, *xyz.shape)) * clean["sigma_m"][None, ..., None]
    return (xyz[None] + noise).reshape(n_repeats, -1, 3)


def parse_vectors(text: str, option: str, unit: str) -> tuple[tuple[float, float, float], ...]:
    """Parse "x,y,z; x,y,z; ..." (CLI) into 3-vectors; ConfigError naming the option."""
    out = []
    for part in [p for p in text.split(";") if p.strip()]:
        try:
            v = tuple(float(x) for x in part.split(","))
        except ValueError:
            raise ConfigError("not a list of numbers", field=option, value=part,
                              expected=f"'x,y,z; x,y,z; ...' in {unit}") from None
        if len(v) != 3 or not all(math.isfinite(x) for x in v):
            raise ConfigError("each vector needs 3 finite numbers", field=option, value=part,
                              expected=f"'x,y,z; x,y,z; ...' in {unit}")
        out.append(v)
    if not out:
        raise InputError("no vectors given", field=option, expected=f"'x,y,z; ...' in {unit}")
    return tuple(out)  # type: ignore[return-value]


__all__ = [
    "IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD",
    "PAPER_POSTURE_DEG",
    "DEFAULT_POSTURES_DEG",
    "PAPER_PRESSURES_MPA",
    "TrackerNoise",
    "collinear",
    "Campaign",
    "CampaignSpec",
    "pressure_foot_spec",
    "simulate_clean",
    "simulate_campaign",
    "campaign_from_arrays",
    "noisy_batch",
    "deflect",
]
