"""Large furniture seen in part: its box completed behind the faces the camera saw.

A camera sees the near faces of an opaque object. A bed seen from its side through a doorway
shows a strip 0.3 m deep of a bed 1 m wide, a refrigerator seen from the front shows its door;
the box of its blobs (``SeenBox``) is that strip, and its centre lies half the missing depth in
front of the object's. ``FOOTPRINT_MIN_WIDTH_M`` holds, per class, the narrower side of the
footprint of its smallest common instance (a single or hospital bed is 0.9 m wide, a couch's
seat 0.7 m deep, a full-size refrigerator 0.55 m deep). A static instance of such a class whose
box is thinner than that along a horizontal map axis, and that the camera saw from beyond its
box along that axis (so it saw the face across it), is extended along that axis away from the
camera to that width: the part of it the near faces hid. The extension stops at a wall (a
background plane) behind the object, since nothing stands inside a wall.

A chair behind a desk shows its seat under the desk's top and not its back: where no view
showed an object's top (``SeenBox.top_seen``: something nearer lay just above the blob, or the
image ended there), a class with a least height (``LEAST_HEIGHT_M``: a chair with a back is at
least 0.7 m tall) has its box raised to that height above its bottom. The back of a chair seen
across a table shows above the table's top and not its seat or legs: where no view showed where
an object stands (``SeenBox.bottom_seen``: something nearer lay just below the blob, or the image
ended there), a class that stands on the floor (``FLOOR_STANDING``) has its box lowered to the
floor.

How long a bed cut by a doorway's side is, and on which side the rest of it lies, the views do
not tell: the length is not completed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D

__all__ = ["FLOOR_STANDING", "FOOTPRINT_MIN_WIDTH_M", "LEAST_HEIGHT_M", "complete_base", "complete_footprint",
           "complete_height"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
COMPLETE_FOOTPRINTS: bool = True
"""A static bed, couch or refrigerator seen in part has its box extended behind the faces
the camera saw, to its class's least footprint width, and a chair, couch or refrigerator
whose top no view showed is raised to its class's least height (``amodal.py``; issue 17: a
bed seen through a doorway as a strip of its side, its centre 0.54 m off; chairs behind a
desk kept up to the seat)."""

FloatArray = NDArray[np.float64]

FOOTPRINT_MIN_WIDTH_M: dict[str, float] = {
    "bed": 0.9,
    "couch": 0.7,
    "refrigerator": 0.55,
}
"""COCO class -> the narrower side (m) of the footprint of its smallest common instance."""
LEAST_HEIGHT_M: dict[str, float] = {
    "chair": 0.7,
    "couch": 0.6,
    "refrigerator": 0.8,
}
"""COCO class -> the height (m) of its lowest common instance (a chair with a back, a low couch's
back, an under-counter refrigerator)."""
FLOOR_STANDING = frozenset({"bed", "bench", "chair", "couch", "refrigerator", "toilet"})
"""COCO classes whose objects stand on the floor, never on a table or a shelf."""
WALL_MIN_NORMAL = 0.87  # a wall faces along a map axis when its normal is within 30° of it
WALL_GAP_M = 0.02  # an extension stops this short of a wall behind the object


def complete_footprint(
    lower_m: FloatArray,
    upper_m: FloatArray,
    class_name: str,
    viewpoint_m: FloatArray | None,
    walls: Sequence[Box3D] = (),
) -> tuple[FloatArray, FloatArray]:
    """(lower, upper) map-frame corners of the object whose seen box is ``lower_m``-``upper_m``,
    seen from ``viewpoint_m`` (the camera's position, map frame): extended away from the camera
    to the class's footprint width along each horizontal axis it is thinner along and the
    camera lies beyond, up to the nearest of ``walls`` behind it. Unchanged for a class without
    a width, without a viewpoint, or already as wide."""
    width = FOOTPRINT_MIN_WIDTH_M.get(class_name)
    if width is None or viewpoint_m is None:
        return lower_m, upper_m
    lower, upper = np.array(lower_m, dtype=np.float64), np.array(upper_m, dtype=np.float64)
    view = np.asarray(viewpoint_m, dtype=np.float64)
    for axis in (0, 1):
        if upper[axis] - lower[axis] >= width:
            continue
        if view[axis] < lower[axis]:  # the camera saw the face towards smaller values
            far = min(lower[axis] + width, _wall_behind(lower, upper, axis, +1, walls))
            upper[axis] = max(upper[axis], far)
        elif view[axis] > upper[axis]:
            far = max(upper[axis] - width, _wall_behind(lower, upper, axis, -1, walls))
            lower[axis] = min(lower[axis], far)
    return lower, upper


def complete_height(
    lower_m: FloatArray, upper_m: FloatArray, class_name: str, top_seen: bool
) -> tuple[FloatArray, FloatArray]:
    """(lower, upper) corners of an object whose top no view showed (``top_seen`` false): at
    least the class's least height above its bottom. Unchanged otherwise."""
    height = LEAST_HEIGHT_M.get(class_name)
    if height is None or top_seen or upper_m[2] - lower_m[2] >= height:
        return lower_m, upper_m
    upper = np.array(upper_m, dtype=np.float64)
    upper[2] = lower_m[2] + height
    return lower_m, upper


def complete_base(
    lower_m: FloatArray, upper_m: FloatArray, class_name: str, bottom_seen: bool, floor_z_m: float
) -> tuple[FloatArray, FloatArray]:
    """(lower, upper) corners of an object whose base no view showed (``bottom_seen`` false):
    down to the floor (``floor_z_m``, map frame) for a class in ``FLOOR_STANDING``. Unchanged
    otherwise."""
    if class_name not in FLOOR_STANDING or bottom_seen or lower_m[2] <= floor_z_m:
        return lower_m, upper_m
    lower = np.array(lower_m, dtype=np.float64)
    lower[2] = floor_z_m
    return lower, upper_m


def _wall_behind(lower: FloatArray, upper: FloatArray, axis: int, sign: int, walls: Sequence[Box3D]) -> float:
    """The map coordinate along ``axis`` (less ``WALL_GAP_M``) of the nearest wall beyond the box's
    far face (``sign``: +1 towards larger values) that faces along ``axis`` and spans the box's
    footprint across it; ±inf when none."""
    other = 1 - axis
    best = np.inf if sign > 0 else -np.inf
    for wall in walls:
        normal = wall.R[:, int(np.argmin(wall.extent_m))]
        if abs(float(normal[axis])) < WALL_MIN_NORMAL:
            continue
        lo, hi = wall.aabb()
        if hi[other] <= lower[other] or lo[other] >= upper[other]:
            continue  # beside the object, not behind it
        at = float(wall.center_m[axis])
        if sign > 0 and at > upper[axis] - WALL_GAP_M:
            best = min(best, at - WALL_GAP_M)
        elif sign < 0 and at < lower[axis] + WALL_GAP_M:
            best = max(best, at + WALL_GAP_M)
    return best
