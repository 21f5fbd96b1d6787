"""``hiper eval changes``: change detection, re-identification and ghosts over several sessions."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbOption
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import emit
from hiper_cli.render.evaluate import show_changes


@eval_app.command("changes")
def changes(
    truth: Annotated[Path, typer.Argument(help="The folder 'hiper sim --sessions N --changes K' wrote.")],
    kb: KbOption = DEFAULT_KB,
    json_out: bool = JSON_OPTION,
) -> None:
    """Change precision / recall / F1 per kind, re-identification precision, ghost rate, count
    error per class and alignment error, of a knowledge base its sessions were perceived into.

    Example: hiper sim --sessions 3 --changes 6 -o days && for s in 1 2 3; do hiper perceive
    days/session_$s --kb days.hiper --detector truth; done && hiper eval changes days --kb days.hiper
    """
    from hiper_cli.evaluate import evaluate_changes

    emit(evaluate_changes(kb, truth).to_dict(), json_out, show_changes)


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
