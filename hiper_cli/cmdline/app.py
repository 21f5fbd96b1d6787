"""The typer app of every command and group: numeric options checked, ``HiperError`` as one line."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

import typer

from hiper_cli.render import print_error

_F = TypeVar("_F", bound=Callable[..., Any])

__all__ = ["HiperTyper", "group"]


def _flag_names(func: Any) -> dict[str, str]:
    """Parameter name -> the long flag the user types (``fx_px`` -> ``--fx``)."""
    import inspect

    try:
        parameters = inspect.signature(func, eval_str=True).parameters
    except (NameError, TypeError):
        parameters = inspect.signature(func).parameters
    out: dict[str, str] = {}
    for name, p in parameters.items():
        for info in (p.default, *getattr(p.annotation, "__metadata__", ())):
            decls = [d for d in getattr(info, "param_decls", None) or () if isinstance(d, str)]
            first = getattr(info, "default", None)  # Annotated[..., typer.Option("--flag")]
            if isinstance(first, str) and first.startswith("-") and hasattr(info, "param_decls"):
                decls.insert(0, first)
            if decls:
                out[name] = next((d for d in decls if d.startswith("--")), decls[0])
    return out


class HiperTyper(typer.Typer):
    """A Typer whose commands check their numeric options (``hiper_cli.validate``) and turn
    ``HiperError`` into one red line and its exit code.

    Use it for the root app and every command group (``hiper kb ...``) so that both the
    installed script and typer's ``CliRunner`` in tests behave the same.
    """

    def command(self, *args: Any, **kwargs: Any) -> Callable[[_F], _F]:
        def wrap(func: _F) -> _F:
            import functools
            import inspect

            from hiper_cli.errors import HiperError
            from hiper_cli.validate import check_options

            if "short_help" not in kwargs:
                # rich help keeps a docstring's line breaks in the list of commands; one line reads
                first = (kwargs.get("help") or inspect.getdoc(func) or "").split("\n\n")[0]
                kwargs["short_help"] = " ".join(first.split())
            decorator = super(HiperTyper, self).command(*args, **kwargs)
            flags = _flag_names(func)

            @functools.wraps(func)
            def guarded(*f_args: Any, **f_kwargs: Any) -> Any:
                try:
                    check_options(f_kwargs, flags)  # every number, where the command line is parsed
                    return func(*f_args, **f_kwargs)
                except HiperError as err:
                    print_error(str(err))
                    raise typer.Exit(err.exit_code) from err

            decorator(guarded)
            return func

        return wrap


def group(name: str, help: str) -> HiperTyper:
    """A command group such as ``hiper kb``; ``help`` must contain an ``Example:``."""
    return HiperTyper(name=name, help=help, no_args_is_help=True, add_completion=False)
