"""Measurements against ground truth: the paper's tables, ours beside them.

One way to measure, whichever command asks: every scoring returns an ``Evaluation`` (the
background, foreground, speed, localisation, recall and timing figures):

- ``evaluate_kb(kb_or_export, log)``: what a knowledge base (or its JSON export) holds, scored
  against ``log``'s ground truth (``hiper eval scene``, ``hiper eval qa``);
- ``perceive_and_score(log, ...)``: an in-memory perception run scored per observation
  (``hiper eval foreground``, ``hiper bench``, ``hiper eval feedback``);
- ``evaluate_foreground`` / ``evaluate_background``: the paper's Table III / Table II reports;
  ``detector_ceiling``: what the 2D detector alone finds; ``evaluate_changes``: a knowledge base
  of several sessions against the changes ``hiper sim --sessions`` made (``hiper eval changes``).
"""

from hiper_cli.evaluate.background import BackgroundReport, evaluate_background
from hiper_cli.evaluate.changes import ChangeReport, evaluate_changes
from hiper_cli.evaluate.detector import DetectorCeiling, detector_ceiling, recall_beside_ceiling
from hiper_cli.evaluate.foreground import (
    ForegroundReport,
    ForegroundRun,
    PerceptionScore,
    evaluate_foreground,
    parse_settings,
    perceive_and_score,
)
from hiper_cli.evaluate.kb import evaluate_kb
from hiper_cli.evaluate.result import SECTIONS, Evaluation

__all__ = [
    "SECTIONS",
    "BackgroundReport",
    "ChangeReport",
    "DetectorCeiling",
    "Evaluation",
    "ForegroundReport",
    "ForegroundRun",
    "PerceptionScore",
    "detector_ceiling",
    "evaluate_background",
    "evaluate_changes",
    "evaluate_foreground",
    "evaluate_kb",
    "parse_settings",
    "perceive_and_score",
    "recall_beside_ceiling",
]
