"""``hiper query workspace``: what a box of the map holds (library: ``query/workspace.py``)."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands.query import query_app

__all__ = ["register"]


@query_app.command("workspace")
def workspace_command(
    center: Annotated[str, typer.Option("--center", help="Centre x,y,z of the workspace box (m, map).")],
    size: Annotated[str, typer.Option("--size", help="Edge of the box (m), or sx,sy,sz.")] = "1.0",
    resolution: Annotated[float, typer.Option("--resolution", help="Voxel edge (m).")] = 0.05,
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """What a box of the map holds, for a manipulation planner.

    The static background as primitive shapes with their class, the foreground as a voxel
    grid with classes and learned dynamics (ODS where hiper analyze has run).

    Example: hiper query workspace --center 1.7,1.9,0.8 --size 1.0 --kb house.hiper --json
    """
    from hiper_cli.query.request import workspace_at
    from hiper_cli.query.views import workspace_view
    from hiper_cli.render.rows import emit_view

    ws = workspace_at(kb, center, size, resolution_m=resolution, kb_docs=kb_docs)
    emit_view(ws.to_dict(), workspace_view(ws), as_json)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper query`` on import."""
