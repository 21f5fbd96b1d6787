"""An unnamed object takes the name its views give it: class evidence fused over the session.

A track's class comes from the detections matched to its blobs frame by frame; an object whose
blobs never matched a box well enough (cut by the image, merged with a neighbour, seen from
afar) stays ``unknown`` although the detector named it in many frames. An object is fused
evidence, so its name should come from all the views that saw it, as a mapped table's does
(``table_views.py``). Every ``VIEW_STEP_S`` of log time the stage keeps the boxes of a frame
the detector looked at (the classes that could name a track), with the camera and a coarse
depth image. At the end of the session every static instance with a surface is projected into
each view (hidden where the depth measured something nearer): named ones too, so that a box
that explains a named chair does not name the unknown behind it (a box names the one instance
it overlaps most). The views vote as a track's observations do (``class_vote.py``): a static
``unknown`` takes class c when c named it in ``min_class_observations`` views, holds
``min_class_share`` of the known-class votes and outweighs ``SUPPORT_MARGIN`` times over the
views that showed it and named nothing (a class given in a few views among many silent ones is
too weakly supported), c is plausible for its size and no walker, and no instance of c lies at
the same place already. The views that named it must span ``NAMED_SPAN_S`` of log time: the
views of one glance (kept 0.2 s apart, a shelf passed in a second) repeat one look, and a
detector's word repeated on one look is no more evidence than the look.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Instance
from hiper_cli.perceive.foreground.class_vote import CUT_VIEW_WEIGHT, SUPPORT_MARGIN, UNKNOWN
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.geometry_only import SAME_OBJECT_KEY
from hiper_cli.perceive.foreground.plausible import (
    CLASS_SIZE_TOLERANCE,
    FIXTURE_CLASSES,
    longest_m,
    max_longest_m,
    min_longest_m,
)
from hiper_cli.perceive.foreground.table_views import (
    DEPTH_STEP_PX,
    TABLE_DETECTOR_CLASSES,
    Scene,
    View,
    best_overlaps,
)
from hiper_cli.perceive.foreground.unmapped_tables import TABLE_CLASS
from hiper_cli.perceive.stage import World
from hiper_cli.types import Detections, Frame

__all__ = ["ObjectViews", "name_by_views"]

FloatArray = NDArray[np.float64]

VIEW_STEP_S = 0.2  # a view is kept at most every 0.2 s of log time (5 a second) ...
MAX_VIEWS = 2000  # ... and at most this many (every other one dropped when full): ~40 MB of depth
STAMP_SLACK_S = 1e-6  # stamps this close are the same time (sums of float steps)
NAMED_SPAN_S = 1.0  # the views that name an object span this much log time: more than one glance
SURFACE_SAMPLES = 64  # an instance's surface is projected with this many of its points at most
SAME_PLACE_M = 0.5  # an instance of the class this near (centres, horizontally) is the same object
VIEWS_KEY = "view_names"  # data key: per class the views that named it, "seen" and "whole": showing it
VOTES_KEY = "view_votes"  # data key: per class (and "unknown") the votes of the views
SPANS_KEY = "view_spans_s"  # data key: per class the log time from its first view to its last
VIEW_CLASS_KEY = "view_class"  # data key: the plausible class its views named most
COUNTS = ("seen", "whole")


@dataclass
class ObjectViews:
    """The detector's boxes of one frame every ``step_s``, with the camera and coarse depth."""

    min_score: float
    walker_classes: tuple[str, ...] = ()
    step_s: float = VIEW_STEP_S
    _views: list[tuple[View, tuple[str, ...], FloatArray, float]] = field(default_factory=list)
    _last_s: float = -np.inf

    def __len__(self) -> int:
        return len(self._views)

    def add(self, frame: Frame, detections: Detections, looked: bool = True,
            tables: Detections | None = None) -> None:
        """Keep ``frame`` with the boxes of ``detections`` scored ``min_score`` or more (walkers
        left out: a person names nothing that stays), and the table boxes of ``tables`` (as
        ``table``), when the detector ``looked`` at it and ``step_s`` passed since the last
        kept; a view without boxes is kept too (it showed objects the detector did not name)."""
        if not looked or frame.stamp_s - self._last_s < self.step_s - STAMP_SLACK_S:
            return
        self._last_s = frame.stamp_s
        found = [(box, name, score) for box, name, score in _boxes(detections)
                 if score >= self.min_score and name not in self.walker_classes]
        found += [(box, TABLE_CLASS, score) for box, name, score in _boxes(tables)
                  if score >= self.min_score and name in TABLE_DETECTOR_CLASSES]
        depth = np.ascontiguousarray(frame.depth_m[::DEPTH_STEP_PX, ::DEPTH_STEP_PX])
        T_cam_map = np.asarray(np.linalg.inv(frame.T_map_cam), dtype=np.float64)
        boxes = np.array([box for box, _, _ in found], dtype=np.float64).reshape(-1, 4)
        self._views.append((View(T_cam_map, frame.camera, depth, boxes), tuple(name for _, name, _ in found),
                            np.array([score for _, _, score in found], dtype=np.float64), frame.stamp_s))
        if len(self._views) > MAX_VIEWS:
            self._views = self._views[::2]
            self.step_s *= 2.0

    def tally(self, instances: Sequence[Instance], asked: Sequence[bool],
              unknown_weight: float) -> list[tuple[dict[str, int], dict[str, float], dict[str, float]]]:
        """Per instance asked for, the views that named it per class (under ``"seen"`` the views
        that showed it: most of its surface in the image, not hidden; under ``"whole"`` those
        that showed its whole box inside the image), and the votes of those views as a track's
        (``class_vote.py``): per class its best box's score, ``unknown_weight`` for a view that
        named it nothing, times ``CUT_VIEW_WEIGHT`` where the image's border cut it. Every
        instance takes part: each box names the one instance it overlaps most (``NAMED_IOU``).
        Third, per class the log time (s) from the first view that named it so to the last."""
        scene = Scene([(i.box, _surface(i)) for i in instances])
        counts: list[dict[str, int]] = [{"seen": 0, "whole": 0} for _ in instances]
        votes: list[dict[str, float]] = [{UNKNOWN: 0.0} for _ in instances]
        spans: list[dict[str, tuple[float, float]]] = [{} for _ in instances]
        for view, classes, scores, stamp_s in self._views:
            boxes, shown_mask, whole_mask = scene.seen_in(view)
            shown = [int(k) for k in np.flatnonzero(shown_mask)]
            named = _named(view, classes, scores, boxes, shown_mask)
            for k in shown:
                whole = bool(whole_mask[k])
                weight = 1.0 if whole else CUT_VIEW_WEIGHT
                counts[k]["seen"] += 1
                counts[k]["whole"] += int(whole)
                mine = named.get(k, {UNKNOWN: unknown_weight})
                for name, score in mine.items():
                    votes[k][name] = votes[k].get(name, 0.0) + weight * score
                    if name != UNKNOWN:
                        counts[k][name] = counts[k].get(name, 0) + 1
                        spans[k][name] = (spans[k].get(name, (stamp_s, stamp_s))[0], stamp_s)
        return [(c, v, {name: last - first for name, (first, last) in f.items()})
                for c, v, f, a in zip(counts, votes, spans, asked, strict=True) if a]


def _boxes(detections: Detections | None) -> list[tuple[FloatArray, str, float]]:
    """The (box, class, score) of each detection (none for None)."""
    if detections is None:
        return []
    xyxy = np.asarray(detections.xyxy, dtype=np.float64).reshape(-1, 4)
    return [(xyxy[k], name, float(score))
            for k, (name, score) in enumerate(zip(detections.class_names, detections.scores, strict=True))]


def _named(view: View, classes: tuple[str, ...], scores: FloatArray, boxes: FloatArray,
           shown: NDArray[np.bool_]) -> dict[int, dict[str, float]]:
    """Per instance a box of ``view`` names (``best_overlaps``), per class the best score."""
    named: dict[int, dict[str, float]] = {}
    for k, name, score in zip(best_overlaps(view.boxes_xyxy, boxes, shown), classes, scores, strict=True):
        if k >= 0:
            mine = named.setdefault(k, {})
            mine[name] = max(mine.get(name, 0.0), float(score))
    return named


def name_by_views(views: ObjectViews, own: Sequence[Instance], world: World, gone: Sequence[str],
                  config: ForegroundConfig) -> list[Instance]:
    """Name the static ``unknown`` instances of ``own`` (this session's final ones, less the
    uuids ``gone``) by their views (``ObjectViews.tally``; the world's other instances take part
    as what else is there; a mapped table's object keeps the table's path): the views are kept
    in ``data["view_names"]``, their votes in ``data["view_votes"]``, their spans in
    ``data["view_spans_s"]``, the plausible class they named most in ``data["view_class"]``.
    Returns those it looked at (their data changed)."""
    seen: dict[str, Instance] = {}
    dropped = set(gone)
    for inst in (*own, *world.foreground.values()):
        if (inst.layer == "foreground" and inst.state == "static" and inst.uuid not in seen
                and inst.uuid not in dropped):
            seen[inst.uuid] = inst
    every = list(seen.values())
    own_ids = {i.uuid for i in own}
    asked = [i.uuid in own_ids and i.class_name == UNKNOWN and SAME_OBJECT_KEY not in i.data for i in every]
    if not any(asked) or not len(views):
        return []
    looked = [i for i, a in zip(every, asked, strict=True) if a]
    tallies = views.tally(every, asked, config.unknown_vote_weight)
    for inst, (counts, votes, spans) in zip(looked, tallies, strict=True):
        inst.data[VIEWS_KEY] = counts
        inst.data[VOTES_KEY] = {k: round(v, 3) for k, v in votes.items()}
        inst.data[SPANS_KEY] = {k: round(v, 2) for k, v in spans.items()}
        name = _best_name(inst, counts)
        if name is None or _same_place(inst, name, every):
            continue
        inst.data[VIEW_CLASS_KEY] = name
        if _strong(counts, votes, name, config) and spans[name] >= NAMED_SPAN_S:
            inst.class_name = name
    return looked


def _strong(counts: dict[str, int], votes: dict[str, float], name: str, config: ForegroundConfig) -> bool:
    """Whether the views name the object ``name`` as a track's votes would (``class_vote.py``):
    ``min_class_observations`` views, ``min_class_share`` of the known-class votes, and
    ``SUPPORT_MARGIN`` times the votes of the views that named it nothing."""
    known = sum(v for k, v in votes.items() if k != UNKNOWN)
    return (counts[name] >= config.min_class_observations and votes[name] >= config.min_class_share * known
            and votes[name] >= SUPPORT_MARGIN * votes[UNKNOWN])


def _best_name(inst: Instance, counts: dict[str, int]) -> str | None:
    """The class that named ``inst`` in most views when it is plausible for its size (and no
    plumbing fixture: those need a wall), or None."""
    named = {c: n for c, n in counts.items() if c not in COUNTS}
    if not named:
        return None
    name, _ = max(named.items(), key=lambda item: (item[1], item[0]))
    if name in FIXTURE_CLASSES:
        return None
    points = _surface(inst)
    longest = longest_m(points, float(inst.box.extent_m[2]))
    if longest > max_longest_m(name, CLASS_SIZE_TOLERANCE):
        return None
    if float(np.max(inst.box.extent_m)) < min_longest_m(name, CLASS_SIZE_TOLERANCE):
        return None
    return name


def _same_place(inst: Instance, name: str, every: Sequence[Instance]) -> bool:
    """Whether another instance of class ``name`` lies at ``inst``'s place (a duplicate)."""
    return any(o is not inst and o.class_name == name
               and float(np.linalg.norm(o.box.center_m[:2] - inst.box.center_m[:2])) <= SAME_PLACE_M
               for o in every)


def _surface(inst: Instance) -> FloatArray:
    """Up to ``SURFACE_SAMPLES`` points of ``inst``'s surface (map frame), else its box's corners."""
    points = inst.data.get("surface_map")
    if not points:
        return inst.box.corners()
    arr = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return arr[:: max(1, len(arr) // SURFACE_SAMPLES)]
