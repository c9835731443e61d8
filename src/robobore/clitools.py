"""Helpers shared by every CLI command: output as table or JSON, errors, progress bars.

Stage CLIs (``robobore/<stage>/cli.py``) use these so every command behaves alike:
a readable table by default, ``--json`` for machine-readable output on stdout, a rich
progress bar on stderr for anything slow, and a one-line error (exit code 2) for bad input.
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from robobore.errors import RoboboreError
from robobore.io.results import dumps_json

F = TypeVar("F", bound=Callable[..., Any])

stdout = Console()
stderr = Console(stderr=True)

JSON_OPTION = typer.Option(False, "--json", help="Print machine-readable JSON on stdout.")


#: Set by ``robobore --debug``: errors also print their Python traceback.
DEBUG = {"on": False}


def print_error(text: str) -> None:
    """``error: <text>`` on stderr, on one line."""
    # soft_wrap: one line whatever the terminal width (paths stay copyable, and the
    # message does not break where a long temporary path happens to end)
    stderr.print(f"[bold red]error:[/] {escape(text)}", highlight=False, markup=True,
                 soft_wrap=True)


def os_error_text(exc: OSError) -> str:
    """One line for an OS error on a user path: the path, what failed and the cause."""
    what = exc.strerror or str(exc) or type(exc).__name__
    where = exc.filename if exc.filename is not None else None
    if where is not None:
        extra = f" -> {exc.filename2}" if getattr(exc, "filename2", None) else ""
        return f"{where}{extra}: {what} ({type(exc).__name__})"
    return f"{what} ({type(exc).__name__})"


def handle_errors(func: F) -> F:
    """Turn a :class:`RoboboreError` (or an ``OSError`` on a user path: permission, disk
    full, missing file) into one clear line on stderr and exit code 2; ``robobore --debug``
    prints the traceback as well."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except RoboboreError as exc:
            if DEBUG["on"]:
                import traceback

                traceback.print_exc()
            print_error(str(exc))
            raise typer.Exit(code=2) from None
        except OSError as exc:
            if DEBUG["on"]:
                import traceback

                traceback.print_exc()
            print_error(os_error_text(exc))
            raise typer.Exit(code=2) from None

    return wrapper  # type: ignore[return-value]


def emit(result: dict[str, Any], as_json: bool, render: Callable[[dict[str, Any]], None]) -> None:
    """Print ``result`` as JSON (``as_json``) or through ``render`` (tables)."""
    if as_json:
        sys.stdout.write(dumps_json(result) + "\n")
        sys.stdout.flush()
    else:
        render(result)


def kv_table(title: str, rows: Iterable[tuple[str, Any]]) -> Table:
    """A two-column (quantity, value) rich table."""
    t = Table(title=title, show_header=True, header_style="bold")
    t.add_column("quantity")
    t.add_column("value", justify="right")
    for k, v in rows:
        t.add_row(escape(str(k)), escape(fmt(v)))
    return t


def fmt(v: Any) -> str:
    """Compact human formatting of numbers (4 significant digits) and other values."""
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v == 0.0:
            return "0"
        a = abs(v)
        if 1e-3 <= a < 1e6:
            return f"{v:.4g}"
        return f"{v:.4e}"
    return str(v)


@contextmanager
def progress_bar(
    description: str, total: int | None, enabled: bool = True
) -> Iterator[Callable[[int], None]]:
    """A rich progress bar on stderr; yields ``advance(n)``.

    The bar goes to stderr, so JSON on stdout stays clean either way. ``enabled`` false
    (commands pass ``not as_json``) keeps the bar only while stderr is a terminal: ``--json``
    in a terminal still shows progress of a long run, while a redirected or piped stderr
    (scripts, logs, tests) gets nothing.
    """
    if not enabled and not stderr.is_terminal:
        yield lambda n=1: None
        return
    prog = Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=stderr,
        transient=True,
    )
    with prog:
        task = prog.add_task(description, total=total)
        yield lambda n=1: prog.advance(task, n)


@contextmanager
def fraction_progress(description: str, enabled: bool = True
                      ) -> Iterator[Callable[[float], None]]:
    """:func:`progress_bar` for work that reports the fraction done (0..1); yields
    ``progress(frac)``, which advances the bar to that fraction (never back)."""
    total = 1000
    with progress_bar(description, total, enabled) as advance:
        done = [0]

        def progress(frac: float) -> None:
            n = min(total, int(frac * total))
            if n > done[0]:
                advance(n - done[0])
                done[0] = n

        yield progress


@contextmanager
def stage_progress(enabled: bool = True) -> Iterator[Callable[[str, int, int], None]]:
    """Progress bars for library code that reports ``progress(task, done, total)`` (the sweep,
    the paper study): yields that callback. Each ``task`` gets its own :func:`progress_bar`
    (one at a time: a new task closes the previous bar), advanced to ``done`` of ``total``
    and closed when ``done`` reaches ``total``."""
    state: dict[str, Any] = {"task": None, "bar": None, "advance": None, "done": 0}

    def close() -> None:
        if state["bar"] is not None:
            bar, state["bar"] = state["bar"], None
            bar.__exit__(None, None, None)

    def progress(task: str, done: int, total: int) -> None:
        if task != state["task"]:
            close()
            bar = progress_bar(task, total, enabled)
            state.update(task=task, bar=bar, advance=bar.__enter__(), done=0)
        if state["bar"] is None:  # this task's bar is finished
            return
        if done > state["done"]:
            state["advance"](done - state["done"])
            state["done"] = done
        if done >= total:
            close()

    try:
        yield progress
    finally:
        close()


def parse_floats(text: str, n: int | None, option: str, unit: str) -> list[float]:
    """Parse a comma-separated list of numbers given on the command line.

    Raises a ConfigError naming the option, the value and the expected count and unit.
    """
    from robobore.errors import ConfigError

    parts = [p.strip() for p in text.replace(";", ",").split(",") if p.strip()]
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise ConfigError(
            "not a list of numbers",
            field=option,
            value=text,
            expected=f"{n or 'some'} comma-separated numbers in {unit}",
        ) from None
    if n is not None and len(vals) != n:
        raise ConfigError(
            f"expected {n} values, got {len(vals)}",
            field=option,
            value=text,
            expected=f"{n} comma-separated numbers in {unit}",
        )
    from robobore.io.ranges import check_value, option_name

    for v in vals:  # NaN refused; plausible range of the option's unit (io.ranges)
        if not math.isinf(v):
            check_value(v, option_name(option), field=option, kind=ConfigError)
    return vals


def check_option(value: float | None, option: str, name: str | None = None) -> float | None:
    """Range-check a single-number option (robobore.io.ranges): NaN, infinity and a value
    outside the plausible range of its quantity (picked from ``name`` or the option's unit
    suffix) are a ConfigError naming the option; ``None`` (not given) passes through."""
    from robobore.errors import ConfigError
    from robobore.io.ranges import check_value, option_name

    if value is None:
        return None
    return check_value(value, name or option_name(option), field=option, kind=ConfigError)


def check_count(value: int | None, option: str, lo: int, hi: int) -> int | None:
    """Check an integer option against ``lo .. hi`` (a ConfigError naming the option)."""
    from robobore.errors import ConfigError

    if value is not None and not lo <= value <= hi:
        raise ConfigError("out of range", field=option, value=value,
                          expected=f"an integer {lo} .. {hi}")
    return value
