"""Small things cut out of the furniture they stand on: a detection box of a small class inside
a blob far too big for that class.

A bottle on a cabinet, a cup on a desk the background did not map, a vase on a sideboard: the
clustering joins the object to what it stands on or leans against, the blob's image box is the
furniture's, the detection box is the object's, their IoU is tiny and the object is never
named (house 41: a bottle on an unmapped side table became part of a 1 m ``unknown``). When a
detection of a class in ``carve_classes`` lies inside a blob (``join_containment`` of its box)
that is longer than any instance of the class (``plausible.max_longest_m``), the blob holds
the object and something else; the detector saw the nearest surface in its box, so the points
in the box within ``carve_depth_m`` of its front (the 10th percentile of their depths) are the
object and become a blob of their own, the rest stays a blob. Nothing is cut when either part
is smaller than ``min_cluster_points`` or the cut part is itself too long for the class.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.config import RefineConfig
from hiper_cli.perceive.foreground.plausible import longest_m, max_longest_m
from hiper_cli.perceive.foreground.segment import (
    JOIN_CONTAINMENT,
    Blob,
    boxes_within,
    pixels_in_boxes,
    sub_blob,
)

__all__ = ["carve_small"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
CARVE_CLASSES: tuple[str, ...] = (
        "bottle", "cup", "wine glass", "bowl", "vase", "laptop", "keyboard", "mouse", "remote",
        "cell phone", "clock", "scissors", "toothbrush", "potted plant", "teddy bear",
    )
"""A detection of one of these inside a blob longer than any instance of its class
    (``class_sizes``) cuts its object out of the blob (``carve.py``: a bottle on an unmapped
    side table; empty: off). Not ``book``: books stand in rows on a shelf, a box covers one
    spine or several, and a shelf's books are often part of the shelf (house 61 with
    ``yolox``: a ``book`` cut out of the shelf was a false positive) ..."""
CARVE_DEPTH_M: float = 0.2
"""... the points in its box within this of the box's front."""

FRONT_PERCENTILE = 10.0  # the front of what a box holds: robust to a few stray nearer samples


def _longest(blob: Blob) -> float:
    return longest_m(blob.points_map, float(blob.extent_map_m[2]))


def _cut(
    blob: Blob, box: NDArray[np.float64], limit_m: float, config: RefineConfig
) -> NDArray[np.bool_] | None:
    """The points of ``blob`` that are the object in ``box``, or None when nothing is cut."""
    pad = config.pixel_step * np.array([-1.0, -1.0, 1.0, 1.0])
    inside = pixels_in_boxes(blob.pixels_uv, (box + pad).reshape(1, 4))[:, 0]
    if np.count_nonzero(inside) < config.min_cluster_points:
        return None
    z = blob.points_cam[:, 2]
    front = float(np.percentile(z[inside], FRONT_PERCENTILE))
    part = inside & (z <= front + CARVE_DEPTH_M)
    n_part = int(np.count_nonzero(part))
    if n_part < config.min_cluster_points or len(z) - n_part < config.min_cluster_points:
        return None
    p = blob.points_map[part]
    height = float(p[:, 2].max() - p[:, 2].min())
    return part if longest_m(p, height) <= limit_m else None


def carve_small(
    blobs: Sequence[Blob],
    changed: Sequence[bool],
    boxes: NDArray[np.float64],
    classes: Sequence[str],
    config: RefineConfig,
    size_tolerance: float,
    width: int,
    height: int,
) -> tuple[list[Blob], list[bool]]:
    """``blobs`` with the small objects ``boxes`` (K, 4; ``classes`` their names) name cut out
    of the furniture they belong to, and per blob whether it is new (``changed``, per blob
    given, carried over; a blob cut in two is replaced by the rest, the part is appended)."""
    out, changed = list(blobs), list(changed)
    if not CARVE_CLASSES or len(classes) != len(boxes):
        return out, changed
    order = np.argsort((boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1]))
    for k in order.tolist():
        name = classes[k]
        if name not in CARVE_CLASSES:
            continue
        limit_m = max_longest_m(name, size_tolerance)
        box = boxes[k : k + 1]
        for i, blob in enumerate(out):
            if blob.fragment or not boxes_within(blob.image_box_xyxy, box, JOIN_CONTAINMENT)[0]:
                continue
            if _longest(blob) <= limit_m:
                continue
            part = _cut(blob, boxes[k], limit_m, config)
            if part is None:
                continue
            out[i] = sub_blob(blob, np.flatnonzero(~part), config.pixel_step, width, height)
            out.append(sub_blob(blob, np.flatnonzero(part), config.pixel_step, width, height))
            changed[i] = True
            changed.append(True)
            break
    return out, changed
