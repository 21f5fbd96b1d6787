"""Which detector classes the foreground stage accepts (the paper's Table III footnote).

The paper: "Not present classes, such as boat and traffic light, have been excluded
beforehand." hiper does the same with two options of ``ForegroundConfig``, applied to the
detections of every frame before refinement and matching (so ``hiper perceive`` and
``hiper eval foreground`` filter identically):

- ``exclude_classes`` (default ``INDOOR_EXCLUDED``): COCO classes that are not found indoors
  (vehicles, street furniture, farm and wild animals, outdoor sports gear), plus
  ``dining table``: hiper's background layer already models tables (their top planes), so a
  table detection would only name the table's legs or a chair beside it as a foreground object;
  the stage keeps those boxes apart to name the bodies of the mapped tables (``table_views.py``);
- ``classes`` (default empty: all): an allow-list for one environment, e.g. the classes a
  house can contain; when given, every other class is dropped.

A dropped detection is as if the detector had not reported it: its blob stays ``unknown``.

A detector's non-maximum suppression is per class, so an object it cannot name for sure (a
bottle or a vase, a bench or a chair) keeps two boxes of different classes in one place, and
the frames where the second name wins can start a track of their own. ``one_name_per_box``
keeps, of two boxes of different classes that overlap by ``same_box_iou`` (IoU), the one with
the higher score: a cup in a hand or a bottle on a table overlap far less. People are left out
(``walker_classes``): a person seated in an armchair can fill the chair's box.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from hiper_cli.perceive.foreground.match import iou_matrix
from hiper_cli.types import Detections

__all__ = ["INDOOR_EXCLUDED", "filter_classes", "one_name_per_box"]

INDOOR_EXCLUDED: tuple[str, ...] = (
    "bicycle", "car", "motorcycle", "airplane", "bus", "train", "truck", "boat",
    "traffic light", "fire hydrant", "stop sign", "parking meter",
    "bird", "horse", "sheep", "cow", "elephant", "bear", "zebra", "giraffe",
    "frisbee", "skis", "snowboard", "kite", "baseball bat", "baseball glove", "skateboard",
    "surfboard", "tennis racket",
    "dining table",
)  # fmt: skip
"""Classes of COCO dropped by default: not present indoors, or modelled by the background
layer (``dining table``)."""


def filter_classes(
    detections: Detections, classes: Iterable[str] = (), exclude: Iterable[str] = ()
) -> Detections:
    """``detections`` without the classes in ``exclude`` and, when ``classes`` is not empty,
    without every class outside it."""
    allow = frozenset(classes)
    deny = frozenset(exclude)
    if len(detections) == 0 or not (allow or deny):
        return detections
    keep = np.array(
        [(not allow or name in allow) and name not in deny for name in detections.class_names], dtype=bool
    )
    return detections if keep.all() else detections.subset(keep)


def one_name_per_box(detections: Detections, iou: float, apart: Iterable[str] = ()) -> Detections:
    """``detections`` without each box that overlaps a box of another class with a higher score
    by ``iou`` or more (1: unchanged). Boxes of the classes ``apart`` (people: a person seated in
    an armchair fills the chair's box) neither drop nor are dropped."""
    n = len(detections)
    if n < 2 or iou >= 1.0:
        return detections
    names = detections.class_names
    overlap = iou_matrix(detections.xyxy, detections.xyxy)
    left_out = frozenset(apart)
    own = np.array([name not in left_out for name in names], dtype=bool)
    other = (np.array(names)[:, None] != np.array(names)[None, :]) & own[:, None] & own[None, :]
    keep = np.ones(n, dtype=bool)
    for i in np.argsort(-detections.scores, kind="stable"):
        if keep[i]:
            keep &= ~(other[i] & (overlap[i] >= iou))  # the lower-scored namings of box i
    return detections if keep.all() else detections.subset(keep)
