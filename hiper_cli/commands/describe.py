"""``hiper describe``: a compact text summary of a scene, sized for an LLM prompt."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, KbDocsOption, KbOption
from hiper_cli.commands._render import JSON_OPTION, console, print_json, safe_text

__all__ = ["register"]


def describe_command(
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    recent_s: Annotated[
        float, typer.Option("--recent-s", help="Movers seen in this many seconds before the KB's last stamp.")
    ] = 300.0,
    as_json: bool = JSON_OPTION,
) -> None:
    """Summarise a scene: layers, counts per class, recent movers, learned features, time span.

    Example: hiper describe --kb house.hiper
    """
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.query.describe import describe

    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        summary = describe(knowledge, recent_s=recent_s)
    if as_json:
        print_json(summary.to_dict())
        return
    console().print(safe_text(summary.text))


def register(app: typer.Typer) -> None:
    app.command(name="describe")(describe_command)
