"""``hiper view``: the knowledge base as a Rerun recording (or live viewer) and a top-down PNG."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbOption
from hiper_cli.render import console, print_json, safe_text

__all__ = ["register"]

Opt = typer.Option
LOG_HELP = "The sensor log: the RGB, depth and overlays of its frames."


def view_command(
    kb: KbOption = DEFAULT_KB,
    log: Annotated[Path | None, Opt("--log", help=LOG_HELP)] = None,
    start_s: Annotated[float | None, Opt("--from", help="First log stamp to show, seconds.")] = None,
    end_s: Annotated[float | None, Opt("--to", help="Last log stamp to show, seconds.")] = None,
    out: Annotated[Path | None, Opt("--out", "-o", help="Write a Rerun recording (.rrd).")] = None,
    spawn: Annotated[bool, Opt("--spawn", help="Stream to a new Rerun viewer window.")] = False,
    png: Annotated[Path | None, Opt("--png", help="Write a top-down picture (no Rerun needed).")] = None,
    image_hz: Annotated[float, Opt("--image-hz", help="With --log: frames/s logged (0: all).")] = 2.0,
    as_json: bool = JSON_OPTION,
) -> None:
    """Show the scene memory over time in Rerun (pip install 'hiper\\[view]') or as a picture.

    Example: hiper view --kb out/demo.hiper --log fixtures/house_small -o demo.rrd --png demo.png
    """
    from hiper_cli.view import TimeWindow, ViewRequest, render_view

    request = ViewRequest(kb=kb, rrd=out, spawn=spawn, png=png, log=log, window=TimeWindow(start_s, end_s),
                          image_hz=image_hz)
    summary = render_view(request)
    if as_json:
        print_json(summary.to_dict())
    else:
        console().print(safe_text(summary.line()))


def register(app: typer.Typer) -> None:
    app.command("view")(view_command)
