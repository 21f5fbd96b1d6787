"""``hiper eval scene``: a knowledge base scored against a realistic world's ground truth."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, JSON_OPTION, KbDocsOption, KbOption
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import emit
from hiper_cli.render.evaluate import show_scene_eval


@eval_app.command(
    "scene",
    help=(
        "Score what a knowledge base holds of a log against the log's ground truth "
        "(gt/instances.json and gt/surface_points.npz: a realistic world's, or a hiper sim log's) "
        "and print Table II (background: semantic and static/dynamic precision, distance error, "
        "coverage of the observed wall and floor pieces) and Table III (foreground: TP/FP/FN per "
        "class, classified precision, centre error, "
        "unknown instances on no real object, person instances per person, walker speed). With "
        "--ceiling DETECTOR it also runs that detector (hiper eval detector) and prints hiper's recall "
        "of the nameable objects seen clearly beside the detector's own. --kb may also name a JSON "
        "export (hiper export --format json).\n\n"
        "Example: hiper perceive ../shared/worlds/bookstore --kb bs.hiper && "
        "hiper eval scene ../shared/worlds/bookstore --kb bs.hiper"
    ),
)
def eval_scene(
    log: Annotated[Path, typer.Argument(help="A log with a realistic world's gt/ folder.")],
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    ceiling: str | None = typer.Option(
        None, "--ceiling", help="Also score this detector's own recall (yolox, onnx:PATH, log, truth)."),
    json_out: bool = JSON_OPTION,
) -> None:
    from hiper_cli.evaluate import evaluate_kb

    data = evaluate_kb(kb, log, docs_dir=kb_docs, ceiling=ceiling).figures
    emit(data, json_out, show_scene_eval)


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper eval``."""
