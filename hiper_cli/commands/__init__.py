"""One module per command group; each defines ``register(app: typer.Typer)``.

``cli.py`` builds the app from them with the typer subclass and error printing below.
"""

from hiper_cli.commands._render import HiperTyper, is_usage_error, print_error, print_usage_error

__all__ = ["HiperTyper", "is_usage_error", "print_error", "print_usage_error"]
