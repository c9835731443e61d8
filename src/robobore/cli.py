"""The ``robobore`` command: ``robobore <stage> <verb>``.

Each stage owns its commands in ``robobore/<stage>/cli.py`` and adds them here through a
``register(groups)`` function, so the stages stay independent. Heavy imports (numba
kernels) happen inside the commands, keeping ``robobore --help`` fast.
"""

from __future__ import annotations

import importlib

import typer

from robobore import __version__

app = typer.Typer(
    name="robobore",
    help="Robotic boring dynamics: robot stiffness, modal analysis, equivalent model, "
    "cutting forces (mechanistic and explicit FE), stability and process studies.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts are plain: units in brackets ("[mm]") stay visible
)

#: Command groups shared by the stages. ``groups["root"]`` is the top-level app, for
#: top-level commands such as ``robobore lobes``.
def _group(help: str) -> typer.Typer:
    return typer.Typer(help=help, no_args_is_help=True, rich_markup_mode=None)


groups: dict[str, typer.Typer] = {
    "root": app,
    "robot": _group("Robot kinematics and stiffness."),
    "identify": _group("Identify models from measurements."),
    "model": _group("Build process models (equivalent model)."),
    "simulate": _group("Time-domain process simulation."),
    "fe": _group("Explicit finite-element cutting simulation."),
    "calibrate": _group("Calibrate models from simulations."),
    "plan": _group("Plan the robot's posture for a bore (stiffness, modes, chatter)."),
}

#: Modules that contribute commands; each has ``register(groups)``.
STAGE_CLIS = [
    "robobore.robot.cli",
    "robobore.modal.cli",
    "robobore.dynamics.cli",
    "robobore.dynamics.cli_calibrate",
    "robobore.cutting.fe.cli",
    "robobore.study.cli",
    "robobore.plan.cli",
    "robobore.measure.cli",
]


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"robobore {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version_callback, is_eager=True, help="Show the version."
    ),
    debug: bool = typer.Option(
        False, "--debug", help="Show the Python traceback of an error (for bug reports)."
    ),
    no_range_check: bool = typer.Option(
        False, "--no-range-check",
        help="Accept values outside their plausible range (docs/inputs.md), with a warning; "
        "recorded in the configs' provenance."),
) -> None:
    """robobore command line."""
    from robobore.clitools import DEBUG

    DEBUG["on"] = debug
    if no_range_check:
        from robobore.io.ranges import set_enabled

        set_enabled(False)


def _build() -> None:
    for mod in STAGE_CLIS:
        importlib.import_module(mod).register(groups)
    for name, sub in groups.items():
        if name != "root" and sub.registered_commands:
            app.add_typer(sub, name=name)


_build()


def main() -> None:  # console-script entry point
    """Run the CLI; a RoboboreError or OSError that escapes a command (one not wrapped in
    ``handle_errors``) is still one line on stderr and exit code 2, not a traceback."""
    import sys

    from robobore.clitools import DEBUG, os_error_text, print_error
    from robobore.errors import RoboboreError

    try:
        app()
    except (RoboboreError, OSError) as exc:
        if DEBUG["on"] or "--debug" in sys.argv[1:]:
            raise
        print_error(os_error_text(exc) if isinstance(exc, OSError) else str(exc))
        sys.exit(2)


if __name__ == "__main__":  # pragma: no cover
    main()
