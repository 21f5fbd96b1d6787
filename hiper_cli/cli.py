"""The ``hiper`` command line: a thin layer that parses options, calls the library, renders.

Each command group lives in one module of ``hiper_cli.commands`` that defines
``register(app)``; this file discovers them, so adding a command touches no other file.
Heavy imports (numpy, open3d, stores) happen inside the commands so ``hiper --help`` is quick.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys

import typer

from hiper_cli import __version__, commands
from hiper_cli.cmdline import HiperTyper
from hiper_cli.errors import HiperError

app = HiperTyper(
    name="hiper",
    help=(
        "Build a lasting scene memory from a robot's RGB-D sensor log and ask it questions.\n\n"
        "Example: hiper info fixtures/house_small"
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"hiper {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """hiper: scene memory for mobile robots."""


def _register_commands() -> None:
    for module in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if module.name.startswith("_"):
            continue
        importlib.import_module(f"{commands.__name__}.{module.name}").register(app)


_register_commands()


def main() -> None:
    """Entry point of the ``hiper`` script: one red line and a non-zero exit on ``HiperError``;
    a usage error prints the command's usage line and one red line with a hint, exit code 2."""
    from hiper_cli.cmdline.usage import is_usage_error, print_usage_error
    from hiper_cli.render import print_error

    try:
        # In non-standalone mode click returns the code of a typer.Exit instead of raising it.
        code = app(standalone_mode=False)
        if isinstance(code, int) and code != 0:
            sys.exit(code)
    except HiperError as err:
        print_error(str(err))
        sys.exit(err.exit_code)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except (typer.Abort, KeyboardInterrupt):
        print("Aborted.", file=sys.stderr)
        sys.exit(130)
    except Exception as exc:  # click's usage errors arrive here in non-standalone mode
        if not is_usage_error(exc):
            raise
        sys.exit(print_usage_error(exc))
