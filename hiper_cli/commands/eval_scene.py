"""``hiper eval scene``: a knowledge base scored against a realistic world's ground truth."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

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
        "of the nameable objects seen clearly beside the detector's own.\n\n"
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
    from hiper_cli.errors import LogError
    from hiper_cli.evaluate.scene import score_scene
    from hiper_cli.evaluate.surfaces import load_surfaces
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.perceive.logs.world_truth import load_world_truth

    if not (log / "gt" / "instances.json").exists() and (log / "gt" / "world.json").exists():
        raise LogError(f"{log / 'gt' / 'instances.json'}: not found; this hiper sim log was made before "
                       "hiper sim wrote scene truth: make it again with hiper sim, or score it with "
                       "hiper eval background / hiper eval foreground")
    truth = load_world_truth(log)
    surfaces = load_surfaces(log)
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        instances = knowledge.instances()
    data = score_scene(truth, surfaces, instances)
    if ceiling is not None:
        data["detector_ceiling"] = _ceiling(log, ceiling, data["foreground"]["matched_truth_ids"])
    emit(data, json_out, show_scene_eval)


def _ceiling(log: Path, detector: str, matched_truth_ids: list[int]) -> dict[str, Any]:
    from hiper_cli.evaluate.detector import detector_ceiling, recall_beside_ceiling
    from hiper_cli.perceive.detect import make_detector
    from hiper_cli.perceive.logs import open_log

    result = detector_ceiling(log, open_log(log), make_detector(detector, log_path=log))
    return {**recall_beside_ceiling(result, matched_truth_ids), "detector": detector}


def register(app: typer.Typer) -> None:
    """Nothing to do: the command adds itself to ``hiper eval``."""
