"""``hiper eval foreground``: the paper's Table III beside ours on a ``hiper sim`` log."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import console, print_json
from hiper_cli.commands.eval import eval_app


@eval_app.command("foreground")
def foreground(
    log: Annotated[Path, typer.Argument(help="A log written by hiper sim (a TUM folder with gt/).")],
    detector: str = typer.Option("truth", "--detector", help="truth, yolox, log or onnx:PATH."),
    background_filter: bool = typer.Option(
        True, "--background-filter/--no-background-filter",
        help="Filter background boxes before clustering (off: the paper's ablation C4).",
    ),
    ablation: bool = typer.Option(
        True, "--ablation/--no-ablation", help="Also run without background filter."
    ),
    max_frames: int = typer.Option(0, "--max-frames", help="Stop after this many frames (0: all)."),
    background: str = typer.Option(
        "auto", "--background", help="stage (hiper's background recognition), truth (ground-truth "
        "boxes) or auto (the stage when available)."
    ),
    classes: str | None = typer.Option(
        None, "--classes", help="Only these detector classes name objects, comma-separated (a per-"
        "environment class list; default: all).",
    ),
    exclude_classes: str | None = typer.Option(
        None, "--exclude-classes", help="Detector classes to drop, comma-separated (default: the "
        "indoor exclusion list of docs/foreground.md; \"\" drops none).",
    ),
    settings: list[str] = typer.Option(  # noqa: B008
        [], "--set", help="A foreground option KEY=VALUE (e.g. --set pixel_step=2); repeatable."
    ),
    json_out: bool = JSON_OPTION,
) -> None:
    """Foreground recognition and tracking against the ground truth (paper Table III).

    Example: hiper eval foreground out/hospital --detector yolox
    """
    from hiper_cli.evaluate.foreground import evaluate_foreground, parse_settings

    options = parse_settings(settings, classes=classes, exclude_classes=exclude_classes)
    report = evaluate_foreground(
        log, detector=detector, background_filter=background_filter, ablation=ablation,
        max_frames=max_frames or None, background=background, **options,
    )
    if json_out:
        print_json(report.to_dict())
        return
    from hiper_cli.commands._tables import show_foreground_eval

    show_foreground_eval(console(), report.to_dict())


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
