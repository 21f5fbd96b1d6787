"""Whether a detector's class fits the 3D object it names: common-sense sizes of COCO classes.

A 2D detector names what an image patch looks like; the depth says how big the thing is. A
blob much longer than any instance of a class is not that class (a trash can is no cup), and
an object seen whole that is much shorter than the smallest instance of a class is not that
class either (a 1 m book display is no bed). ``CLASS_SIZES`` holds, per COCO class, the
longest dimension (metres) of its smallest and largest common instances: furniture and
appliance standards for the large ones (the shortest beds are cribs, about 1.3 m long; the
shortest couches are two-seaters of about 1.2 m), everyday objects for the small ones. A
class without a lower bound (0) has instances of any size down to what the sensor resolves,
or is so often seen partly hidden (people behind tables) that a short view says nothing.

The two bounds are used differently, because a view can show less of an object but never
more (``ForegroundStage``, ``Tracker``):

- too long: an observation whose blob is longer than the class's largest instance (times
  ``1 + class_size_tolerance``) is not of that class (``unknown``), in any view: a part of an
  object is never longer than the object;
- too short: a track whose blobs, in every view that named the class and showed them whole
  (inside the image, not hidden in part by something nearer: ``whole.occluded``), stayed
  shorter than the class's smallest instance (times ``1 - class_size_tolerance``) cannot take
  that class; a view cut by the image's border or by an occluder shows only a part, and one
  whole view of the full length is enough.

Plumbing fixtures (``fixture_classes``: sinks, toilets) are where the pipes are: built into a
counter or standing against a wall (``attached``). A round stool seen from above looks like
a basin to a detector; one standing free in the room is no sink.

The longest dimension of a blob (``longest_m``) is the longer side of the smallest rectangle
around its points seen from above (independent of how the object is turned in the map, unlike
an axis-aligned box, which makes a square 0.86 m footprint 1.2 m long at 45 degrees), or its
height, whichever is larger.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D

__all__ = ["CLASS_SIZES", "attached", "longest_m", "max_longest_m", "min_longest_m"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
FIXTURE_CLASSES: tuple[str, ...] = ("sink", "toilet")
"""Plumbing fixtures (``plausible.attached``): a blob named one of these classes is ``unknown``
unless it stands against a wall (within ``fixture_reach_m`` of a background wall) or is
built into a counter (its centre inside a background table top's footprint, its top within
``fixture_reach_m`` of the top's height). Pipes come out of walls; a round stool seen from
above, standing free in the room, is no sink (empty: off)."""
FIXTURE_REACH_M: float = 0.3
CLASS_SIZE_TOLERANCE: float = 0.15
"""The sizes' margin for measurement: the largest times 1 + this, the smallest times 1 - this."""

CLASS_SIZES: dict[str, tuple[float, float]] = {
    # people and what they carry
    "person": (0.0, 2.5),
    "backpack": (0.0, 0.8),
    "umbrella": (0.0, 1.3),
    "handbag": (0.0, 0.7),
    "tie": (0.0, 0.7),
    "suitcase": (0.0, 1.0),
    # furniture and appliances
    "chair": (0.0, 1.4),
    "couch": (1.0, 4.0),
    "bed": (1.3, 2.6),
    "bench": (0.0, 2.5),
    "toilet": (0.4, 1.0),
    "sink": (0.0, 1.3),
    "refrigerator": (0.5, 2.2),
    "oven": (0.0, 1.2),
    "microwave": (0.0, 0.8),
    "toaster": (0.0, 0.5),
    "tv": (0.0, 2.3),
    "potted plant": (0.0, 2.5),
    "dining table": (0.0, 4.0),
    # things on tables and shelves
    "laptop": (0.0, 0.6),
    "keyboard": (0.0, 0.7),
    "mouse": (0.0, 0.2),
    "remote": (0.0, 0.3),
    "cell phone": (0.0, 0.25),
    "book": (0.0, 0.6),
    "clock": (0.0, 0.8),
    "vase": (0.0, 1.2),
    "scissors": (0.0, 0.35),
    "teddy bear": (0.0, 1.2),
    "hair drier": (0.0, 0.4),
    "toothbrush": (0.0, 0.3),
    "bottle": (0.0, 0.5),
    "wine glass": (0.0, 0.3),
    "cup": (0.0, 0.25),
    "bowl": (0.0, 0.5),
    "fork": (0.0, 0.3),
    "knife": (0.0, 0.4),
    "spoon": (0.0, 0.3),
    "banana": (0.0, 0.3),
    "apple": (0.0, 0.15),
    "orange": (0.0, 0.15),
    "sandwich": (0.0, 0.35),
    "broccoli": (0.0, 0.35),
    "carrot": (0.0, 0.35),
    "hot dog": (0.0, 0.35),
    "pizza": (0.0, 0.6),
    "donut": (0.0, 0.25),
    "cake": (0.0, 0.6),
    "sports ball": (0.0, 0.4),
    # animals kept indoors
    "cat": (0.0, 1.0),
    "dog": (0.0, 1.4),
}  # fmt: skip
"""COCO class -> (longest dimension of its smallest, of its largest common instance), metres."""
ATTACH_SAMPLES = 256  # ``attached`` measures distances from this many of the points at most


def max_longest_m(class_name: str, tolerance: float) -> float:
    """The longest a blob of ``class_name`` may be (inf for a class not in ``CLASS_SIZES``)."""
    size = CLASS_SIZES.get(class_name)
    return np.inf if size is None else size[1] * (1.0 + tolerance)


def min_longest_m(class_name: str, tolerance: float) -> float:
    """The shortest an object of ``class_name`` seen whole may be (0: no lower bound)."""
    size = CLASS_SIZES.get(class_name)
    return 0.0 if size is None else size[0] * (1.0 - tolerance)


def longest_m(points_map: NDArray[np.float64], height_m: float) -> float:
    """The longest dimension of an object whose points (N, 3, map frame, z up) are given, of
    height ``height_m``: the longer side of the smallest rectangle around the points' footprint,
    or the height when larger."""
    xy = np.ascontiguousarray(points_map[:, :2], dtype=np.float32)
    if len(xy) < 3:
        return float(height_m)
    import cv2

    (_, _), (w, h), _ = cv2.minAreaRect(xy)
    return float(max(w, h, height_m))


def _distance_to_box(points: NDArray[np.float64], box: Box3D) -> NDArray[np.float64]:
    """Distance (m) of each point (N, 3) to the oriented ``box`` (0 inside)."""
    local = (points - box.center_m) @ box.R
    outside = np.maximum(np.abs(local) - box.extent_m / 2.0, 0.0)
    return np.asarray(np.linalg.norm(outside, axis=1), dtype=np.float64)


def attached(
    points_map: NDArray[np.float64], walls: Sequence[Box3D], tops: Sequence[Box3D], reach_m: float
) -> bool:
    """Whether the object of ``points_map`` (N, 3, map frame) stands against a wall (a point
    within ``reach_m`` of a wall's box) or is built into a counter (its centre inside the
    footprint of a table top, whose height is within ``reach_m`` of the object's top)."""
    if len(points_map) == 0:
        return False
    points_map = points_map[:: max(1, len(points_map) // ATTACH_SAMPLES)]
    if any(float(_distance_to_box(points_map, wall).min()) <= reach_m for wall in walls):
        return True
    centre = points_map.mean(axis=0)
    top = float(points_map[:, 2].max())
    for box in tops:
        lo, hi = box.aabb()
        inside = bool(np.all(centre[:2] >= lo[:2]) and np.all(centre[:2] <= hi[:2]))
        if inside and abs(top - float(hi[2])) <= reach_m:
            return True
    return False
