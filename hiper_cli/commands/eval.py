"""``hiper eval``: the paper's result tables measured on simulated logs with ground truth.

The subcommands live in ``eval_*.py`` modules beside this one and add themselves to
``eval_app``.
"""

from __future__ import annotations

import typer

from hiper_cli.cmdline import group

eval_app = group(
    "eval",
    "Measure hiper against the ground truth of hiper sim logs, beside the paper's numbers.\n\n"
    "Example: hiper eval background out/house",
)


def register(app: typer.Typer) -> None:
    app.add_typer(eval_app, name="eval")
