"""robobore: robotic boring and robotic machining dynamics.

Pipeline (see docs/ARCHITECTURE.md): robot stiffness identification -> modal analysis ->
equivalent mass-spring-damper model -> cutting (mechanistic forces, explicit FE) ->
process dynamics (time domain, stability lobes) -> study (sweeps, comparison, report).

The Python API is :mod:`robobore.api` (``from robobore import api``, docs/api.md); its
functions are also attributes of the package (``robobore.stability_lobes``), loaded on
first use so that ``import robobore`` stays light.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("robobore")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]


def __getattr__(name: str):
    """The functions of :mod:`robobore.api`, imported on first use."""
    if name.startswith("__"):
        raise AttributeError(name)
    import importlib

    api = importlib.import_module("robobore.api")
    if name == "api":
        return api
    if name in api.__all__:
        return getattr(api, name)
    raise AttributeError(f"module 'robobore' has no attribute {name!r}")


def __dir__() -> list[str]:
    import importlib

    return sorted({*globals(), "api", *importlib.import_module("robobore.api").__all__})
