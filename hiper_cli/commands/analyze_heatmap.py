"""``hiper analyze heatmap``: where a class goes, as a PNG and nav2 costmap-filter masks."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands.analyze import DailyOption, EnvOption, FromOption, LastOption, ToOption, analyze_app

__all__ = ["register"]


@analyze_app.command("heatmap")
def heatmap_command(
    class_name: Annotated[str, typer.Option("--class", help="The class whose whereabouts to draw.")
                          ] = "person",
    t_from: FromOption = None, t_to: ToOption = None, last: LastOption = None, daily: DailyOption = None,
    inverse: Annotated[bool, typer.Option("--inverse", help="Also write the inverse map (for search).")
                       ] = False,
    out_dir: Annotated[Path, typer.Option("--out", "-o", help="Output folder (default: here).")] = Path("."),
    map_yaml: Annotated[str | None, typer.Option(
        "--map", help="map_server YAML to draw on (stored as the environment's map).")] = None,
    env: EnvOption = None, kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Algorithm 5: the class's trajectories in the window inflated by a normal distribution and
    capped at 80 % occupancy, on the map; writes a PNG and nav2 costmap-filter masks (keepout
    and speed limit, raw PGM + YAML, with the filter servers' parameters and a costmap snippet).

    Example: hiper analyze heatmap --class person --daily 09:00-10:00 --inverse -o maps
    """
    from hiper_cli.analyze.requests import WindowText, heatmap_at
    from hiper_cli.render.rows import emit_view

    run = heatmap_at(kb, class_name, WindowText(t_from, t_to, last, daily), out_dir, kb_docs=kb_docs,
                     env_name=env, map_yaml=map_yaml, inverse=inverse)
    emit_view(run.to_dict(), run.view(), as_json)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper analyze`` on import."""
