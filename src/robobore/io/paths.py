"""One rule for every file a config file names: relative to the config file's folder.

A relative path inside a config (``[coefficients] file``, ``[material] name = "my.toml"``,
``[modal] file``, ``[robot] campaign``, ``[measured] file``, ...) is resolved against the
folder of the config file that names it, never against the current directory, so the same
config gives the same result wherever it is run from. The resolved absolute path is what the
loaders put back into the config recorded in the results' provenance. A config given as a
mapping with no file (the Python API) resolves against the current directory.
"""

from __future__ import annotations

from pathlib import Path

from robobore.errors import ConfigError


def config_dir(config: str | Path | None) -> Path:
    """The folder relative paths in ``config`` are resolved against (cwd without a file)."""
    if config is None or str(config).startswith("<"):
        return Path.cwd()
    return Path(config).resolve().parent


def resolve_config_path(value: str | Path, config: str | Path | None, key: str, *,
                        must_exist: bool = True, what: str = "file") -> Path:
    """The absolute path of a file named under ``key`` in the config file ``config``.

    ``~`` is expanded; a relative path is taken relative to the config file's folder. With
    ``must_exist`` a missing file is a :class:`ConfigError` naming the config file, the key,
    the value and where it was looked for.
    """
    if not isinstance(value, str | Path) or str(value).strip() == "":
        raise ConfigError(f"bad {what} name", file=None if config is None else str(config),
                          field=key, value=value, expected="a file path (relative paths are "
                          "resolved against the config file's folder)")
    p = Path(value).expanduser()
    base = config_dir(config)
    q = (p if p.is_absolute() else base / p).resolve()
    if must_exist and not q.is_file():
        raise ConfigError(f"{what} not found", file=None if config is None else str(config),
                          field=key, value=str(value),
                          expected=f"an existing file at {q} (relative paths are resolved "
                          f"against the config file's folder {base})")
    return q


def names_a_path(name: str, suffixes: tuple[str, ...] = (".toml",)) -> bool:
    """Whether a config value that may be a bundled name or a path is a path (it has a
    folder part or ends in one of ``suffixes``)."""
    s = str(name)
    return any(s.lower().endswith(x) for x in suffixes) or "/" in s or "\\" in s


__all__ = ["config_dir", "resolve_config_path", "names_a_path"]
