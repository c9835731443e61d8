"""Boring insert and chip geometry: chip area and local uncut chip thickness along the edge.

Method after Atabey, Lazoglu & Altintas (2003) "Mechanics of boring processes - Part I",
IJMTM 43:463-476, and the edge discretisation of Kaymakci, Kilic & Altintas (2012) "Unified
cutting force model for turning, boring, drilling and milling operations", IJMTM 54-55:34-45.

Tool-profile coordinates (the plane through the bore axis that contains the tool tip):
``zeta`` [m] along the feed (bore axis, +zeta towards the uncut material) measured from the
tool tip, ``drop`` [m] radially inwards from the tip radius ``R = D/2``. The edge profile,
parametrised by arc length ``s`` from the tip (``s > 0`` on the leading/major side):

* nose arc (``-r kappa' <= s <= r kappa``): local approach angle ``psi = s / r``,
  ``zeta = r sin psi``, ``drop = r (1 - cos psi)``;
* major (lead) edge beyond it, at the approach angle ``kappa`` to the feed axis (up to
  :data:`robobore.io.sections.APPROACH_ANGLE_MAX_DEG`; above 90 deg the edge is undercut:
  it runs back against the feed as it goes outwards, as on 93 .. 107.5 deg boring bars and
  copying tools);
* minor (end) edge on the trailing side at the end-cutting-edge angle ``kappa'``.

Chip of a steady pass with feed ``f`` per revolution (per insert) and radial depth ``ap``
(pre-bore radius ``R - ap``): the material between the current profile, the profile of the
previous pass (shifted by ``-f``) and the pre-bore surface. Its exact area is
``A = integral_0^ap min(f, w(d)) dd`` where ``w(d)`` is the width of the profile at drop
``d``; hence ``A = ap f - A_scallop`` where ``A_scallop`` is the cusp area the nose leaves
on the bore (``~ f^3 / (12 r)`` when the feed is inside the nose). ``A = ap f`` is the
textbook value when the scallop is negligible. For an undercut edge (``kappa > 90 deg``) the
profile is not a function of ``zeta`` (the major edge runs back behind the nose's axial
extreme ``zeta = r``), so the area and the scallop are computed by radial levels: at drop
``d`` the tool spans ``[a(d), b(d)]`` (trailing and leading edge), each pass removes
``min(f, w(d))`` with ``w = b - a``, and a gap ``f - w(d)`` stays where the tool is narrower
than the feed (the cusp between the minor edge and the previous pass's major edge).
:meth:`BoringInsert.drop` is then the profile's lower envelope (the nose arc up to ``zeta =
r``), used for the trailing-side contact; it is exact while the cusp stays within the nose
(``f`` below about ``r``).

Edge elements: the leading edge from the tip to the pre-bore surface is cut into ``n``
elements of equal arc length ``dS = db``; each element takes the chip slices at the radial
levels it spans (see :func:`edge_elements`), so ``h = f sin(kappa_local)`` where the chip is
fully covered and ``sum(h db)`` is the exact chip area. The engaged edge also runs back over
the trailing side of the nose, from the tip to the point ``zeta_i < 0`` where the current
profile meets the previous pass's (``drop(zeta_i) = min(ap, drop(zeta_i + f))``; ``-f/2`` on a
pure arc). The chip there is a thin sliver that the radial-level attribution gives to the
leading side, so those *trailing* elements carry no chip (``h = db = 0``) but their edge length
``dS`` and local orientation ``kappa < 0``: the edge (ploughing/rubbing) force acts over the
whole engaged edge (Kaymakci et al. 2012: edge forces integrated from the intersection with the
previous pass to the depth-of-cut end).

The edge profile (``edge_point``), the profile width (``profile_width``) and the
elements (``element_pass``) are compiled scalar functions
(:mod:`robobore.cutting.edge_kernels`): :meth:`BoringInsert.point`,
the areas by radial levels and :func:`edge_elements` call them, and the boring process of the
dynamics (:func:`robobore.dynamics.process.boring_process`) is built from :func:`edge_elements`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from robobore.cutting.edge_kernels import edge_points, element_pass, profile_widths
from robobore.errors import ConfigError
from robobore.io.sections import (
    CLEARANCE_MAX_DEG,
    EDGE_RADIUS_MAX_UM,
    END_EDGE_ANGLE_MAX_DEG,
    INCLINATION_MAX_DEG,
    NOSE_RADIUS_MAX_MM,
    RAKE_MAX_DEG,
    check_approach_angle,
)


def _check(name: str, value: float, lo: float, hi: float, unit: str, lo_open: bool = False) -> None:
    ok = math.isfinite(value) and (value > lo if lo_open else value >= lo) and value <= hi
    if not ok:
        br = "(" if lo_open else "["
        raise ConfigError("out of range", field=name, value=value,
                          expected=f"a value in {br}{lo}, {hi}] {unit}")


@dataclass(frozen=True)
class BoringInsert:
    """Boring insert geometry (SI: metres, angles in degrees as named).

    ``approach_angle_deg`` (kappa_r) is the angle between the major cutting edge and the feed
    axis (90 deg: edge perpendicular to the bore axis; up to 107.5 deg, undercut); the lead
    angle is 90 - kappa_r. The insert's included angle ``180 - kappa_r - end_edge_angle`` must
    be positive.
    ``end_edge_angle_deg`` is the minor (end) cutting edge angle. ``rake_deg`` is the normal
    rake, ``inclination_deg`` the cutting-edge inclination, ``clearance_deg`` the relief angle,
    ``edge_radius_m`` the cutting-edge (hone) radius, ``n_inserts`` the number of inserts on
    the bar (equally spaced).
    """

    nose_radius_m: float = 0.4e-3
    approach_angle_deg: float = 90.0
    end_edge_angle_deg: float = 5.0
    rake_deg: float = 7.0
    inclination_deg: float = 0.0
    clearance_deg: float = 7.0
    edge_radius_m: float = 20e-6
    n_inserts: int = 1

    def __post_init__(self) -> None:
        # the bounds of the [insert] section (robobore.io.sections), in SI
        _check("insert.nose_radius_m", self.nose_radius_m, 0.0, NOSE_RADIUS_MAX_MM * 1e-3, "m",
               lo_open=True)
        check_approach_angle(self.approach_angle_deg)
        if not (math.isfinite(self.end_edge_angle_deg)
                and 0.0 < self.end_edge_angle_deg < END_EDGE_ANGLE_MAX_DEG):
            raise ConfigError("out of range", field="insert.end_edge_angle_deg",
                              value=self.end_edge_angle_deg,
                              expected=f"a value in (0, {END_EDGE_ANGLE_MAX_DEG:g}) deg")
        if self.approach_angle_deg + self.end_edge_angle_deg >= 180.0:
            raise ConfigError("no insert: approach angle + end-edge angle >= 180 deg",
                              field="insert.end_edge_angle_deg", value=self.end_edge_angle_deg,
                              expected=f"< {180.0 - self.approach_angle_deg:g} deg (a positive "
                              "included angle)")
        _check("insert.rake_deg", self.rake_deg, -RAKE_MAX_DEG, RAKE_MAX_DEG, "deg")
        _check("insert.inclination_deg", self.inclination_deg, -INCLINATION_MAX_DEG,
               INCLINATION_MAX_DEG, "deg")
        _check("insert.clearance_deg", self.clearance_deg, 0.0, CLEARANCE_MAX_DEG, "deg")
        _check("insert.edge_radius_m", self.edge_radius_m, 0.0, EDGE_RADIUS_MAX_UM * 1e-6, "m")
        if int(self.n_inserts) != self.n_inserts or not 1 <= self.n_inserts <= 12:
            raise ConfigError("out of range", field="insert.n_inserts", value=self.n_inserts,
                              expected="an integer in [1, 12]")

    # -- profile -------------------------------------------------------------------------
    @property
    def kappa(self) -> float:
        return math.radians(self.approach_angle_deg)

    @property
    def kappa_end(self) -> float:
        return math.radians(self.end_edge_angle_deg)

    @property
    def zeta_max(self) -> float:
        """Axial extent of the profile ahead of the tip [m]: where the nose arc meets the
        major edge (``r sin kappa``), or the arc's extreme ``r`` for ``kappa >= 90 deg``."""
        r, k = self.nose_radius_m, self.kappa
        return r if k >= math.pi / 2 - 1e-12 else r * math.sin(k)

    def drop(self, zeta: np.ndarray) -> np.ndarray:
        """Radial drop of the profile's lower envelope below the tip [m] at axial offsets
        ``zeta`` [m] (the surface a pass leaves; inf ahead of the tool for kappa >= 90 deg)."""
        z = np.asarray(zeta, float)
        r, k, ke = self.nose_radius_m, self.kappa, self.kappa_end
        s_maj, s_min = self.zeta_max, r * math.sin(ke)
        out = np.empty_like(z)
        arc = (z >= -s_min) & (z <= s_maj)
        out[arc] = r - np.sqrt(np.maximum(r * r - z[arc] ** 2, 0.0))
        lead = z > s_maj
        if k >= math.pi / 2 - 1e-12:
            out[lead] = np.inf
        else:
            out[lead] = r * (1 - math.cos(k)) + (z[lead] - s_maj) * math.tan(k)
        trail = z < -s_min
        out[trail] = r * (1 - math.cos(ke)) + (-z[trail] - s_min) * math.tan(ke)
        return out

    def point(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Edge point at arc length ``s`` [m] from the tip.

        Returns ``(zeta, drop, kappa_local, curvature)``: position [m], local approach angle
        [rad] (positive on the major side, negative on the minor side) and curvature [1/m]
        (``edge_kernels.edge_point``: nose arc ``-r kappa' <= s <= r kappa``, the straight major edge
        beyond ``r kappa``, the straight minor edge beyond ``-r kappa'``).
        """
        s = np.asarray(s, float)
        r, k, ke = self.nose_radius_m, self.kappa, self.kappa_end
        flat = np.ascontiguousarray(s).reshape(-1)
        zeta, drop, kl = np.empty_like(flat), np.empty_like(flat), np.empty_like(flat)
        edge_points(flat, r, k, ke, zeta, drop, kl)
        curv = np.where((s >= -r * ke) & (s <= r * k), 1.0 / r, 0.0)
        return zeta.reshape(s.shape), drop.reshape(s.shape), kl.reshape(s.shape), curv

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> BoringInsert:
        return cls(**d)


@dataclass(frozen=True)
class EdgeElements:
    """Engaged edge discretised into elements (structure of arrays, all shape ``(n,)``).

    ``s`` arc-length position of the element centre [m] (negative on the trailing side);
    ``zeta``, ``drop`` its profile position [m]; ``kappa`` local approach angle [rad] (negative
    on the trailing side); ``h`` local uncut chip thickness [m]; ``db`` chip width [m]; ``dS``
    edge length [m]. ``area`` is the exact chip area [m^2] (1-D integral), ``area_elements`` =
    ``sum(h db)``. Every element is engaged edge: the first ``n_trailing`` elements (ordered by
    ``s``, from the intersection with the previous pass at ``trailing_end_zeta_m`` to the tip)
    only rub (``h = db = 0``, edge forces only); the others cut the chip.
    """

    s: np.ndarray
    zeta: np.ndarray
    drop: np.ndarray
    kappa: np.ndarray
    h: np.ndarray
    db: np.ndarray
    dS: np.ndarray
    area: float
    area_elements: float
    depth_m: float
    feed_m: float
    n_trailing: int = 0
    trailing_end_zeta_m: float = 0.0

    @property
    def n(self) -> int:
        return int(self.s.size)

    @property
    def trailing(self) -> np.ndarray:
        """Mask of the trailing (rubbing-only) elements, shape ``(n,)``."""
        return np.arange(self.n) < self.n_trailing

    @property
    def engaged_length(self) -> float:
        """Total engaged edge length [m] (leading + trailing side)."""
        return float(self.dS.sum())

    @property
    def trailing_length(self) -> float:
        """Engaged edge length on the trailing side of the nose [m]."""
        return float(self.dS[: self.n_trailing].sum())

    @property
    def leading_length(self) -> float:
        """Engaged edge length on the leading (chip-cutting) side [m]."""
        return float(self.dS[self.n_trailing:].sum())

    @property
    def equivalent_approach_angle(self) -> float:
        """Chip-area weighted mean local approach angle [rad] (equivalent straight edge)."""
        w = self.h * self.db
        return float((w * self.kappa).sum() / w.sum())

    def to_dict(self) -> dict[str, Any]:
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                for k, v in self.__dict__.items()}


def _prev_surface_drop(insert: BoringInsert, zeta: np.ndarray, feed: float, depth: float):
    """Drop of the surface the current pass meets: min(ap, previous-pass profile)."""
    return np.minimum(depth, insert.drop(zeta + feed))


def chip_area(insert: BoringInsert, depth_m: float, feed_m: float, n_grid: int = 20001) -> float:
    """Exact steady chip area [m^2] for radial depth ``depth_m`` and feed ``feed_m`` per insert.

    ``A = integral over zeta of max(0, min(ap, drop(zeta + f)) - drop(zeta))`` on a dense grid
    (trapezoid; the integrand is continuous, error O(grid^2)).
    """
    _check("depth_m", depth_m, 0.0, 0.05, "m", lo_open=True)
    _check("feed_m", feed_m, 0.0, 0.01, "m", lo_open=True)
    if insert.kappa > math.pi / 2:
        return _level_area(insert, depth_m, feed_m, n_grid)
    r = insert.nose_radius_m
    s_maj, s_min = insert.zeta_max, r * math.sin(insert.kappa_end)
    # front of the envelope: an undercut edge deeper than r lies behind the arc's extreme
    undercut = insert.kappa > math.pi / 2 and depth_m >= r
    z_hi = s_maj if undercut else lead_end(insert, depth_m)
    # piecewise over the profile's corners (the integrand jumps at s_maj - f when kappa = 90)
    cuts = [-feed_m, z_hi]
    for b in (-s_min, s_maj, -s_min - feed_m, s_maj - feed_m, 0.0, -feed_m / 2):
        if -feed_m < b < z_hi:
            cuts.append(b)
    cuts = sorted(set(cuts))
    n_seg = max(200, n_grid // len(cuts))
    total = 0.0
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        z = np.linspace(np.nextafter(a, b), np.nextafter(b, a), n_seg)
        g = np.maximum(_prev_surface_drop(insert, z, feed_m, depth_m) - insert.drop(z), 0.0)
        total += float(np.trapezoid(g, z))
    return total


def _level_area(insert: BoringInsert, depth_m: float, feed_m: float, n_grid: int) -> float:
    """``integral_0^ap min(f, w(d)) dd`` [m^2], piecewise between the profile's corners and
    the level where ``w(d) = f`` (``w`` grows with ``d`` for a positive included angle)."""
    r = insert.nose_radius_m
    cuts = {0.0, depth_m}
    for b in (r * (1 - math.cos(insert.kappa)), r * (1 - math.cos(insert.kappa_end))):
        if 0.0 < b < depth_m:
            cuts.add(b)
    if _width_at_drop(insert, np.array([depth_m]))[0] > feed_m:
        dc = float(_bisect(lambda d: feed_m - _width_at_drop(insert, d), np.zeros(1),
                           np.full(1, depth_m), iters=80)[0])
        if 0.0 < dc < depth_m:
            cuts.add(dc)
    cuts_l = sorted(cuts)
    n_seg = max(200, n_grid // len(cuts_l))
    total = 0.0
    for a, b in zip(cuts_l[:-1], cuts_l[1:], strict=True):
        d = np.linspace(a, b, n_seg)
        total += float(np.trapezoid(np.minimum(feed_m, _width_at_drop(insert, d)), d))
    return total


def scallop_area(insert: BoringInsert, feed_m: float, n_grid: int = 20001) -> float:
    """Area [m^2] of one cusp left on the bore by the nose (per feed period)."""
    if insert.kappa > math.pi / 2:  # by radial levels: the gaps f - w(d) where w < f
        d_hi = float(_bisect(lambda d: feed_m - _width_at_drop(insert, d), np.zeros(1),
                             np.full(1, 0.05), iters=80)[0])
        return d_hi * feed_m - _level_area(insert, d_hi, feed_m, n_grid)
    z = np.linspace(-feed_m, 0.0, n_grid)
    g = np.minimum(insert.drop(z), insert.drop(z + feed_m))
    return float(np.trapezoid(g, z))


def lead_end(insert: BoringInsert, depth: float) -> float:
    """zeta [m] where the leading edge reaches the pre-bore surface (drop = ap); for an
    undercut edge (kappa > 90 deg) this lies behind the arc's extreme ``r``."""
    r, k = insert.nose_radius_m, insert.kappa
    d_arc = r * (1 - math.cos(k))
    if depth <= d_arc:
        return math.sqrt(max(r * r - (r - depth) ** 2, 0.0))
    if math.isclose(k, math.pi / 2):
        return r
    return r * math.sin(k) + (depth - d_arc) / math.tan(k)


def _s_of_drop_lead(insert: BoringInsert, depth: float) -> float:
    r, k = insert.nose_radius_m, insert.kappa
    d_arc = r * (1 - math.cos(k))
    if depth <= d_arc:
        return r * math.acos(1 - depth / r)
    return r * k + (depth - d_arc) / math.sin(k)


def _bisect(fun, lo: np.ndarray, hi: np.ndarray, iters: int = 60) -> np.ndarray:
    """Vectorised bisection for a root of ``fun`` with fun(lo) > 0 >= fun(hi)."""
    lo = np.array(lo, float)
    hi = np.array(hi, float)
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        pos = fun(mid) > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    return 0.5 * (lo + hi)


def _width_at_drop(insert: BoringInsert, d: np.ndarray) -> np.ndarray:
    """Width ``w(d) = b(d) - a(d)`` [m] of the tool profile at drop ``d`` [m]
    (``edge_kernels.profile_width``)."""
    d = np.asarray(d, float)
    flat = np.ascontiguousarray(d).reshape(-1)
    out = np.empty_like(flat)
    profile_widths(flat, insert.nose_radius_m, insert.kappa, insert.kappa_end,
                    math.isclose(insert.kappa, math.pi / 2), out)
    return out.reshape(d.shape)


def trailing_intersection(insert: BoringInsert, depth_m: float, feed_m: float) -> float:
    """zeta [m] (< 0) where the engaged edge ends on the trailing side of the nose.

    The root of ``g(zeta) = min(ap, drop(zeta + f)) - drop(zeta)`` on ``(-f, 0)``: from the tip
    back to it the current profile lies below the surface left by the previous pass (or the
    pre-bore surface), so the edge is in contact. ``g`` falls strictly from ``g(0) > 0`` to
    ``g(-f) < 0`` (``drop`` grows away from the tip on both sides), so the root is unique;
    bisection to ``f 2^-80``. Works on the nose arc (``-f/2`` for a pure arc) and on the
    straight minor edge beyond it (large feed or small end-edge angle).
    """
    _check("depth_m", depth_m, 0.0, 0.05, "m", lo_open=True)
    _check("feed_m", feed_m, 0.0, 0.01, "m", lo_open=True)
    # the root without the pre-bore surface is the root with it wherever the previous pass
    # lies inside the material there (drop(z + f) <= ap): the depth then does not enter
    z = _trailing_root(insert, float(feed_m), math.inf)
    if float(insert.drop(np.array([z + feed_m]))[0]) <= depth_m:
        return z
    return _trailing_root(insert, float(feed_m), float(depth_m))


@functools.lru_cache(maxsize=1024)
def _trailing_root(insert: BoringInsert, feed_m: float, depth_m: float) -> float:
    def g(z: np.ndarray) -> np.ndarray:
        return _prev_surface_drop(insert, z, feed_m, depth_m) - insert.drop(z)

    return float(_bisect(g, np.zeros(1), np.full(1, -feed_m), iters=80)[0])


def _s_of_zeta_trail(insert: BoringInsert, zeta: float) -> float:
    """Arc length s [m] (<= 0) of the trailing-side profile point at axial offset ``zeta <= 0``."""
    r, ke = insert.nose_radius_m, insert.kappa_end
    z = -zeta
    if z <= r * math.sin(ke):
        return -r * math.asin(min(z / r, 1.0))
    return -(r * ke + (z - r * math.sin(ke)) / math.cos(ke))


def _trailing_split(insert: BoringInsert, s_i: float, n: int) -> tuple[int, int]:
    """Elements ``(n_str, n_arc)`` of the trailing side from ``s_i < 0`` to the tip on the
    straight minor edge and on the arc: the arc / minor-edge corner is a node (so every element
    has one orientation law), each piece gets elements by its length."""
    s_corner = -insert.nose_radius_m * insert.kappa_end
    if s_i < s_corner:
        L_str, L_arc = s_corner - s_i, -s_corner
        n_str = max(1, round(n * L_str / (L_str + L_arc)))
        return n_str, max(1, n - n_str)
    return 0, n


@functools.lru_cache(maxsize=8)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1] (computed once per order)."""
    return np.polynomial.legendre.leggauss(n)


def edge_elements(insert: BoringInsert, depth_m: float, feed_m: float,
                  n_elements: int = 40, n_quad: int = 16, trailing_edge: bool = True,
                  n_trailing: int | None = None, exact_area: bool = True) -> EdgeElements:
    """Discretise the engaged edge for depth ``depth_m`` [m] and feed per insert ``feed_m`` [m].

    The chip is attributed to the edge by radial levels ``d`` (slices at constant radius): the
    slice of the chip at level ``d`` has axial length ``min(f, w(d))`` and is bounded ahead by
    the leading side of the current profile, which therefore cuts it. An element between
    levels ``d1 < d2`` of the leading edge (from the tip to the pre-bore surface) has area
    ``integral min(f, w(d)) dd`` (``n_quad``-point Gauss-Legendre) and local thickness
    ``h = area / dS``; on a fully covered straight edge this is ``h = f sin(kappa)``
    (Kaymakci et al. 2012) and ``sum(h db)`` equals the exact chip area. Works for depths
    inside the nose radius (only the arc cuts) and beyond it (the major edge cuts too).
    ``n_elements`` is the number of these leading (chip-cutting) elements.

    ``trailing_edge`` (default True): also the trailing side of the nose from the tip back to
    :func:`trailing_intersection` (where the current profile meets the previous pass's), which
    is in contact with the work and carries edge (ploughing) forces but, by the radial-level
    attribution, no chip: ``n_trailing`` elements (default: in proportion to its length
    relative to the leading edge, at least 1; the arc / minor-edge corner is an element
    boundary) with ``h = db = 0``, their length ``dS`` and local approach angle ``kappa < 0``.
    They come first (ordered by ``s``); the chip-area identity is unchanged.
    ``exact_area=False`` skips the separate exact integral (:func:`chip_area`): ``area`` is
    then ``area_elements``, for callers that use only the elements.
    """
    _check("depth_m", depth_m, 0.0, 0.05, "m", lo_open=True)
    _check("feed_m", feed_m, 0.0, 0.01, "m", lo_open=True)
    if int(n_elements) != n_elements or n_elements < 1:
        raise ConfigError("need at least one element", field="n_elements", value=n_elements,
                          expected="an integer >= 1")
    if n_trailing is not None and (int(n_trailing) != n_trailing or n_trailing < 1):
        raise ConfigError("need at least one trailing element", field="n_trailing",
                          value=n_trailing, expected="an integer >= 1 (or None: automatic)")
    s_end = _s_of_drop_lead(insert, depth_m)
    n = int(n_elements)
    s_i, n_str, n_arc, z_i = 0.0, 0, 0, 0.0
    if trailing_edge:
        z_i = trailing_intersection(insert, depth_m, feed_m)
        s_i = _s_of_zeta_trail(insert, z_i)
        n_auto = max(1, round(n * (-s_i) / s_end))
        n_str, n_arc = _trailing_split(insert, s_i, int(n_trailing or n_auto))
    n_tr = n_str + n_arc
    E = n + n_tr
    out = np.empty((7, E))
    quad = np.ascontiguousarray(np.vstack(_gauss_legendre(int(n_quad))))
    r, k = insert.nose_radius_m, insert.kappa
    area_elements = element_pass((r, k, insert.kappa_end, math.isclose(k, math.pi / 2)),
                                  float(depth_m), float(feed_m), float(s_end), float(s_i),
                                  (n, n_str, n_arc), quad, out)
    s, zeta, drop, kl, h, db, dS = out
    area = chip_area(insert, depth_m, feed_m) if exact_area else area_elements
    return EdgeElements(s=s, zeta=zeta, drop=drop, kappa=kl, h=h, db=db, dS=dS,
                        area=area, area_elements=area_elements, depth_m=float(depth_m),
                        feed_m=float(feed_m), n_trailing=int(n_tr), trailing_end_zeta_m=z_i)


__all__ = ["BoringInsert", "EdgeElements", "chip_area", "scallop_area", "edge_elements", "lead_end",
           "trailing_intersection"]
