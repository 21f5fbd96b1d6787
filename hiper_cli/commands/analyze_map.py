"""``hiper analyze map``: the map layer as map_server YAML + PGM."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands.analyze import EnvOption, analyze_app

__all__ = ["register"]


@analyze_app.command("map")
def map_command(
    out: Annotated[Path, typer.Option("--out", "-o", help="map_server YAML to write (PGM beside it).")
                   ] = Path("map.yaml"),
    map_yaml: Annotated[str | None, typer.Option(
        "--map", help="Load this map_server YAML as the environment's map instead.")] = None,
    resolution_m: Annotated[float, typer.Option("--resolution-m", help="Cell size when built from the KB.")
                            ] = 0.05,
    env: EnvOption = None, kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """The map layer: an occupancy grid built from the background and the observed trajectories
    (or loaded with --map), stored in the environment and exported as map_server YAML + PGM.

    Example: hiper analyze map --kb scene.hiper -o maps/floor.yaml
    """
    from hiper_cli.analyze.requests import map_at
    from hiper_cli.render.rows import emit_view

    run = map_at(kb, out, kb_docs=kb_docs, env_name=env, map_yaml=map_yaml, resolution_m=resolution_m)
    emit_view(run.to_dict(), run.view(), as_json)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper analyze`` on import."""
