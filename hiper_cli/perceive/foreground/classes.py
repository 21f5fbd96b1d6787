"""Which detector classes the foreground stage accepts (the paper's Table III footnote).

The paper: "Not present classes, such as boat and traffic light, have been excluded
beforehand." hiper does the same with two options of ``ForegroundConfig``, applied to the
detections of every frame before refinement and matching (so ``hiper perceive`` and
``hiper eval foreground`` filter identically):

- ``exclude_classes`` (default ``INDOOR_EXCLUDED``): COCO classes that are not found indoors
  (vehicles, street furniture, farm and wild animals, outdoor sports gear), plus
  ``dining table``: hiper's background layer already models tables (their top planes), so a
  table detection would only name the table's legs or a chair beside it as a foreground object;
- ``classes`` (default empty: all): an allow-list for one environment, e.g. the classes a
  house can contain; when given, every other class is dropped.

A dropped detection is as if the detector had not reported it: its blob stays ``unknown``.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from hiper_cli.types import Detections

__all__ = ["INDOOR_EXCLUDED", "filter_classes"]

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
    if keep.all():
        return detections
    return Detections(
        detections.xyxy[keep],
        tuple(n for n, k in zip(detections.class_names, keep, strict=True) if k),
        detections.scores[keep],
    )
