"""``hiper describe``: a compact text summary of a scene, sized for an LLM prompt."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Json, Kb, KbDocs
from hiper_cli.render import console, print_json, safe_text

__all__ = ["register"]

RecentS = Annotated[float, typer.Option(
    "--recent-s", help="Movers seen in this many seconds before the KB's last stamp.")]


def describe_command(kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, recent_s: RecentS = 300.0,
                     as_json: Json = False) -> None:
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


def register(app: HiperTyper) -> None:
    app.command(name="describe")(describe_command)
