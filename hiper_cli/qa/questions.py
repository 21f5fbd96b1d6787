"""Questions in the NaVQA style generated from a log's truth, each with its true answer and
the plain words the query layer reads. Kinds: ``yes_no``, ``count``, ``position``, ``time``,
``duration``; horizons: ``short`` (the last ``short_s`` seconds) and ``long`` (the whole log).
Deterministic for a seed (the seed draws the times of "after T"/"before T" questions).

A count's true answer holds every instance in view in the horizon, however briefly; the
question also says how many of them were in view less than ``glimpse_s`` (``glimpsed``: a cup
seen in two frames as the camera turned, a person who came into range in the log's last
0.2 s), which no perceiver that confirms what it sees can count. The score reports the count
accuracy both ways (``score.py``)."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from hiper_cli.qa.scene import SceneTruth
from hiper_cli.query.results import iso_time
from hiper_cli.query.vocabulary import plural

__all__ = ["KINDS", "QUESTION_FORMAT", "Question", "generate_questions"]

KINDS = ("yes_no", "count", "position", "time", "duration")
QUESTION_FORMAT = "hiper-qa-question"
# Asked about in every log whether it holds them or not (the "no" answers of yes/no questions).
COMMON_CLASSES = ("person", "chair", "couch", "bed", "tv", "bottle", "cup", "laptop", "refrigerator",
                  "potted plant", "book", "bicycle", "table")
NEAR_RADIUS_M = 2.0


@dataclass(frozen=True)
class Question:
    """One question: ``text`` for the query layer (or any agent), asked at ``now_s`` from
    ``pose`` (x, y, z, yaw; the robot's last pose); ``answer``: bool, int, [x, y, z] (m),
    a stamp (s) or a duration (s) by ``kind``."""

    id: str
    kind: str
    horizon: str
    text: str
    answer: Any
    now_s: float
    pose: tuple[float, float, float, float]
    class_name: str
    # Whether the perceiver can name the class (its detector's vocabulary, or a background
    # class); the headline figures are over these, the others are reported apart.
    named: bool = True
    # Count questions: how many of the ``answer`` instances were in view less than the
    # generator's ``glimpse_s`` in the horizon.
    glimpsed: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"format": QUESTION_FORMAT, "version": 1, **asdict(self),
                "now_iso": iso_time(self.now_s), "pose": list(self.pose)}


def _clock(stamp_s: float) -> str:
    return iso_time(stamp_s)[11:19]  # HH:MM:SS, the grammar's time of day


def _whole_second(stamp_s: float) -> float:
    """The stamp ``_clock`` writes: the question's words hold whole seconds, so its true answer
    must be taken at that second, not at the drawn stamp (a bottle seen at 36.03 s was there
    "after 00:00:36", whatever fraction was drawn)."""
    return float(np.floor(stamp_s))


def _in_view_s(stamps: np.ndarray, gap_s: float) -> float:
    dt = np.diff(stamps)
    return float(dt[dt <= gap_s].sum())


class _Builder:
    def __init__(
        self,
        scene: SceneTruth,
        short_s: float,
        seed: int,
        view_gap_s: float,
        vocabulary: frozenset[str] | None,
        glimpse_s: float,
    ) -> None:
        self.scene, self.short_s, self.gap, self.vocabulary = scene, short_s, view_gap_s, vocabulary
        self.glimpse_s = glimpse_s
        self.rng = np.random.default_rng(seed)
        self.out: list[Question] = []
        self.since = scene.now_s - short_s

    def add(self, kind: str, horizon: str, text: str, answer: Any, cls: str, glimpsed: int = 0) -> None:
        qid = f"q{len(self.out):04d}"
        named = self.vocabulary is None or cls in self.vocabulary
        self.out.append(Question(qid, kind, horizon, text, answer, self.scene.now_s, self.scene.pose, cls,
                                 named, glimpsed))

    def seen_in(self, cls: str, lo: float, hi: float) -> list[int]:
        """Instances of ``cls`` seen at some stamp in [lo, hi]."""
        return [i.id for i in self.scene.instances(cls)
                if np.any((self.scene.seen[i.id] >= lo - 1e-6) & (self.scene.seen[i.id] <= hi + 1e-6))]

    def yes_no(self, classes: list[str]) -> None:
        s, short = self.scene, f"in the last {self.short_s:g} seconds"
        for cls in classes:
            self.add("yes_no", "long", f"is there a {cls}", bool(self.seen_in(cls, s.start_s, s.now_s)), cls)
            self.add("yes_no", "short", f"is there a {cls} {short}",
                     bool(self.seen_in(cls, self.since, s.now_s)), cls)
            near = any(s.distance_m(i) <= NEAR_RADIUS_M for i in s.instances(cls))
            self.add("yes_no", "long", f"is there a {cls} within {NEAR_RADIUS_M:g} m of me", near, cls)
            t = _whole_second(self.rng.uniform(s.start_s, s.now_s))
            horizon = "short" if s.now_s - t <= self.short_s else "long"
            self.add("yes_no", horizon, f"was there a {cls} after {_clock(t)}",
                     bool(self.seen_in(cls, t, s.now_s)), cls)
            t = _whole_second(self.rng.uniform(s.start_s, s.now_s))
            self.add("yes_no", "long", f"was there a {cls} before {_clock(t)}",
                     bool(self.seen_in(cls, s.start_s, t)), cls)

    def glimpsed(self, ids: list[int], lo: float, hi: float) -> int:
        """How many of ``ids`` were in view less than ``glimpse_s`` within [lo, hi]."""
        def in_view_s(i: int) -> float:
            stamps = self.scene.seen[i]
            return _in_view_s(stamps[(stamps >= lo - 1e-6) & (stamps <= hi + 1e-6)], self.gap)

        return sum(in_view_s(i) < self.glimpse_s for i in ids)

    def counts(self, classes: list[str]) -> None:
        s = self.scene
        for cls in classes:
            ids = self.seen_in(cls, s.start_s, s.now_s)
            self.add("count", "long", f"how many {plural(cls)}", len(ids), cls,
                     self.glimpsed(ids, s.start_s, s.now_s))
            ids = self.seen_in(cls, self.since, s.now_s)
            self.add("count", "short", f"how many {plural(cls)} in the last {self.short_s:g} seconds",
                     len(ids), cls, self.glimpsed(ids, self.since, s.now_s))

    def positions(self, classes: list[str]) -> None:
        s = self.scene
        for cls in classes:
            insts = s.instances(cls)
            nearest = min(insts, key=s.distance_m)
            self.add("position", "long", f"where is the closest {cls}",
                     s.last_position(nearest).tolist(), cls)
            # several last seen in one frame: the nearest of them (the query layer's rule)
            last = max(insts, key=lambda i: (float(s.seen[i.id][-1]), -s.distance_m(i)))
            self.add("position", "long", f"where was the {cls} last seen",
                     s.last_position(last).tolist(), cls)
            recent = [i for i in insts if i.id in self.seen_in(cls, self.since, s.now_s)]
            if recent:
                near = min(recent, key=s.distance_m)
                self.add("position", "short",
                         f"where is the closest {cls} in the last {self.short_s:g} seconds",
                         s.last_position(near).tolist(), cls)

    def times(self, classes: list[str]) -> None:
        s = self.scene
        for cls in classes:
            stamps = np.concatenate([s.seen[i.id] for i in s.instances(cls)])
            self.add("time", "long", f"when was the {cls} last seen", float(stamps.max()), cls)
            self.add("time", "long", f"when was the {cls} first seen", float(stamps.min()), cls)
            if stamps.max() >= self.since:
                self.add("time", "short",
                         f"when was the {cls} last seen in the last {self.short_s:g} seconds",
                         float(stamps.max()), cls)

    def durations(self, classes: list[str]) -> None:
        s = self.scene
        for cls in classes:
            insts = s.instances(cls)
            if len(insts) == 1:
                self.add("duration", "long", f"how long was the {cls} in view",
                         _in_view_s(s.seen[insts[0].id], self.gap), cls)
            else:
                near = min(insts, key=s.distance_m)
                self.add("duration", "long", f"how long was the closest {cls} in view",
                         _in_view_s(s.seen[near.id], self.gap), cls)


def generate_questions(
    scene: SceneTruth,
    *,
    short_s: float = 15.0,
    seed: int = 0,
    view_gap_s: float = 1.0,
    vocabulary: frozenset[str] | None = None,
    glimpse_s: float = 0.5,
) -> list[Question]:
    """Every question of every kind about the classes the log shows (and, for yes/no, common
    indoor classes it may not show); ``view_gap_s`` as the query layer's ``QueryConfig``;
    ``vocabulary``: the classes the perceiver can name (None: all), which marks each question
    ``named`` or not; ``glimpse_s``: a count question's ``glimpsed`` instances were in view
    less than this."""
    from hiper_cli.query.vocabulary import resolve_class

    present = [c for c in scene.classes() if resolve_class(c) == c]
    b = _Builder(scene, short_s, seed, view_gap_s, vocabulary, glimpse_s)
    b.yes_no(sorted(set(present) | set(COMMON_CLASSES)))
    b.counts(present)
    b.positions(present)
    b.times(present)
    b.durations(present)
    return b.out
