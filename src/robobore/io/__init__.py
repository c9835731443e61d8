"""Input/output at the package's edges: config files, results files, atomic writes."""

from robobore.io.config import load_toml, validate_model
from robobore.io.results import atomic_write_bytes, atomic_write_text, write_json, write_netcdf

__all__ = [
    "load_toml",
    "validate_model",
    "atomic_write_bytes",
    "atomic_write_text",
    "write_json",
    "write_netcdf",
]
