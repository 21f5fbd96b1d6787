"""Detectors that replay detections instead of running a model: ``log`` and ``truth``."""

from __future__ import annotations

import bisect
from pathlib import Path

from hiper_cli.errors import ConfigError
from hiper_cli.types import Detections, Frame

__all__ = ["LogDetector", "TruthDetector"]


class LogDetector:
    """The detections recorded in the log itself (``Frame.detections``); none when absent."""

    name = "log"

    def __init__(self, min_score: float = 0.0) -> None:
        self.min_score = float(min_score)

    def detect(self, frame: Frame) -> Detections:
        dets = frame.detections
        if dets is None or len(dets) == 0:
            return Detections.empty()
        return _above(dets, self.min_score)


class TruthDetector:
    """The simulator's noisy ground-truth detections, ``LOG/gt/detections.jsonl``.

    Detections are matched to a frame by stamp (nearest within ``stamp_tolerance_s``); a frame
    without a record has no detections. The ``instance_id`` of each record is dropped: the
    detector must not leak the truth beyond what a real detector would give.
    """

    name = "truth"

    def __init__(self, log_path: Path, min_score: float = 0.0, stamp_tolerance_s: float = 0.005) -> None:
        from hiper_cli.errors import LogError
        from hiper_cli.perceive.logs.truth import load_truth

        try:
            records = load_truth(log_path).load_detections()
        except LogError as err:
            raise ConfigError(f"detector 'truth': {err}") from err
        self._stamps = sorted(records)
        self._by_stamp = {s: Detections.from_records(r) for s, r in records.items()}
        # the classes the truth can report: those in its records
        self.class_names = tuple(sorted({n for d in self._by_stamp.values() for n in d.class_names}))
        self.min_score = float(min_score)
        self.stamp_tolerance_s = float(stamp_tolerance_s)

    def detect(self, frame: Frame) -> Detections:
        stamps = self._stamps
        i = bisect.bisect_left(stamps, frame.stamp_s)
        best: float | None = None
        for j in (i - 1, i):
            if not 0 <= j < len(stamps):
                continue
            if best is None or abs(stamps[j] - frame.stamp_s) < abs(best - frame.stamp_s):
                best = stamps[j]
        if best is None or abs(best - frame.stamp_s) > self.stamp_tolerance_s:
            return Detections.empty()
        return _above(self._by_stamp[best], self.min_score)


def _above(dets: Detections, min_score: float) -> Detections:
    if min_score <= 0.0:
        return dets
    keep = dets.scores >= min_score
    return Detections(
        dets.xyxy[keep], tuple(n for n, k in zip(dets.class_names, keep, strict=True) if k), dets.scores[keep]
    )
