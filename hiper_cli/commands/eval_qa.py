"""``hiper eval qa``: a question-answering benchmark from a log's ground truth."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import console, frame_progress, print_json
from hiper_cli.commands.eval import eval_app


def _fmt(v: Any, digits: int = 3) -> str:
    return "-" if v is None else f"{v:.{digits}f}" if isinstance(v, float) else str(v)


def _err(v: Any) -> str:
    """A median error; None when over half the questions went unanswered (infinite)."""
    return "inf" if v is None else _fmt(v)


@eval_app.command("qa")
def qa(
    log: Annotated[Path, typer.Argument(help="A log with ground truth: hiper sim's gt/ or a world's gt/.")],
    kb: Annotated[
        str | None, typer.Option("--kb", help="Answer from this knowledge base (default: perceive the log).")
    ] = None,
    detector: Annotated[
        str, typer.Option("--detector", help="When perceiving: auto (truth where the log has gt/detections."
                          "jsonl, else yolox), truth, yolox, log or onnx:PATH.")
    ] = "auto",
    out_dir: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Folder for questions.jsonl, answers.jsonl (and kb.hiper)."),
    ] = None,
    short_s: Annotated[
        float, typer.Option("--short-s", help="The short horizon: the last this many seconds.")
    ] = 15.0,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the generated question times.")] = 0,
    glimpse_s: Annotated[
        float, typer.Option("--glimpse-s", help="An instance in view less than this many seconds is a "
                            "glimpse: counts are also scored with glimpses optional.")
    ] = 0.5,
    as_json: bool = JSON_OPTION,
) -> None:
    """NaVQA-style questions (yes/no, count, position, time, duration; short and long
    horizons) generated from the log's truth, asked through the query layer and scored
    (position error horizontal, 3-D beside it); questions about classes the detector cannot
    name are scored apart. The questions with their true answers are written as JSONL.

    Example: hiper eval qa out/house -o out/house_qa --json
    """
    from hiper_cli.qa import evaluate_qa

    with frame_progress("perceive", console(), enabled=not as_json and kb is None) as bar:
        report = evaluate_qa(log, kb=kb, detector=detector, out_dir=out_dir, short_s=short_s, seed=seed,
                             glimpse_s=glimpse_s, progress=None if bar is None else bar.update)
    data = report.to_dict()
    if as_json:
        print_json(data)
        return
    from rich.table import Table

    out = console()
    table = Table("kind", "horizon", "questions", "answered", "accuracy / median error", "detail",
                  title=f"hiper eval qa {log} (detector {report.detector}"
                  + (f", answers from {kb})" if kb else ")"))
    for kind, by in data["by_kind"].items():
        for horizon in ("short", "long", "all"):
            f = by[horizon]
            if not f.get("n"):
                continue
            unit = {"position": " m", "time": " s", "duration": " s"}.get(kind, "")
            if "accuracy" in f:
                value = _fmt(f.get("accuracy"))
            else:  # None: more than half unanswered, an infinite median
                value = ("inf" if f.get("median_error") is None else _fmt(f["median_error"])) + unit
            if kind == "yes_no":
                note = f"yes {_fmt(f.get('accuracy_on_yes'))} / no {_fmt(f.get('accuracy_on_no'))}"
            elif kind == "count":
                note = (f"{_fmt(f.get('accuracy_glimpses_optional'))} with {f.get('glimpsed')} glimpsed "
                        "instances optional")
            else:
                note = f"answered: median {_fmt(f.get('median_error_answered'))}{unit}"
            table.add_row(kind, horizon, str(f["n"]), str(f["answered"]), value, note)
    out.print(table)
    out.print(
        f"binary accuracy {_fmt(data['binary_accuracy'])}, count accuracy {_fmt(data['count_accuracy'])} "
        f"({_fmt(data['count_accuracy_glimpses_optional'])} with instances in view < {glimpse_s:g} s "
        "optional), "
        f"position error {_err(data['position_error_median_m'])} m, time error "
        f"{_err(data['time_error_median_s'])} s, duration error {_err(data['duration_error_median_s'])} s "
        f"(DAAAM on OC-NaVQA: 0.711, 41.75 m, 107.4 s); questions in {data['files']['questions']}"
    )
    other = data["unnamed"]
    if other["questions"]:
        out.print(
            f"classes the perceiver cannot name ({', '.join(data['unnamed_classes'])}), apart: "
            f"{other['questions']} questions, binary accuracy {_fmt(other['binary_accuracy'])}, count "
            f"accuracy {_fmt(other['count_accuracy'])}, position error "
            f"{_err(other['position_error_median_m'])} m"
        )


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
