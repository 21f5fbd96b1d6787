"""Ask each question through the query layer and score its answer against the truth: binary
accuracy (yes/no), count accuracy, position error (m), time error (s), duration error (s), per
kind and horizon. A question the layer cannot answer scores as wrong (an infinite error).

A count is right when it equals the truth (``count_accuracy``, the headline); beside it,
``count_accuracy_glimpses_optional`` takes a count as right when it lies between the truth less
its glimpsed instances and the truth (``Question.glimpsed``): what is left is what the perceiver
missed or doubled among the things it had time to see."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiper_cli.errors import HiperError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.qa.questions import KINDS, Question
from hiper_cli.query import Answer, ask

__all__ = ["Scored", "answer_question", "summarise"]


@dataclass(frozen=True)
class Scored:
    """A question, what hiper answered (None: no answer) and its score: ``correct`` for yes/no
    and count, ``error`` (m or s, ``inf`` when unanswered) for the others; a position's error
    is horizontal (where a robot would go), ``error_3d`` the full one."""

    question: Question
    predicted: Any
    correct: bool | None
    error: float | None
    text: str
    error_3d: float | None = None
    # count questions: right with the glimpsed instances counted or not
    right_but_glimpses: bool | None = None

    def to_dict(self) -> dict[str, Any]:
        err = None if self.error is None or math.isinf(self.error) else self.error
        return {"id": self.question.id, "kind": self.question.kind, "horizon": self.question.horizon,
                "question": self.question.text, "truth": self.question.answer, "predicted": self.predicted,
                "correct": self.correct, "error": err, "error_3d": self.error_3d,
                "answered": self.predicted is not None, "named": self.question.named,
                "hiper_text": self.text,
                **({"glimpsed": self.question.glimpsed, "right_but_glimpses": self.right_but_glimpses}
                   if self.question.kind == "count" else {})}


def _predicted(q: Question, a: Answer) -> Any:
    if q.kind == "yes_no":
        return a.value
    if q.kind == "count":
        return a.count
    if q.kind == "position":
        return list(a.hits[0].center_map_m) if a.hits else None
    if q.kind == "time":
        return None if a.time is None else a.time.stamp_s
    return a.duration_s


def answer_question(kb: KnowledgeBase, q: Question) -> Scored:
    """Ask ``q`` from its pose at its now; score the answer."""
    try:
        a = ask(kb, q.text, pose=q.pose, now_s=q.now_s)
    except HiperError as failure:
        binary = q.kind in ("yes_no", "count")
        return Scored(q, None, False if binary else None, None if binary else math.inf, f"error: {failure}",
                      right_but_glimpses=False if q.kind == "count" else None)
    p = _predicted(q, a)
    if q.kind == "yes_no":
        return Scored(q, p, p is not None and p == q.answer, None, a.text)
    if q.kind == "count":
        within = p is not None and q.answer - q.glimpsed <= p <= q.answer
        return Scored(q, p, p is not None and p == q.answer, None, a.text, right_but_glimpses=within)
    if p is None:
        return Scored(q, None, None, math.inf, a.text)
    if q.kind == "position":
        delta = np.asarray(p) - np.asarray(q.answer)
        return Scored(q, p, None, float(np.linalg.norm(delta[:2])), a.text, float(np.linalg.norm(delta)))
    return Scored(q, p, None, abs(float(p) - float(q.answer)), a.text)


def _figures(rows: list[Scored]) -> dict[str, Any]:
    out: dict[str, Any] = {"n": len(rows), "answered": sum(r.predicted is not None for r in rows)}
    if not rows:
        return out
    if rows[0].question.kind in ("yes_no", "count"):
        out["accuracy"] = sum(bool(r.correct) for r in rows) / len(rows)
        if rows[0].question.kind == "count":
            out["accuracy_glimpses_optional"] = sum(bool(r.right_but_glimpses) for r in rows) / len(rows)
            out["glimpsed"] = sum(r.question.glimpsed for r in rows)
    else:
        errs = np.array([r.error for r in rows], dtype=np.float64)
        out["median_error"] = float(np.median(errs))
        finite = errs[np.isfinite(errs)]
        out["median_error_answered"] = float(np.median(finite)) if len(finite) else None
        if rows[0].question.kind == "position":
            full = np.array([math.inf if r.error_3d is None else r.error_3d for r in rows])
            out["median_error_3d"] = float(np.median(full))
    if rows[0].question.kind == "yes_no":  # most questions are "no": show both sides
        yes = [r for r in rows if r.question.answer]
        no = [r for r in rows if not r.question.answer]
        out["true_yes"] = len(yes)
        out["accuracy_on_yes"] = sum(bool(r.correct) for r in yes) / len(yes) if yes else None
        out["accuracy_on_no"] = sum(bool(r.correct) for r in no) / len(no) if no else None
    return out


def summarise(scored: list[Scored]) -> dict[str, Any]:
    """Headline figures and the breakdown per kind and horizon over the questions about classes
    the perceiver can name; the same for the others under ``unnamed``."""
    named = [r for r in scored if r.question.named]
    return _summary(named) | {"unnamed": _summary([r for r in scored if not r.question.named]),
                              "unnamed_classes": sorted({r.question.class_name for r in scored
                                                         if not r.question.named})}


def _summary(scored: list[Scored]) -> dict[str, Any]:
    by: dict[str, Any] = {}
    for kind in KINDS:
        rows = [r for r in scored if r.question.kind == kind]
        by[kind] = {"all": _figures(rows)} | {
            h: _figures([r for r in rows if r.question.horizon == h]) for h in ("short", "long")
        }

    def get(kind: str, key: str) -> Any:
        return by[kind]["all"].get(key)

    def finite(v: Any) -> Any:
        return None if v is None or (isinstance(v, float) and math.isinf(v)) else v

    return {
        "questions": len(scored),
        "binary_accuracy": get("yes_no", "accuracy"),
        "count_accuracy": get("count", "accuracy"),
        "count_accuracy_glimpses_optional": get("count", "accuracy_glimpses_optional"),
        "position_error_median_m": finite(get("position", "median_error")),
        "position_error_3d_median_m": finite(get("position", "median_error_3d")),
        "time_error_median_s": finite(get("time", "median_error")),
        "duration_error_median_s": finite(get("duration", "median_error")),
        "by_kind": {k: {h: {key: finite(val) for key, val in f.items()} for h, f in v.items()}
                    for k, v in by.items()},
    }
