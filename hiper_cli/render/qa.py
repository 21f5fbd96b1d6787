"""What ``hiper eval qa`` shows: figures per kind and horizon, per log, and the headline."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hiper_cli.render.text import safe_text

__all__ = ["show_qa", "show_qa_set"]


def _fmt(v: Any, digits: int = 3) -> str:
    return "-" if v is None else f"{v:.{digits}f}" if isinstance(v, float) else str(v)


def _err(v: Any) -> str:
    """A median error; None when over half the questions went unanswered (infinite)."""
    return "inf" if v is None else _fmt(v)


def show_qa(out: Any, data: dict[str, Any], log: Path, kb: str | None, glimpse_s: float) -> None:
    """One log's benchmark (answered from ``kb``, else perceived): the kinds, then the headline."""
    title = f"hiper eval qa {log} (detector {data['detector']}"
    title += f", answers from {kb})" if kb else ")"
    _print_kinds(out, data, title)
    _print_headline(out, data, glimpse_s, f"questions in {data['files']['questions']}")


def show_qa_set(out: Any, data: dict[str, Any], glimpse_s: float) -> None:
    """Several logs as one benchmark: per log, the kinds over all, the headline over all."""
    n = len(data["logs"])
    _print_logs(out, data)
    _print_kinds(out, data, f"hiper eval qa: all {n} logs")
    _print_headline(out, data, glimpse_s, f"over all {n} logs")


def _print_logs(out: Any, data: dict[str, Any]) -> None:
    from rich.table import Table

    table = Table("log", "detector", "questions", "binary", "count", "count, glimpses optional",
                  "position m", "time s", "duration s", title="hiper eval qa, per log")
    for row in [*data["logs"], {**data, "log": "all", "detector": ""}]:
        name = safe_text(Path(row["log"]).name) if row["log"] != "all" else "[bold]all"
        table.add_row(name, safe_text(row["detector"]),
                      str(row["questions"]), _fmt(row["binary_accuracy"]), _fmt(row["count_accuracy"]),
                      _fmt(row["count_accuracy_glimpses_optional"]), _err(row["position_error_median_m"]),
                      _err(row["time_error_median_s"]), _err(row["duration_error_median_s"]))
    out.print(table)


def _kind_row(kind: str, f: dict[str, Any]) -> tuple[str, str]:
    """The figure and the detail of one kind of question at one horizon."""
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
    return value, note


def _print_kinds(out: Any, data: dict[str, Any], title: str) -> None:
    from rich.table import Table

    table = Table("kind", "horizon", "questions", "answered", "accuracy / median error", "detail",
                  title=title)
    for kind, by in data["by_kind"].items():
        for horizon in ("short", "long", "all"):
            f = by[horizon]
            if f.get("n"):
                table.add_row(kind, horizon, str(f["n"]), str(f["answered"]), *_kind_row(kind, f))
    out.print(table)


def _print_headline(out: Any, data: dict[str, Any], glimpse_s: float, where: str) -> None:
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
