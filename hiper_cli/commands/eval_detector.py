"""``hiper eval detector``: how many clearly seen, nameable objects the 2D detector finds at all."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import JSON_OPTION
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import console, emit, frame_progress, safe_text
from hiper_cli.render.evaluate import show_detector_ceiling


@eval_app.command(
    "detector",
    help=(
        "Run a detector over the frames of LOG that have per-pixel ground truth and count, per class, "
        "the objects seen clearly (a COCO-nameable class, >= 1,500 px with depth in some frame) that "
        "it finds in at least one frame (a detection of the class or an alt class with IoU >= 0.5 "
        "against the box of the object's visible pixels), and in what share of the frames that show "
        "them: the ceiling of hiper's recall with that detector.\n\n"
        "Example: hiper eval detector ../shared/worlds/bookstore --detector yolox --json"
    ),
)
def eval_detector(
    log: Annotated[Path, typer.Argument(help="A log with per-pixel truth (shared world, hiper sim log).")],
    detector: str = typer.Option("yolox", "--detector", help="yolox, onnx:PATH, log or truth."),
    max_frames: int = typer.Option(0, "--max-frames", help="Use at most this many labelled frames (0: all)."),
    json_out: bool = JSON_OPTION,
) -> None:
    from hiper_cli.evaluate.detector import detector_ceiling
    from hiper_cli.perceive.detect import make_detector
    from hiper_cli.perceive.logs import open_log

    reader = open_log(log)
    model = make_detector(detector, log_path=log)
    screen = console()
    with frame_progress(f"{safe_text(detector)} on {safe_text(log)}", screen, enabled=not json_out) as bar:
        result = detector_ceiling(log, reader, model, max_frames=max_frames,
                                  progress=bar.update if bar else None)
    emit({**result.to_dict(), "detector": detector}, json_out, show_detector_ceiling)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper eval``."""
