"""Multi-mode tool-point model: modes with frequency, damping ratio, modal stiffness, direction.

Each mode ``j`` is a single-degree-of-freedom oscillator acting along a unit direction
``d_j`` of the boring frame (X horizontal, Y vertical, Z feed)::

    q_j'' + 2 zeta_j w_j q_j' + w_j^2 q_j = (d_j . F) / m_j,     m_j = k_j / w_j^2
    r = sum_j d_j q_j                      (tool-point displacement [m], shape (3,))

so the tool-point FRF matrix is ``G(iw) = sum_j d_j d_j^T / (k_j (1 - (w/w_j)^2 + 2 i zeta_j
w/w_j))`` [m/N], shape ``(3, 3, n_w)`` (outputs, inputs, frequencies).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import ConfigError


@dataclass(frozen=True)
class Mode:
    """One tool-point mode (SI: Hz, N/m; direction a unit 3-vector in the boring frame)."""

    frequency_Hz: float
    damping_ratio: float
    stiffness_N_per_m: float
    direction: tuple[float, float, float]

    def to_dict(self) -> dict[str, Any]:
        return {"frequency_Hz": self.frequency_Hz, "damping_ratio": self.damping_ratio,
                "stiffness_N_per_m": self.stiffness_N_per_m, "direction": list(self.direction)}


def check_unit_vector(v: Any, field: str, file: str | None = None, tol: float = 0.01) -> np.ndarray:
    """Validate a direction: 3 finite numbers, non-zero, within ``tol`` of unit length.

    Returns the normalised vector. Errors name the key, the value and what was expected.
    """
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError("not a vector of numbers", file=file, field=field, value=v,
                          expected="3 numbers (a unit vector)") from None
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ConfigError("must have 3 finite components", file=file, field=field, value=v,
                          expected="[x, y, z] (a unit vector)")
    n = float(np.linalg.norm(a))
    if n < 1e-9:
        raise ConfigError("zero-length direction", file=file, field=field, value=v,
                          expected="a unit vector")
    if abs(n - 1.0) > tol:
        raise ConfigError(f"direction length {n:.4f} is more than {tol:.0%} off unit length",
                          file=file, field=field, value=v, expected="a unit vector (|d| = 1)")
    return a / n


@dataclass(frozen=True)
class ToolPointStructure:
    """Tool-point modes as structure of arrays (all SI).

    ``frequency_Hz``, ``damping_ratio``, ``stiffness_N_per_m``: shape ``(m,)``;
    ``directions``: shape ``(m, 3)`` unit rows.
    """

    frequency_Hz: np.ndarray
    damping_ratio: np.ndarray
    stiffness_N_per_m: np.ndarray
    directions: np.ndarray

    @classmethod
    def from_modes(cls, modes: list[dict[str, Any]] | list[Mode],
                   file: str | None = None, key: str = "structure.modes") -> ToolPointStructure:
        """Validate and build from a list of mode dicts (the ``[structure] modes`` contract)."""
        if not modes:
            raise ConfigError("no modes", file=file, field=key, expected="at least one mode")
        f, z, k, d = [], [], [], []
        for i, md in enumerate(modes):
            md = md.to_dict() if isinstance(md, Mode) else md
            where = f"{key}[{i}]"
            for name, unit, lo_open in (("frequency_Hz", "Hz", True),
                                        ("stiffness_N_per_m", "N/m", True),
                                        ("damping_ratio", "(ratio, 0 <= zeta < 1)", False)):
                if name not in md:
                    raise ConfigError("missing key", file=file, field=f"{where}.{name}",
                                      expected=f"a number in {unit}")
                try:
                    val = float(md[name])
                except (TypeError, ValueError):
                    raise ConfigError("not a number", file=file, field=f"{where}.{name}",
                                      value=md[name], expected=f"a number in {unit}") from None
                bad = (not math.isfinite(val)) or (val <= 0 if lo_open else val < 0)
                if name == "damping_ratio" and val >= 1:
                    bad = True
                if bad:
                    raise ConfigError("out of range", file=file, field=f"{where}.{name}",
                                      value=md[name], expected=f"a positive number in {unit}")
            if "direction" not in md:
                raise ConfigError("missing key", file=file, field=f"{where}.direction",
                                  expected="a unit vector [x, y, z]")
            f.append(float(md["frequency_Hz"]))
            z.append(float(md["damping_ratio"]))
            k.append(float(md["stiffness_N_per_m"]))
            d.append(check_unit_vector(md["direction"], f"{where}.direction", file))
        return cls(np.array(f), np.array(z), np.array(k), np.array(d))

    @classmethod
    def from_equivalent(cls, em: Any) -> ToolPointStructure:
        """From an :class:`robobore.equivalent.EquivalentModel` (three units along its frame)."""
        return cls.from_modes(em.tool_point_modes())

    @property
    def n_modes(self) -> int:
        return int(self.frequency_Hz.size)

    @property
    def omega(self) -> np.ndarray:
        return 2 * np.pi * self.frequency_Hz

    @property
    def modal_mass(self) -> np.ndarray:
        return self.stiffness_N_per_m / self.omega**2

    def modes(self) -> list[Mode]:
        return [Mode(float(f), float(z), float(k), tuple(float(x) for x in d))
                for f, z, k, d in zip(self.frequency_Hz, self.damping_ratio,
                                      self.stiffness_N_per_m, self.directions, strict=True)]

    def modal_frf(self, omega: np.ndarray) -> np.ndarray:
        """Modal receptances ``1 / (k_j (1 - r^2 + 2 i zeta r))`` [m/N], shape (m, n_w)."""
        w = np.asarray(omega, float)[None, :]
        r = w / self.omega[:, None]
        return 1.0 / (self.stiffness_N_per_m[:, None]
                      * (1 - r**2 + 2j * self.damping_ratio[:, None] * r))

    def frf(self, omega: np.ndarray) -> np.ndarray:
        """Tool-point FRF matrix [m/N], shape (3, 3, n_w): G[o, i] = sum_j d_jo d_ji / ..."""
        h = self.modal_frf(omega)
        D = self.directions
        return np.einsum("jo,ji,jw->oiw", D, D, h)

    def to_dict(self) -> dict[str, Any]:
        return {"modes": [m.to_dict() for m in self.modes()]}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ToolPointStructure:
        return cls.from_modes(d["modes"])


__all__ = ["Mode", "ToolPointStructure", "check_unit_vector"]
