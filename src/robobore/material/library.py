"""Material library: Johnson-Cook materials from TOML files (bundled or the user's own).

A material file has the tables ``[johnson_cook]`` (A_MPa, B_MPa, n, C, m, eps_dot0_per_s,
T_room_K, T_melt_K; optional hardening_strain_limit), ``[damage]`` (D1..D5), ``[elastic]``
(E_GPa, nu) and ``[thermal]`` (rho_kg_m3, cp_J_kgK, k_W_mK, taylor_quinney). Bundled files live in
``robobore/material/library/``; :func:`load_material` takes a bundled name (``"TC4"``) or a
path to a TOML file; a relative path is resolved against the folder of the config file that
names it (``source``), never the current directory.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from robobore.errors import ConfigError
from robobore.io.config import load_toml, validate_model
from robobore.io.paths import config_dir, names_a_path, resolve_config_path
from robobore.material import johnson_cook as jc


class _JC(BaseModel):
    model_config = ConfigDict(extra="forbid")
    A_MPa: float = Field(gt=0)
    B_MPa: float = Field(ge=0)
    n: float = Field(gt=0, le=1.5)
    C: float = Field(ge=0)
    m: float = Field(gt=0)
    eps_dot0_per_s: float = Field(gt=0)
    T_room_K: float = Field(gt=0)
    T_melt_K: float = Field(gt=0)
    #: optional: the plastic strain beyond which the hardening term B eps^n stays at its
    #: value (the constants' fit rarely reaches the strains of a secondary shear zone)
    hardening_strain_limit: float | None = Field(default=None, gt=0)


class _Damage(BaseModel):
    model_config = ConfigDict(extra="forbid")
    D1: float
    D2: float
    D3: float
    D4: float
    D5: float


class _Elastic(BaseModel):
    model_config = ConfigDict(extra="forbid")
    E_GPa: float = Field(gt=0)
    nu: float = Field(gt=-1.0, lt=0.5)


class _Thermal(BaseModel):
    model_config = ConfigDict(extra="forbid")
    rho_kg_m3: float = Field(gt=0)
    cp_J_kgK: float = Field(gt=0)
    k_W_mK: float = Field(ge=0)
    taylor_quinney: float = Field(ge=0, le=1)


class _MaterialFile(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: str
    description: str = ""
    johnson_cook: _JC
    damage: _Damage
    elastic: _Elastic
    thermal: _Thermal


@dataclass(frozen=True)
class Material:
    """A Johnson-Cook material in SI units (Pa, K, kg/m3, J/(kg K), W/(m K))."""

    name: str
    A: float
    B: float
    n: float
    C: float
    m: float
    eps_dot0: float
    T_room: float
    T_melt: float
    D1: float
    D2: float
    D3: float
    D4: float
    D5: float
    E: float
    nu: float
    rho: float
    cp: float
    k: float
    taylor_quinney: float
    #: plastic strain beyond which the hardening term is held (inf: the plain Johnson-Cook law)
    hardening_strain_limit: float = math.inf

    @property
    def G(self) -> float:
        """Shear modulus [Pa]."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def K(self) -> float:
        """Bulk modulus [Pa]."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    def flow_stress(self, eps_p: float, eps_rate: float, T: float) -> float:
        """Johnson-Cook flow stress [Pa] at plastic strain, rate [1/s] and temperature [K]."""
        return float(jc.jc_flow_stress(eps_p, eps_rate, T, self.A, self.B, self.n, self.C,
                                       self.m, self.eps_dot0, self.T_room, self.T_melt,
                                       self.hardening_strain_limit))

    def failure_strain(self, triaxiality: float, eps_rate: float, T: float) -> float:
        """Johnson-Cook failure strain at a stress triaxiality, rate [1/s], temperature [K]."""
        return float(jc.jc_failure_strain(triaxiality, eps_rate, T, self.D1, self.D2, self.D3,
                                          self.D4, self.D5, self.eps_dot0, self.T_room,
                                          self.T_melt))

    def to_array(self) -> np.ndarray:
        """Flat float64 array indexed by the constants of :mod:`robobore.material.johnson_cook`."""
        a = np.zeros(jc.N_MAT)
        a[jc.A], a[jc.B], a[jc.N], a[jc.C], a[jc.M] = self.A, self.B, self.n, self.C, self.m
        a[jc.EPS0], a[jc.TROOM], a[jc.TMELT] = self.eps_dot0, self.T_room, self.T_melt
        a[jc.D1], a[jc.D2], a[jc.D3], a[jc.D4], a[jc.D5] = (self.D1, self.D2, self.D3,
                                                            self.D4, self.D5)
        a[jc.E_MOD], a[jc.NU], a[jc.RHO], a[jc.CP] = self.E, self.nu, self.rho, self.cp
        a[jc.KCOND], a[jc.BETA_TQ] = self.k, self.taylor_quinney
        a[jc.EPS_HMAX] = self.hardening_strain_limit
        return a

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Material:
        return cls(**d)


def bundled_materials() -> list[str]:
    """Names of the bundled materials."""
    lib = resources.files("robobore.material") / "library"
    return sorted(p.name[:-5].upper() for p in lib.iterdir() if p.name.endswith(".toml"))


def _from_file_data(data: dict[str, Any], source: str) -> Material:
    f = validate_model(_MaterialFile, data, source=source)
    j, d, e, t = f.johnson_cook, f.damage, f.elastic, f.thermal
    if j.T_melt_K <= j.T_room_K:
        raise ConfigError("melting temperature must exceed room temperature", file=source,
                          field="johnson_cook.T_melt_K", value=j.T_melt_K,
                          expected=f"a temperature in K above T_room_K = {j.T_room_K}")
    return Material(name=f.name, A=j.A_MPa * 1e6, B=j.B_MPa * 1e6, n=j.n, C=j.C, m=j.m,
                    eps_dot0=j.eps_dot0_per_s, T_room=j.T_room_K, T_melt=j.T_melt_K,
                    D1=d.D1, D2=d.D2, D3=d.D3, D4=d.D4, D5=d.D5, E=e.E_GPa * 1e9, nu=e.nu,
                    rho=t.rho_kg_m3, cp=t.cp_J_kgK, k=t.k_W_mK,
                    taylor_quinney=t.taylor_quinney,
                    hardening_strain_limit=(math.inf if j.hardening_strain_limit is None
                                            else j.hardening_strain_limit))


def load_material(name_or_path: str | Path, *, source: str | None = None,
                  field: str = "material.name",
                  hardening_strain_limit: float | None = None) -> Material:
    """A bundled material by name (case-insensitive, e.g. ``"TC4"``) or a user TOML file;
    ``hardening_strain_limit``, when given, replaces the file's."""
    mat = _load_material(name_or_path, source=source, field=field)
    if hardening_strain_limit is not None:
        mat = replace(mat, hardening_strain_limit=float(hardening_strain_limit))
    return mat


def resolve_material_name(name: str | Path, source: str | None = None,
                          field: str = "material.name") -> str:
    """A material named in the config ``source``: a bundled name stays as it is; a path (it
    ends in ``.toml``, has a folder part, or is a file next to the config) becomes the
    absolute path, resolved against the config file's folder (:mod:`robobore.io.paths`)."""
    s = str(name)
    if names_a_path(s) or (s and (config_dir(source) / s).is_file()):
        return str(resolve_config_path(s, source, field, what="material file"))
    return s


def _load_material(name_or_path: str | Path, *, source: str | None, field: str) -> Material:
    s = resolve_material_name(name_or_path, source, field)
    if Path(s).is_absolute():
        return _from_file_data(load_toml(s), s)
    lib = resources.files("robobore.material") / "library" / f"{s.lower()}.toml"
    if not lib.is_file():
        raise ConfigError("unknown material", file=source, field=field, value=s,
                          expected=f"one of {bundled_materials()} or a path to a material "
                          "TOML file")
    with resources.as_file(lib) as fp:
        return _from_file_data(load_toml(fp), str(fp))
