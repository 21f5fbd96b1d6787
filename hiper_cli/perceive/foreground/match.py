"""Semantic assignment of blobs (the paper's Algorithm 4): IoU of image boxes, then a threshold.

Detections and blobs come from the same frame (synchronised by stamp upstream). For every blob
the IoU of its projected image box with every detection box is computed; the blob takes the
class of the detection with the highest IoU when that IoU is strictly above the threshold,
otherwise it stays ``unknown``. Ties on IoU go to the higher score, then the lower index.
A detection may name several blobs (a person split in two by an occluder stays a person).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.types import Detections

__all__ = ["Match", "assign_classes", "iou_matrix", "named_within"]


@dataclass(frozen=True)
class Match:
    """The class given to one blob, with the detection it came from (``None``: unknown)."""

    class_name: str
    score: float
    detection_index: int | None
    iou: float


def iou_matrix(a_xyxy: NDArray[np.float64], b_xyxy: NDArray[np.float64]) -> NDArray[np.float64]:
    """IoU of every box in ``a`` (N, 4) with every box in ``b`` (M, 4): an (N, M) matrix.

    Boxes of zero area have IoU 0 with everything (including themselves).
    """
    a = np.asarray(a_xyxy, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b_xyxy, dtype=np.float64).reshape(-1, 4)
    if len(a) == 0 or len(b) == 0:
        return np.zeros((len(a), len(b)))
    inter = _intersections(a, b)
    union = _areas(a)[:, None] + _areas(b)[None, :] - inter
    return np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)


def _intersections(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Intersection area of every box in ``a`` (N, 4) with every box in ``b`` (M, 4)."""
    iw = np.clip(np.minimum(a[:, None, 2], b[None, :, 2]) - np.maximum(a[:, None, 0], b[None, :, 0]), 0, None)
    ih = np.clip(np.minimum(a[:, None, 3], b[None, :, 3]) - np.maximum(a[:, None, 1], b[None, :, 1]), 0, None)
    return np.asarray(iw * ih, dtype=np.float64)


def _areas(boxes: NDArray[np.float64]) -> NDArray[np.float64]:
    return (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])


def assign_classes(
    blob_boxes_xyxy: NDArray[np.float64],
    detections: Detections,
    *,
    iou_threshold: float,
    min_score: float = 0.0,
    unknown: str = "unknown",
) -> list[Match]:
    """Algorithm 4: one ``Match`` per blob box (see the module docstring)."""
    boxes = np.asarray(blob_boxes_xyxy, dtype=np.float64).reshape(-1, 4)
    no_match = Match(unknown, 0.0, None, 0.0)
    if len(boxes) == 0:
        return []
    usable = np.flatnonzero(detections.scores >= min_score) if len(detections) else np.zeros(0, dtype=int)
    if len(usable) == 0:
        return [no_match] * len(boxes)
    iou = iou_matrix(boxes, detections.xyxy[usable])
    scores = detections.scores[usable]
    out: list[Match] = []
    for i in range(len(boxes)):
        row = iou[i]
        best = float(row.max())
        if not best > iou_threshold:
            out.append(no_match)
            continue
        tied = np.flatnonzero(row == best)
        j = int(tied[np.argmax(scores[tied])])  # argmax takes the first of equal scores
        k = int(usable[j])
        out.append(Match(detections.class_names[k], float(detections.scores[k]), k, best))
    return out


def named_within(
    blob_box_xyxy: NDArray[np.float64], detections: Detections, *, min_score: float, min_cover: float
) -> frozenset[str]:
    """The classes of the detections (score at least ``min_score``) that lie mostly inside one
    blob's image box: at least ``min_cover`` of a detection box's area. A blob that took no
    class, or another one, may still hold a detection of a class (a bottle joined with the cup
    beside it is no match for the bottle's box, yet the detector named the bottle there)."""
    if len(detections) == 0:
        return frozenset()
    d = np.asarray(detections.xyxy, dtype=np.float64).reshape(-1, 4)
    inter = _intersections(np.asarray(blob_box_xyxy, dtype=np.float64).reshape(1, 4), d)[0]
    area = _areas(d)
    inside = (area > 0) & (inter >= min_cover * area) & (detections.scores >= min_score)
    return frozenset(detections.class_names[k] for k in np.flatnonzero(inside))
