"""Linear cutting-process description shared by the time-domain simulation and the lobes.

The process is a set of cutting "elements" (the edge elements of a boring insert, or one
element for the general single-point case), each described in a basis ``B(theta)`` whose rows
are three unit vectors of the boring frame:

* boring bar (``rotating=True``): ``B = (e_t, e_r, e_z)`` with ``e_t = (-sin t, cos t, 0)`` the
  velocity direction of the insert, ``e_r = (cos t, sin t, 0)`` outward radial and ``e_z`` the
  feed (bore axis); ``theta`` is the bar angle from X towards Y;
* single-point cutting with fixed directions (``rotating=False``): ``B = I`` (X, Y, Z).

For element ``e`` at depth of cut ``a`` (per unit depth widths ``w_e``, edge lengths ``s_e``,
depth-independent edge lengths ``l_e``)::

    h_e  = p h0_e - n_e . B (r(t) - mu r_s)        (p: passes since the surface at this angle
                                                    was cut; r_s: tool displacement then)
    F    = B^T sum_e [ shear_e h_e w_e a g  (if h_e > 0)
                       + edge_e (s_e a g + l_e)  (while the insert cuts at all) ]
    g    = max(0, 1 + dd . B r / a)                 (depth modulation against the pre-bore
                                                    surface; dd = 0 for the general case)

``l_e`` (``edge_fixed_m``) is the engaged edge on the trailing side of the nose: its length is
set by the feed (where the nose meets the previous pass), not by the depth, so it neither
stretches with the simulated depth nor enters the depth-modulation stiffness. Those elements
have ``h0 = w = 0``: they rub (edge force) but carry no chip and no regeneration.

One linearised model at every depth: a boring process remembers how it was built
(``geometry``: insert, coefficients, feed and options, :class:`BoringGeometry`), and
:meth:`CuttingProcess.at_depth` rebuilds it from the chip geometry at another depth of cut.
The time-domain simulation integrates the process built at its own depth; the lobes
(semi-discretisation, frequency domain) and the mode-coupling limit judge each trial depth
``a`` with ``process.at_depth(a)``, so a nose-radius insert, whose engaged edge, local
approach angles and chip thicknesses change with the depth, is judged on the same chip at the
same depth by every method. A process without ``geometry`` (the single-point contract, whose
force is linear in the depth) is the same at every depth.

``n_e`` (chip normal: a tool displacement along it REDUCES the chip), ``shear_e`` [N/m^2] and
``edge_e`` [N/m] are basis coordinates; forces are ON THE TOOL; ``mu`` is the overlap factor
(1: full regeneration). The general contract (``[process]`` of the TOML) is one element with
``n = chip_normal``, ``shear = K u`` (``u = force_direction``), ``h0 = feed``, ``w = 1``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import math

import numba as nb
import numpy as np

from robobore.cutting.forces import CuttingCoefficients
from robobore.cutting.geometry import BoringInsert, edge_elements
from robobore.errors import ConfigError


@dataclass(frozen=True)
class BoringGeometry:
    """What a boring process is built from (:func:`boring_process`'s arguments but the depth),
    so that :meth:`CuttingProcess.at_depth` can rebuild the process at any depth of cut."""

    insert: BoringInsert
    coefficients: CuttingCoefficients
    feed_per_rev_m: float
    n_elements: int = 24
    overlap: float = 1.0
    depth_modulation: bool = True
    min_chip_thickness_m: float | None = None
    trailing_edge: bool = True


@dataclass(frozen=True)
class CuttingProcess:
    """Structure-of-arrays process model (see module docstring). Shapes: (E,), (E, 3), (3,)."""

    rotating: bool
    n_inserts: int
    h0: np.ndarray
    width_per_depth: np.ndarray
    edge_per_depth: np.ndarray
    normal: np.ndarray
    shear: np.ndarray
    edge: np.ndarray
    depth_direction: np.ndarray
    overlap: float = 1.0
    feed_per_rev_m: float = 0.0
    reference_depth_m: float | None = None
    label: str = ""
    edge_fixed_m: np.ndarray | None = None
    geometry: BoringGeometry | None = None
    #: derived quantities kept with the process: the processes at other depths
    #: (:meth:`at_depth`) and the steady deflections of the lobes; not part of its value
    memo: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        E = int(np.asarray(self.h0).size)
        if self.edge_fixed_m is None:
            object.__setattr__(self, "edge_fixed_m", np.zeros(E))
        else:
            lf = np.asarray(self.edge_fixed_m, float)
            if lf.shape != (E,) or not np.all(np.isfinite(lf)) or np.any(lf < 0):
                raise ConfigError("depth-independent edge lengths must be one finite length "
                                  ">= 0 per element", field="edge_fixed_m",
                                  value=lf.tolist() if lf.size < 10 else f"shape {lf.shape}",
                                  expected=f"{E} lengths >= 0 in m")
            object.__setattr__(self, "edge_fixed_m", lf)

    @property
    def n_elements(self) -> int:
        return int(self.h0.size)

    @property
    def depth_dependent(self) -> bool:
        """True when the process changes with the depth of cut beyond the linear scaling of
        its widths (a boring insert, rebuilt from its chip geometry at each depth)."""
        return self.geometry is not None

    def at_depth(self, depth_m: float) -> CuttingProcess:
        """The process linearised at depth of cut ``depth_m`` [m]: rebuilt from the chip
        geometry (:func:`boring_process` with the same insert, coefficients, feed and options)
        for a boring process, ``self`` for a process without geometry or at its own depth.
        Processes are cached per depth (12 significant digits)."""
        g = self.geometry
        a = float(depth_m)
        if g is None or not (math.isfinite(a) and a > 0.0):
            return self
        ref = self.reference_depth_m
        if ref is not None and abs(a - ref) <= 1e-12 * ref:
            return self
        key = float(f"{a:.12g}")
        hit = self.memo.get(key)
        if hit is None:
            if len(self.memo) > 4096:
                self.memo.clear()
            hit = _boring_process(g.insert, g.coefficients, key, g.feed_per_rev_m,
                                  g.n_elements, g.overlap, g.depth_modulation,
                                  g.min_chip_thickness_m, g.trailing_edge, g, self.label)
            self.memo[key] = hit
        return hit

    def fixed(self) -> CuttingProcess:
        """The same process without its geometry: linearised once, at its reference depth,
        its widths scaled linearly with any other depth (the model of a straight edge)."""
        return replace(self, geometry=None, memo={})

    def basis(self, theta: np.ndarray) -> np.ndarray:
        """Basis matrices, shape (n, 3, 3): rows are the basis vectors in the boring frame."""
        th = np.atleast_1d(np.asarray(theta, float))
        B = np.zeros((th.size, 3, 3))
        if self.rotating:
            c, s = np.cos(th), np.sin(th)
            B[:, 0, 0], B[:, 0, 1] = -s, c
            B[:, 1, 0], B[:, 1, 1] = c, s
            B[:, 2, 2] = 1.0
        else:
            B[:] = np.eye(3)
        return B

    def directional_matrix(self, theta: np.ndarray,
                           insert_weights: np.ndarray | None = None) -> np.ndarray:
        """Regenerative directional matrix per unit depth [N/m^2], shape (n, 3, 3).

        Linearised about the nominal chip, all inserts summed (insert ``p`` at
        ``theta + 2 pi p / N``): ``dF = -a A(theta) (r(t) - mu r(t - tau))``,
        ``A = sum_p g_p B_p^T [sum_e w_e shear_e n_e^T] B_p`` with optional per-insert weights
        ``g_p`` (shape (n, N); e.g. the actual/nominal depth ratio along a deflected path).
        """
        th = np.atleast_1d(np.asarray(theta, float))
        core = np.einsum("e,ei,ej->ij", self.width_per_depth, self.shear, self.normal)
        A = np.zeros((th.size, 3, 3))
        for p in range(self.n_inserts):
            B = self.basis(th + 2 * np.pi * p / self.n_inserts)
            Ap = np.swapaxes(B, 1, 2) @ (core @ B)
            if insert_weights is not None:
                Ap = Ap * insert_weights[:, p, None, None]
            A += Ap
        return A

    def mean_directional_matrix(self, n_theta: int = 720) -> np.ndarray:
        """Zero-order (revolution-averaged) directional matrix [N/m^2], shape (3, 3)."""
        if not self.rotating:
            return self.directional_matrix(np.zeros(1))[0]
        th = np.linspace(0, 2 * np.pi, n_theta, endpoint=False)
        return self.directional_matrix(th).mean(axis=0)

    def process_stiffness(self, theta: np.ndarray) -> np.ndarray:
        """Non-regenerative stiffness from depth modulation [N/m], shape (n, 3, 3).

        ``dF = P(theta) r`` with
        ``P = sum_p B_p^T [sum_e (w_e h0_e shear_e + s_e edge_e)] dd^T B_p`` (per unit depth
        widths ``w_e`` and edge lengths ``s_e``; it does not scale with depth: the width
        change is the displacement itself). The depth-independent (trailing-side) edge
        lengths ``edge_fixed_m`` do not change with the depth and are not in ``P``."""
        th = np.atleast_1d(np.asarray(theta, float))
        vec = (np.einsum("e,e,ei->i", self.width_per_depth, self.h0, self.shear)
               + np.einsum("e,ei->i", self.edge_per_depth, self.edge))
        core = np.outer(vec, self.depth_direction)
        P = np.zeros((th.size, 3, 3))
        if not np.any(self.depth_direction):
            return P
        for p in range(self.n_inserts):
            B = self.basis(th + 2 * np.pi * p / self.n_inserts)
            P += np.swapaxes(B, 1, 2) @ (core @ B)
        return P

    def to_dict(self) -> dict[str, Any]:
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                for k, v in self.__dict__.items()
                if k not in ("geometry", "memo")}


def single_point_process(cutting_coefficient_N_per_m2: float, force_direction: np.ndarray,
                         chip_normal: np.ndarray, feed_per_rev_m: float,
                         n_inserts: int = 1, overlap: float = 1.0) -> CuttingProcess:
    """The general single-point contract: ``F = K a h u`` with ``h = f - n . (r - mu r_s)``."""
    u = np.asarray(force_direction, float)
    n = np.asarray(chip_normal, float)
    return CuttingProcess(
        rotating=False, n_inserts=int(n_inserts), h0=np.array([feed_per_rev_m / n_inserts]),
        width_per_depth=np.ones(1), edge_per_depth=np.zeros(1), normal=n[None, :],
        shear=(cutting_coefficient_N_per_m2 * u)[None, :], edge=np.zeros((1, 3)),
        depth_direction=np.zeros(3), overlap=float(overlap), feed_per_rev_m=feed_per_rev_m,
        reference_depth_m=None, label="single-point (fixed directions)")


def boring_process(insert: BoringInsert, coefficients: CuttingCoefficients, depth_m: float,
                   feed_per_rev_m: float, n_elements: int = 24, overlap: float = 1.0,
                   depth_modulation: bool = True,
                   min_chip_thickness_m: float | None = None,
                   trailing_edge: bool = True) -> CuttingProcess:
    """Rotating boring bar: edge elements of ``insert`` at depth ``depth_m`` (see
    :mod:`robobore.cutting.geometry`) with the mechanistic force model
    (:mod:`robobore.cutting.forces`). Element widths scale linearly with the simulated depth
    (uniform stretch of the engaged edge: exact on a straight edge, an approximation when the
    depth differs much from ``depth_m`` on the nose).

    Minimum chip thickness: elements whose nominal uncut chip thickness is below
    ``min_chip_thickness_m`` (default 0.25 x the edge radius; the minimum chip thickness is
    about 0.2-0.4 edge radii, Liu, DeVor & Kapoor 2006) plough rather than cut: they keep their
    edge (ploughing) force but carry no shearing force and no regeneration. Near the nose tip
    the nominal thickness tends to zero, and a linear model that kept those elements fully
    engaged would overstate the regenerative gain (the time domain drops them as soon as the
    tool vibrates).

    ``trailing_edge`` (default True): the engaged trailing side of the nose (from the tip to
    where the nose meets the previous pass, :func:`robobore.cutting.geometry.edge_elements`)
    adds rubbing elements: ``h0 = 0``, no chip width, their edge force (``Kte``, ``Kfe`` times
    the length, thrust normal to the local edge) on a length that does not scale with the
    depth (``edge_fixed_m``: set by the feed at the nominal cut; the vibration does not move
    the intersection point in this model). In the time domain they are switched with the
    insert like the other edge forces (on while any element cuts), never on their own
    ``h``; they add to the nominal force and the steady deflection, not to the regenerative
    directional matrix nor to the depth-modulation stiffness."""
    return _boring_process(insert, coefficients, depth_m, feed_per_rev_m, n_elements, overlap,
                           depth_modulation, min_chip_thickness_m, trailing_edge)


def _boring_process(insert: BoringInsert, coefficients: CuttingCoefficients, depth_m: float,
                    feed_per_rev_m: float, n_elements: int = 24, overlap: float = 1.0,
                    depth_modulation: bool = True, min_chip_thickness_m: float | None = None,
                    trailing_edge: bool = True, geometry: BoringGeometry | None = None,
                    label: str | None = None) -> CuttingProcess:
    """:func:`boring_process`; ``geometry`` and ``label``, where given, are those of a process
    of the same insert, coefficients, feed and options (:meth:`CuttingProcess.at_depth`).

    The elements are those of :func:`robobore.cutting.geometry.edge_elements` (with
    ``exact_area=False``, 16-point Gauss-Legendre chip areas); :func:`_process_arrays` forms
    the process arrays from them in one compiled pass."""
    fz = feed_per_rev_m / insert.n_inserts
    # edge_elements refuses a depth, feed per insert or element count out of range by name
    el = edge_elements(insert, depth_m, fz, n_elements, trailing_edge=trailing_edge,
                       exact_area=False)
    E = el.n
    hmin = 0.25 * insert.edge_radius_m if min_chip_thickness_m is None else min_chip_thickness_m
    c = coefficients
    wpd, epd, efix = np.empty(E), np.empty(E), np.empty(E)
    normal, shear, edge = np.empty((E, 3)), np.empty((E, 3)), np.empty((E, 3))
    _process_arrays(el.kappa, el.h, el.db, el.dS, el.n_trailing, float(depth_m), float(hmin),
                    np.array([c.Ktc, c.Krc, c.Kfc, c.Kte, c.Kre, c.Kfe], float),
                    wpd, epd, efix, normal, shear, edge)
    h0 = el.h
    if label is None:
        label = (f"boring bar, {insert.n_inserts} insert(s), nose {insert.nose_radius_m * 1e3:g} "
                 f"mm, kappa_r {insert.approach_angle_deg:g} deg")
    if geometry is None:
        geometry = BoringGeometry(insert, coefficients, float(feed_per_rev_m), int(n_elements),
                                  float(overlap), bool(depth_modulation), min_chip_thickness_m,
                                  bool(trailing_edge))
    # h0: the element's nominal thickness; per unit depth widths
    return CuttingProcess(
        rotating=True, n_inserts=insert.n_inserts, h0=h0, width_per_depth=wpd,
        edge_per_depth=epd, normal=normal, shear=shear, edge=edge,
        depth_direction=np.array([0.0, 1.0, 0.0]) if depth_modulation else np.zeros(3),
        overlap=float(overlap), feed_per_rev_m=feed_per_rev_m, reference_depth_m=depth_m,
        label=label, edge_fixed_m=efix, geometry=geometry)


@nb.njit(cache=True)
def _process_arrays(kl, h, db, dS, n_trailing, depth, hmin, K, wpd, epd, efix, normal, shear,
                    edge):  # pragma: no cover - numba
    """Process arrays of :func:`_boring_process` from the edge elements (local approach angle
    ``kl``, chip thickness ``h`` and width ``db``, edge length ``dS``; the first
    ``n_trailing`` rub only), in place: per unit depth chip widths (0 below ``hmin``) and edge
    lengths, the trailing side's edge lengths as depth-independent ``efix``, and each
    element's coefficients (:func:`_element_coefficients`). ``K``: Ktc, Krc, Kfc, Kte, Kre,
    Kfe."""
    for j in range(kl.size):
        wpd[j] = db[j] / depth if h[j] >= hmin else 0.0
        if j < n_trailing:
            epd[j] = 0.0
            efix[j] = dS[j]
        else:
            epd[j] = dS[j] / depth
            efix[j] = 0.0
        _element_coefficients(kl[j], K, normal[j], shear[j], edge[j])


@nb.njit(cache=True, inline="always")
def _element_coefficients(kl, K, normal, shear, edge):  # pragma: no cover - numba
    """Chip normal and shearing / edge force coefficients of an element of local approach
    angle ``kl`` in basis coordinates (t, r, z); the tangential force on the tool is
    ``-Ft e_t``."""
    sk, ck = math.sin(kl), math.cos(kl)
    normal[0], normal[1], normal[2] = 0.0, -ck, -sk
    shear[0], shear[1], shear[2] = -K[0], -K[2] * ck - K[1] * sk, -K[2] * sk + K[1] * ck
    edge[0], edge[1], edge[2] = -K[3], -K[5] * ck - K[4] * sk, -K[5] * sk + K[4] * ck


def tooth_period(speed_rpm: float, n_inserts: int) -> float:
    """Delay between successive inserts [s]: 60 / (N n)."""
    return 60.0 / (n_inserts * speed_rpm)


__all__ = ["CuttingProcess", "BoringGeometry", "single_point_process", "boring_process", "tooth_period"]
