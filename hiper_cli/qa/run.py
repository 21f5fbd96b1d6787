"""``hiper eval qa`` in one call: the questions of a log's truth, its knowledge base (given, or
perceived from the log), every question asked and scored, the questions written as JSONL."""

from __future__ import annotations

import json
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError
from hiper_cli.evaluate import Evaluation, evaluate_kb
from hiper_cli.perceive.logs.truth import load_truth
from hiper_cli.qa.questions import generate_questions
from hiper_cli.qa.scene import load_scene_truth
from hiper_cli.qa.score import Scored, answer_question, summarise

__all__ = ["QaReport", "QaSet", "evaluate_qa", "evaluate_qa_set", "has_scene_truth", "pick_detector"]

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
    # the knowledge base scored against the log's scene truth (``hiper_cli.evaluate``), where
    # the log has one: what the answers stand on
    perception: Evaluation | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"format": "hiper-eval-qa", "version": 1, "log": self.log, "kb": self.kb,
                "detector": self.detector, "short_s": self.short_s, "seed": self.seed,
                **self.figures, "published": PUBLISHED, "files": self.files, "seconds": self.seconds,
                "perception": None if self.perception is None else self.perception.to_dict()}


def pick_detector(log: Path, detector: str) -> str:
    """``auto``: the simulator's truth detections where the log has them, else ``yolox``."""
    if detector != "auto":
        return detector
    return "truth" if (log / "gt" / "detections.jsonl").exists() else "yolox"


def vocabulary_of(log: Path, detector: str) -> frozenset[str]:
    """The classes a perceiver with ``detector`` can name: the ``truth`` detector's classes
    (``gt/noise.json``), else COCO less the indoor exclusion list; plus the background's table."""
    from hiper_cli.perceive.foreground.classes import INDOOR_EXCLUDED
    from hiper_cli.query.vocabulary import COCO

    noise = log / "gt" / "noise.json"
    if detector == "truth" and noise.exists():
        classes = set(json.loads(noise.read_text()).get("classes", []))
    else:
        classes = set(COCO) - set(INDOOR_EXCLUDED)
    return frozenset(classes | {"table"})


def seen_fraction(log: Path, default: float) -> float:
    """The share of the image an instance must cover to count as seen: the ``hiper sim``
    truth detector's own ``min_pixels`` (of 640×480) where the log has it."""
    noise = log / "gt" / "noise.json"
    if noise.exists():
        return float(json.loads(noise.read_text()).get("min_pixels", default * 640 * 480)) / (640 * 480)
    return default


def _perceive(log: Path, kb: Path, detector: str, progress: Callable[[int, int], None] | None) -> None:
    from hiper_cli.pipeline import PerceiveOptions, perceive_log

    options = PerceiveOptions(stages=("background", "foreground"),
                              stage_options={"foreground": {"detector": detector}}, on_existing="replace")
    perceive_log(log, str(kb), options=options, progress=progress)


def evaluate_qa(
    log: str | Path,
    *,
    kb: str | None = None,
    detector: str = "auto",
    out_dir: str | Path | None = None,
    short_s: float = 15.0,
    seed: int = 0,
    min_pixel_fraction: float | None = None,
    glimpse_s: float = 0.5,
    progress: Callable[[int, int], None] | None = None,
) -> QaReport:
    """Generate the questions of ``log``, answer them from ``kb`` (default: perceive the log
    with ``detector`` into ``OUT/kb.hiper``) and score them; writes ``OUT/questions.jsonl``
    (questions with true answers) and ``OUT/answers.jsonl`` (hiper's answers, scored).
    ``min_pixel_fraction``: how much of the image an instance must cover to count as seen
    (default: the sim truth detector's threshold, else 0.1 %). ``detector`` also says which
    classes the perceiver can name when ``kb`` is given. ``glimpse_s``: an instance in view less
    than this is a glimpse, which a count may leave out (``count_accuracy_glimpses_optional``).
    ``progress(done, total)`` after each frame perceived."""
    from hiper_cli.graph import open_kb_for_reading

    log = Path(log)
    if not short_s > 0:
        raise ConfigError(f"--short-s {short_s}: expected a positive number of seconds")
    if not glimpse_s >= 0:
        raise ConfigError(f"--glimpse-s {glimpse_s}: expected zero or a positive number of seconds")
    out = Path(out_dir) if out_dir is not None else Path(tempfile.mkdtemp(prefix="hiper-qa-"))
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    fraction = seen_fraction(log, 0.001) if min_pixel_fraction is None else min_pixel_fraction
    scene = load_scene_truth(log, min_pixel_fraction=fraction)
    used = pick_detector(log, detector)
    questions = generate_questions(scene, short_s=short_s, seed=seed, vocabulary=vocabulary_of(log, used),
                                   glimpse_s=glimpse_s)
    seconds = {"questions": time.perf_counter() - t0}
    if kb is None:
        kb = str(out / "kb.hiper")
        t0 = time.perf_counter()
        _perceive(log, Path(kb), used, progress)
        seconds["perceive"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    with open_kb_for_reading(kb) as knowledge:
        scored = [answer_question(knowledge, q) for q in questions]
    seconds["answer"] = time.perf_counter() - t0
    files = {"questions": str(out / "questions.jsonl"), "answers": str(out / "answers.jsonl")}
    Path(files["questions"]).write_text("".join(json.dumps(q.to_dict()) + "\n" for q in questions))
    Path(files["answers"]).write_text("".join(json.dumps(s.to_dict()) + "\n" for s in scored))
    figures = summarise(scored) | {"seen_min_pixels": scene.min_pixels, "glimpse_s": glimpse_s}
    t0 = time.perf_counter()
    perception = evaluate_kb(kb, log) if has_scene_truth(log) else None
    seconds["perception"] = time.perf_counter() - t0
    return QaReport(str(log), kb, used, short_s, seed, figures, scored, files,
                    {k: round(v, 2) for k, v in seconds.items()}, perception)


def has_scene_truth(log: Path) -> bool:
    """The log's truth can score a knowledge base's instances (``evaluate_kb``)."""
    return (log / "gt" / "instances.json").is_file() and (log / "gt" / "surface_points.npz").is_file()


@dataclass
class QaSet:
    """Several logs asked as one benchmark: each log's report, and ``figures`` over every
    question of them all (a median over all position errors, not a median of medians)."""

    reports: list[QaReport]
    figures: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        return {"format": "hiper-eval-qa-set", "version": 1, "logs": [r.to_dict() for r in self.reports],
                **self.figures, "published": PUBLISHED}


def log_folders(logs: list[Path], out_dir: Path) -> list[Path]:
    """One folder per log under ``out_dir``, named after the log (``name-2`` for a repeat)."""
    folders: list[Path] = []
    for log in logs:
        base = log.resolve().name or "log"
        name, k = base, 1
        while out_dir / name in folders:
            k += 1
            name = f"{base}-{k}"
        folders.append(out_dir / name)
    return folders


def evaluate_qa_set(
    logs: list[Path],
    *,
    kbs: list[str] | None = None,
    out_dir: str | Path | None = None,
    on_log: Callable[[int, Path], Callable[[int, int], None] | None] | None = None,
    **options: Any,
) -> QaSet:
    """``evaluate_qa`` on each of ``logs`` (answered from ``kbs[i]`` when given, one per log),
    each writing into its own folder under ``out_dir``; pooled figures over all questions.
    ``on_log(i, log)`` before each log returns its frame progress callback."""
    if kbs is not None and len(kbs) != len(logs):
        logs_text = f"{len(logs)} log" + ("s" if len(logs) != 1 else "")
        raise ConfigError(f"{len(kbs)} --kb for {logs_text}: give --kb once per LOG, "
                          "in the same order, or leave it out to perceive each log")
    for log in logs:  # a missing gt/ is named before any log is perceived
        load_truth(log)
    root = Path(out_dir) if out_dir is not None else Path(tempfile.mkdtemp(prefix="hiper-qa-"))
    reports = []
    for i, (log, folder) in enumerate(zip(logs, log_folders(logs, root), strict=True)):
        progress = on_log(i, log) if on_log is not None else None
        reports.append(evaluate_qa(log, kb=None if kbs is None else kbs[i], out_dir=folder,
                                   progress=progress, **options))
    scored = [s for r in reports for s in r.scored]
    glimpse_s = reports[0].figures["glimpse_s"] if reports else options.get("glimpse_s", 0.5)
    return QaSet(reports, summarise(scored) | {"glimpse_s": glimpse_s})
