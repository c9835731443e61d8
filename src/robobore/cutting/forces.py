"""Mechanistic edge-element force model for boring (Atabey, Lazoglu & Altintas 2003 type).

Per edge element (``robobore.cutting.geometry.EdgeElements``), with local uncut chip
thickness ``h``, chip width ``db`` and edge length ``dS``::

    dFt = Ktc h db + Kte dS      tangential (against the cutting velocity of the insert)
    dFf = Kfc h db + Kfe dS      thrust, normal to the local edge in the tool-profile plane
                                 (the orthogonal-cutting "feed/thrust" force; along the feed
                                 when the local approach angle is 90 deg)
    dFl = Krc h db + Kre dS      lateral, along the local edge towards its leading end
                                 (non-zero for inclined / oblique edges)

The thrust acts along the local chip-thickness direction ``(-sin k, -cos k)`` in (feed, radial)
coordinates, i.e. it is resolved by the local approach angle ``k`` into
``feed = -dFf sin k + dFl cos k`` and ``radial = -dFf cos k - dFl sin k`` (forces ON THE TOOL,
radial positive outwards). Every element is engaged edge and carries its edge forces
(``K*e dS``), including the rubbing-only elements on the trailing side of the nose
(``h = 0``, ``k < 0``; see :func:`robobore.cutting.geometry.edge_elements`): there the edge
normal leans the other way along the feed, so their thrust has a feed component of the
opposite sign (``-Kfe dS sin k > 0``) that partly cancels the leading side's.

The rotating-frame totals ``(F_tangential, F_radial, F_feed)`` go to the boring frame
(X horizontal, Y vertical, Z feed) with the bar's rotation angle ``theta`` (from X towards Y;
the insert moves along ``e_t = (-sin theta, cos theta, 0)``)::

    F = -Ft e_t(theta) + Fr e_r(theta) + Fz e_z

Coefficients (:class:`CuttingCoefficients`): shearing ``K*c`` in N/m^2, edge ``K*e`` in N/m.
Their files (TOML or JSON, per-speed fits) are read by
:mod:`robobore.cutting.coefficient_files`; the bundled TC4 sets and the orthogonal-to-oblique
transformation are in :mod:`robobore.cutting.coefficient_sets`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robobore.cutting.geometry import BoringInsert, EdgeElements, edge_elements
from robobore.errors import ConfigError
from robobore.io.ranges import check_value

_KEYS = {"Ktc": "Ktc_N_per_m2", "Krc": "Krc_N_per_m2", "Kfc": "Kfc_N_per_m2",
         "Kte": "Kte_N_per_m", "Kre": "Kre_N_per_m", "Kfe": "Kfe_N_per_m"}


@dataclass(frozen=True)
class CuttingCoefficients:
    """Linear edge-force model coefficients (shearing N/m^2, edge N/m) and their source."""

    Ktc: float
    Krc: float
    Kfc: float
    Kte: float = 0.0
    Kre: float = 0.0
    Kfe: float = 0.0
    provenance: str = "user"
    #: plain-language warnings on how the set was chosen (a cutting speed outside the
    #: calibrated speeds, a pooled set where per-speed fits exist); not part of the values
    warnings: tuple[str, ...] = field(default=(), compare=False)
    #: the cutting speed [m/min] a speed-dependent set was evaluated at (None: one set for
    #: every speed)
    speed_m_per_min: float | None = field(default=None, compare=False)
    #: the uncut chip thicknesses [m] the set was fitted over (None: not known)
    chip_thickness_range_m: tuple[float, float] | None = field(default=None, compare=False)

    def domain_warnings(self, chip_thickness_m: Any) -> list[str]:
        """The set's warnings plus one when the nominal chip thickness of a cut (the largest
        ``h0`` of its elements) exceeds the fitted range: the linear law extrapolated beyond
        its thickest test. Thinner chips are what the edge term of the law is for (towards
        the nose tip every boring chip thins to zero), so they are not flagged."""
        out = list(self.warnings)
        rng = self.chip_thickness_range_m
        h = np.asarray(chip_thickness_m, float)
        if rng is not None and h.size and float(h.max()) > rng[1] * (1 + 1e-9):
            out.append(f"cutting coefficients fitted over chip thicknesses "
                       f"{rng[0] * 1e6:g}-{rng[1] * 1e6:g} um, used up to "
                       f"{float(h.max()) * 1e6:.3g} um (the linear force law extrapolated)")
        return out

    def __post_init__(self) -> None:
        for name in _KEYS:
            v = getattr(self, name)
            if not isinstance(v, int | float) or not math.isfinite(v):
                raise ConfigError("not a finite number", field=_KEYS[name], value=v,
                                  expected="a number in " + ("N/m^2" if name[-1] == "c"
                                                             else "N/m"))
        if self.Ktc <= 0:
            raise ConfigError("tangential shearing coefficient must be positive",
                              field="Ktc_N_per_m2", value=self.Ktc, expected="> 0 N/m^2")

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {_KEYS[k]: float(getattr(self, k)) for k in _KEYS}
        d["provenance"] = self.provenance
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], source: str | None = None) -> CuttingCoefficients:
        """From ``{"Ktc_N_per_m2": .., ..., "provenance": ..}`` (missing edge terms are 0)."""
        vals: dict[str, Any] = {}
        for short, key in _KEYS.items():
            if key not in d:
                if short in ("Ktc", "Kfc"):
                    raise ConfigError("missing key", file=source, field=key,
                                      expected="a number in N/m^2")
                continue
            # a number (never a boolean), finite, within the plausible range of its unit
            # (robobore.io.ranges: N/mm^2 for N/m^2 is refused with a hint)
            vals[short] = check_value(d[key], key, file=source, field=key, kind=ConfigError)
        vals.setdefault("Krc", 0.0)
        return cls(**vals, provenance=str(d.get("provenance", source or "user")))


# ---------------------------------------------------------------------------- forces
@dataclass(frozen=True)
class ElementForces:
    """Per-element local forces [N] (arrays of shape (n,)) and rotating-frame totals [N].

    ``tangential``/``radial``/``feed`` totals are the force ON THE TOOL along
    ``-e_t`` (i.e. opposite to the insert velocity, given as a positive magnitude), ``e_r``
    (positive outwards) and ``e_z`` (positive along the feed).
    """

    dFt: np.ndarray
    dFf: np.ndarray
    dFl: np.ndarray
    tangential: float
    radial: float
    feed: float


def element_forces(el: EdgeElements, c: CuttingCoefficients) -> ElementForces:
    """Edge-element forces and their rotating-frame sums (see module docstring).

    Shearing terms on the chip ``h db`` of each element, edge terms on its length ``dS``:
    every element of ``el`` is engaged edge, those with ``h = 0`` (trailing side of the nose)
    carry the edge forces only."""
    dA = el.h * el.db
    dS = el.dS
    dFt = c.Ktc * dA + c.Kte * dS
    dFf = c.Kfc * dA + c.Kfe * dS
    dFl = c.Krc * dA + c.Kre * dS
    sk, ck = np.sin(el.kappa), np.cos(el.kappa)
    feed = float(np.sum(-dFf * sk + dFl * ck))
    radial = float(np.sum(-dFf * ck - dFl * sk))
    return ElementForces(dFt, dFf, dFl, float(dFt.sum()), radial, feed)


def rotating_to_boring(tangential: float, radial: float, feed: float,
                       theta: np.ndarray) -> np.ndarray:
    """Boring-frame force on the tool, shape (3, n_theta) [N], for bar angles ``theta`` [rad]."""
    th = np.asarray(theta, float)
    et = np.stack([-np.sin(th), np.cos(th), np.zeros_like(th)])
    er = np.stack([np.cos(th), np.sin(th), np.zeros_like(th)])
    ez = np.stack([np.zeros_like(th), np.zeros_like(th), np.ones_like(th)])
    return -tangential * et + radial * er + feed * ez


def boring_forces(insert: BoringInsert, depth_m: float, feed_per_rev_m: float,
                  coefficients: CuttingCoefficients, n_theta: int = 360,
                  n_elements: int = 40, trailing_edge: bool = True) -> dict[str, Any]:
    """Static (rigid-tool) boring forces over one revolution.

    Returns a dict with ``theta_rad`` (n,), ``force_N`` (3, n) in the boring frame (sum over
    the inserts, equally spaced), rotating-frame totals per insert, chip area, and per-axis
    mean and amplitude (half peak-to-peak). ``trailing_edge`` (default True): edge forces
    also on the engaged trailing side of the nose
    (:func:`robobore.cutting.geometry.edge_elements`); False gives the
    leading edge only.
    """
    fz = feed_per_rev_m / insert.n_inserts
    el = edge_elements(insert, depth_m, fz, n_elements, trailing_edge=trailing_edge)
    ef = element_forces(el, coefficients)
    th = np.linspace(0.0, 2 * np.pi, n_theta, endpoint=False)
    F = np.zeros((3, n_theta))
    for p in range(insert.n_inserts):
        F += rotating_to_boring(ef.tangential, ef.radial, ef.feed,
                                th + 2 * np.pi * p / insert.n_inserts)
    return {"theta_rad": th, "force_N": F, "tangential_N": ef.tangential,
            "radial_N": ef.radial, "feed_N": ef.feed, "chip_area_m2": el.area,
            "mean_N": F.mean(axis=1), "amplitude_N": 0.5 * (F.max(axis=1) - F.min(axis=1)),
            "elements": el, "element_forces": ef}


__all__ = ["CuttingCoefficients", "ElementForces", "element_forces", "rotating_to_boring",
           "boring_forces"]
