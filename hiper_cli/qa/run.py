"""``hiper eval qa`` in one call: the questions of a log's truth, its knowledge base (given, or
perceived from the log), every question asked and scored, the questions written as JSONL."""

from __future__ import annotations

import json
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError
from hiper_cli.qa.questions import generate_questions
from hiper_cli.qa.scene import load_scene_truth
from hiper_cli.qa.score import Scored, answer_question, summarise

__all__ = ["QaReport", "evaluate_qa", "pick_detector"]

# DAAAM (OC-NaVQA, real data, a cloud LLM): binary accuracy, position error (m), time error (s).
PUBLISHED = {"system": "DAAAM on OC-NaVQA", "binary_accuracy": 0.711, "position_error_m": 41.75,
             "time_error_s": 1.79 * 60}


@dataclass
class QaReport:
    log: str
    kb: str
    detector: str | None
    short_s: float
    seed: int
    figures: dict[str, Any]
    scored: list[Scored] = field(default_factory=list)
    files: dict[str, str] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"format": "hiper-eval-qa", "version": 1, "log": self.log, "kb": self.kb,
                "detector": self.detector, "short_s": self.short_s, "seed": self.seed,
                **self.figures, "published": PUBLISHED, "files": self.files, "seconds": self.seconds}


def pick_detector(log: Path, detector: str) -> str:
    """``auto``: the simulator's truth detections where the log has them, else ``yolox``."""
    if detector != "auto":
        return detector
    return "truth" if (log / "gt" / "detections.jsonl").exists() else "yolox"


def _perceive(log: Path, kb: Path, detector: str) -> None:
    from hiper_cli.pipeline import PerceiveOptions, perceive_log

    options = PerceiveOptions(stages=("background", "foreground"),
                              stage_options={"foreground": {"detector": detector}}, on_existing="replace")
    perceive_log(log, str(kb), options=options)


def evaluate_qa(
    log: str | Path,
    *,
    kb: str | None = None,
    detector: str = "auto",
    out_dir: str | Path | None = None,
    short_s: float = 15.0,
    seed: int = 0,
    min_pixel_fraction: float = 0.001,
) -> QaReport:
    """Generate the questions of ``log``, answer them from ``kb`` (default: perceive the log
    with ``detector`` into ``OUT/kb.hiper``) and score them; writes ``OUT/questions.jsonl``
    (questions with true answers) and ``OUT/answers.jsonl`` (hiper's answers, scored).
    ``min_pixel_fraction``: how much of the image an instance must cover to count as seen."""
    from hiper_cli.graph import open_kb_for_reading

    log = Path(log)
    if not short_s > 0:
        raise ConfigError(f"--short-s {short_s}: expected a positive number of seconds")
    out = Path(out_dir) if out_dir is not None else Path(tempfile.mkdtemp(prefix="hiper-qa-"))
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    scene = load_scene_truth(log, min_pixel_fraction=min_pixel_fraction)
    questions = generate_questions(scene, short_s=short_s, seed=seed)
    seconds = {"questions": time.perf_counter() - t0}
    used = None
    if kb is None:
        used = pick_detector(log, detector)
        kb = str(out / "kb.hiper")
        t0 = time.perf_counter()
        _perceive(log, Path(kb), used)
        seconds["perceive"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    with open_kb_for_reading(kb) as knowledge:
        scored = [answer_question(knowledge, q) for q in questions]
    seconds["answer"] = time.perf_counter() - t0
    files = {"questions": str(out / "questions.jsonl"), "answers": str(out / "answers.jsonl")}
    Path(files["questions"]).write_text("".join(json.dumps(q.to_dict()) + "\n" for q in questions))
    Path(files["answers"]).write_text("".join(json.dumps(s.to_dict()) + "\n" for s in scored))
    return QaReport(str(log), kb, used, short_s, seed, summarise(scored), scored, files,
                    {k: round(v, 2) for k, v in seconds.items()})
