"""``hiper analyze features`` and the ``analyze`` group (library: ``analyze/requests.py``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption, group

__all__ = ["analyze_app", "register"]

analyze_app = group("analyze", "Learn object features, build the map layer and draw heatmaps from a "
                    "knowledge base.\n\nExample: hiper analyze heatmap --class person --kb scene.hiper "
                    "-o maps")
FromOption = Annotated[str | None, typer.Option("--from", help="Window start: seconds or ISO date-time.")]
ToOption = Annotated[str | None, typer.Option("--to", help="Window end: seconds or ISO date-time.")]
LastOption = Annotated[str | None, typer.Option("--last", help="Only the last span of data, e.g. 1h, "
                                               "15min.")]
DailyOption = Annotated[str | None, typer.Option("--daily", help="Only this time of every day (UTC), e.g. "
                                                "09:00-10:00.")]
EnvOption = Annotated[str | None, typer.Option("--env", help="Environment (default: the only one).")]


@analyze_app.command("features")
def features_command(
    class_name: Annotated[list[str] | None, typer.Option(
        "--class", help="Class (repeatable; default all).")] = None,
    t_from: FromOption = None, t_to: ToOption = None, last: LastOption = None, daily: DailyOption = None,
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Write histograms (paper Fig. 8) to this PNG.")] = None,
    no_store: Annotated[bool, typer.Option(
        "--no-store", help="Show the features only; leave the KB as it is.")] = False,
    kb: KbOption = DEFAULT_KB, kb_docs: KbDocsOption = None, as_json: bool = JSON_OPTION,
) -> None:
    """Per class: the Object Dynamic Score [μ_v, c_l, c_u, r] with the 2σ noise split, and box
    size and altitude with 95 % bootstrap intervals; stored as analyses in the map layer, where
    perception reads them as priors.

    Example: hiper analyze features --class person --kb scene.hiper --plot person.png
    """
    from hiper_cli.analyze.requests import WindowText, features_at
    from hiper_cli.render.rows import emit_view

    run = features_at(kb, class_name, WindowText(t_from, t_to, last, daily), kb_docs=kb_docs, plot=plot,
                      store=not no_store)
    emit_view(run.to_dict(), run.view(), as_json)


def register(app: typer.Typer) -> None:
    app.add_typer(analyze_app, name="analyze")
