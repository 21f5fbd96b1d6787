"""``hiper eval qa``: a question-answering benchmark from a log's ground truth."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import console, frame_progress, print_json, safe_text
from hiper_cli.commands.eval import eval_app


def _fmt(v: Any, digits: int = 3) -> str:
    return "-" if v is None else f"{v:.{digits}f}" if isinstance(v, float) else str(v)


def _err(v: Any) -> str:
    """A median error; None when over half the questions went unanswered (infinite)."""
    return "inf" if v is None else _fmt(v)


@eval_app.command("qa")
def qa(
    logs: Annotated[list[Path], typer.Argument(
        help="Logs with ground truth: hiper sim's gt/ or a world's gt/. Several are one benchmark: "
        "figures per log and over all their questions.")],
    kb: Annotated[
        list[str] | None, typer.Option("--kb", help="Answer from this knowledge base (default: perceive the "
                                       "log); once per LOG, in order, for several logs.")
    ] = None,
    detector: Annotated[
        str, typer.Option("--detector", help="When perceiving: auto (truth where the log has gt/detections."
                          "jsonl, else yolox), truth, yolox, log or onnx:PATH.")
    ] = "auto",
    out_dir: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Folder for questions.jsonl, answers.jsonl (and kb.hiper); with "
                     "several logs, a folder per log in it."),
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

    Example: hiper eval qa out/house_1 out/office_2 out/hospital_3 -o out/qa
    """
    from hiper_cli.qa import evaluate_qa, evaluate_qa_set

    options: dict[str, Any] = {"detector": detector, "short_s": short_s, "seed": seed, "glimpse_s": glimpse_s}
    if len(logs) == 1 and (kb is None or len(kb) == 1):
        with frame_progress("perceive", console(), enabled=not as_json and kb is None) as bar:
            report = evaluate_qa(logs[0], kb=kb[0] if kb else None, out_dir=out_dir,
                                 progress=None if bar is None else bar.update, **options)
        data = report.to_dict()
        if as_json:
            print_json(data)
            return
        title = f"hiper eval qa {logs[0]} (detector {report.detector}"
        title += f", answers from {kb[0]})" if kb else ")"
        _print_kinds(data, title)
        _print_headline(data, glimpse_s, f"questions in {data['files']['questions']}")
        return
    bars = ExitStack()  # one bar at a time: rich shows a single live display

    def on_log(i: int, log: Path) -> Any:
        bars.close()
        if as_json or kb is not None:
            return None
        bar = bars.enter_context(frame_progress(f"perceive {i + 1}/{len(logs)} {log.name}", console()))
        return None if bar is None else bar.update

    with bars:
        result = evaluate_qa_set(logs, kbs=kb, out_dir=out_dir, on_log=on_log, **options)
    data = result.to_dict()
    if as_json:
        print_json(data)
        return
    _print_logs(data)
    _print_kinds(data, f"hiper eval qa: all {len(logs)} logs")
    _print_headline(data, glimpse_s, f"over all {len(logs)} logs")


def _print_logs(data: dict[str, Any]) -> None:
    from rich.table import Table

    table = Table("log", "detector", "questions", "binary", "count", "count, glimpses optional",
                  "position m", "time s", "duration s", title="hiper eval qa, per log")
    for row in [*data["logs"], {**data, "log": "all", "detector": ""}]:
        name = safe_text(Path(row["log"]).name) if row["log"] != "all" else "[bold]all"
        table.add_row(name, safe_text(row["detector"]),
                      str(row["questions"]), _fmt(row["binary_accuracy"]), _fmt(row["count_accuracy"]),
                      _fmt(row["count_accuracy_glimpses_optional"]), _err(row["position_error_median_m"]),
                      _err(row["time_error_median_s"]), _err(row["duration_error_median_s"]))
    console().print(table)


def _print_kinds(data: dict[str, Any], title: str) -> None:
    from rich.table import Table

    table = Table("kind", "horizon", "questions", "answered", "accuracy / median error", "detail",
                  title=title)
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
    console().print(table)


def _print_headline(data: dict[str, Any], glimpse_s: float, where: str) -> None:
    out = console()
    out.print(
        f"binary accuracy {_fmt(data['binary_accuracy'])}, count accuracy {_fmt(data['count_accuracy'])} "
        f"({_fmt(data['count_accuracy_glimpses_optional'])} with instances in view < {glimpse_s:g} s "
        "optional), "
        f"position error {_err(data['position_error_median_m'])} m, time error "
        f"{_err(data['time_error_median_s'])} s, duration error {_err(data['duration_error_median_s'])} s "
        f"(DAAAM on OC-NaVQA: 0.711, 41.75 m, 107.4 s); {safe_text(where)}"
    )
    other = data["unnamed"]
    if other["questions"]:
        out.print(
            f"classes the perceiver cannot name ({safe_text(', '.join(data['unnamed_classes']))}), apart: "
            f"{other['questions']} questions, binary accuracy {_fmt(other['binary_accuracy'])}, count "
            f"accuracy {_fmt(other['count_accuracy'])}, position error "
            f"{_err(other['position_error_median_m'])} m"
        )


def register(app: typer.Typer) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
