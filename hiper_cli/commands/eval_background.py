"""``hiper eval background``: Table II of the paper (background reconstruction), ours beside it."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import JSON_OPTION
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import emit
from hiper_cli.render.evaluate import show_background_eval


@eval_app.command(
    "background",
    help=(
        "Run background recognition over a hiper sim log (its mapping phase) and print the paper's "
        "Table II rows beside ours: processing time per keyframe, instance and observation counts, "
        "static/dynamic and semantic precision, walls and tables TP/FP, furniture and door false "
        "positives, and the distance of our planes to the true surfaces.\n\n"
        "Example: hiper eval background out/house --method ransac"
    ),
)
def eval_background(
    log: Annotated[Path, typer.Argument(help="A log written by hiper sim (with gt/).")],
    method: str = typer.Option("fast", "--method", "-m", help="Plane extractor: fast or ransac."),
    all_phases: bool = typer.Option(
        False, "--all-phases", help="Use every frame, not only the mapping phase (people then appear)."
    ),
    max_frames: int | None = typer.Option(None, "--max-frames", help="Stop after this many frames."),
    keyframe_hz: float = typer.Option(2.0, "--keyframe-hz", help="Mapping rate (the paper: 2 Hz)."),
    json_out: bool = JSON_OPTION,
) -> None:
    # one core: keep BLAS and OpenMP (open3d) single-threaded; set before numpy loads
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from hiper_cli.evaluate.background import evaluate_background

    report = evaluate_background(
        log, method=method, phase=None if all_phases else "mapping", max_frames=max_frames,
        keyframe_hz=keyframe_hz,
    )
    emit(report.to_dict(), json_out, show_background_eval)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper eval``."""
