"""What people carry is part of them: detections of carried things inside a person's box.

A bag on a walker's arm, a phone at an ear or an umbrella over a head moves with the person,
and its depth lies on the person's body: the blob under it is the person's arm or torso, cut
from the legs by the bag's own box (``refine`` joins the pieces of one box, the smallest
holding them). A detection of a carried class (``carried_classes``) whose box lies for the
most part (``carried_containment`` of its area) inside the box of a walker detection of the
same frame is therefore not an object of its own: it is dropped before refinement, like an
excluded class, and the person's box joins and names the pieces. A bag on a chair or a
suitcase standing alone keeps its detection.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from hiper_cli.types import Detections

__all__ = ["drop_carried"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
CARRIED_CLASSES: tuple[str, ...] = ("backpack", "umbrella", "handbag", "tie", "suitcase", "cell phone")
"""Things people carry (``carried.py``): a detection of one of these classes whose box lies
inside a walker detection's box (``carried_containment`` of its area) is part of that person
(a bag on a walker's arm, a phone at an ear) and is dropped before refinement, so the
person's box names the blob; empty: off."""
CARRIED_CONTAINMENT: float = 0.8


def drop_carried(
    detections: Detections,
    carried: Iterable[str],
    walkers: Iterable[str],
    min_containment: float,
    min_score: float = 0.0,
) -> Detections:
    """``detections`` without those of a class in ``carried`` whose box has at least
    ``min_containment`` of its area inside the box of a detection of a class in ``walkers``
    scoring at least ``min_score``."""
    carried_set, walker_set = frozenset(carried), frozenset(walkers)
    names = detections.class_names
    if len(detections) < 2 or not carried_set or min_containment > 1.0:
        return detections
    is_carried = np.array([n in carried_set for n in names], dtype=bool)
    is_walker = np.array([n in walker_set for n in names], dtype=bool) & (detections.scores >= min_score)
    if not is_carried.any() or not is_walker.any():
        return detections
    xyxy = detections.xyxy
    item, person = xyxy[is_carried], xyxy[is_walker]
    lo = np.maximum(item[:, None, :2], person[None, :, :2])
    hi = np.minimum(item[:, None, 2:], person[None, :, 2:])
    iw, ih = np.clip(hi - lo, 0.0, None).transpose(2, 0, 1)
    area = (item[:, 2] - item[:, 0]) * (item[:, 3] - item[:, 1])
    share = (iw * ih).max(axis=1) / np.where(area > 0, area, 1.0)
    drop = np.zeros(len(detections), dtype=bool)
    drop[np.flatnonzero(is_carried)] = (share >= min_containment) & (area > 0)
    if not drop.any():
        return detections
    return detections.subset(~drop)
