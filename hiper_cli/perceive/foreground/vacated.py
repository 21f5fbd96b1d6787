"""Places seen empty: an earlier session's static object whose box this session's camera saw
through, while nothing stood in front of it, is no longer where that session left it.

Each frame, rays to a few points inside each such box (its centre and four points halfway to
its sides, at the centre's height) are followed to the depth measured at their pixels. A ray
whose return lies beyond the far side of the box (``THROUGH_MARGIN_M``) passed through empty
space; one whose return lies inside the box hit the object; one nearer than the box is
occluded and says nothing. A frame where most of a box's usable rays passed through counts
as empty, one where half of them hit counts as present. A box empty in ``MIN_EMPTY_FRAMES``
frames, and in more frames than present, was vacated.

Seen from above, the surface under a cup is the far side of the cup's box, and no ray passes
through it: such a place is told empty only from a view low enough for rays to pass the box's
far side above the surface. Something standing on the floor is, from a robot's camera height.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Instance

__all__ = ["EmptyPlaces"]

FloatArray = NDArray[np.float64]
# (in view, depth of the points along the optical axis (m), depth measured at their pixels (m))
Projector = Callable[[FloatArray], tuple[NDArray[np.bool_], FloatArray, FloatArray]]

SAMPLE_OFFSETS = np.array([[0.0, 0.0], [0.5, 0.5], [0.5, -0.5], [-0.5, 0.5], [-0.5, -0.5]])
THROUGH_MARGIN_M = 0.15  # a return this far beyond the box's far side: the ray passed through
HIT_MARGIN_M = 0.1  # a return within the box, give or take this: the ray hit the object
MIN_RAYS = 3  # usable rays (in view, with a return, not occluded) a frame needs for a verdict
EMPTY_SHARE = 0.8  # of the usable rays through: the frame saw the place empty
PRESENT_SHARE = 0.5  # of the usable rays hitting: the frame saw the object there
MIN_EMPTY_FRAMES = 3


class EmptyPlaces:
    """The boxes of earlier static instances, and per box the frames that saw it empty (and
    the first such stamp) and the frames that saw something in it."""

    def __init__(self, instances: Sequence[Instance]) -> None:
        self.uuids = [inst.uuid for inst in instances]
        n = len(self.uuids)
        self._lower = np.zeros((n, 3))
        self._upper = np.zeros((n, 3))
        for k, inst in enumerate(instances):
            self._lower[k], self._upper[k] = inst.box.aabb()
        centre, half = (self._lower + self._upper) / 2.0, (self._upper - self._lower) / 2.0
        offsets = np.zeros((len(SAMPLE_OFFSETS), 3))
        offsets[:, :2] = SAMPLE_OFFSETS
        # (n, k, 3): k sample points per box
        self._points = centre[:, None, :] + offsets[None, :, :] * half[:, None, :]
        self.empty = np.zeros(n, dtype=np.int64)
        self.present = np.zeros(n, dtype=np.int64)
        self.first_empty_s = np.full(n, np.nan)

    def look(self, project: Projector, camera_map_m: FloatArray, stamp_s: float) -> None:
        """Count this frame's verdict on every box (``project``: map points to (in view, their
        depth, the depth measured at their pixel); ``camera_map_m``: the camera centre)."""
        n, k = self._points.shape[:2]
        points = self._points.reshape(-1, 3)
        ok, z, measured = project(points)
        lower, upper = np.repeat(self._lower, k, axis=0), np.repeat(self._upper, k, axis=0)
        entry, exit_ = _slab(camera_map_m, points - camera_map_m, lower, upper)
        # depth grows linearly along a ray from the camera: the box spans these depths on it
        near_m, far_m = entry * z, exit_ * z
        usable = ok & (measured > 0) & (measured >= near_m - HIT_MARGIN_M)
        through = usable & (measured > far_m + THROUGH_MARGIN_M)
        hit = usable & (measured <= far_m + HIT_MARGIN_M)
        usable, through, hit = (a.reshape(n, k).sum(axis=1) for a in (usable, through, hit))
        judged = usable >= MIN_RAYS
        empty = judged & (through >= EMPTY_SHARE * usable)
        present = judged & (hit >= PRESENT_SHARE * usable)
        self.empty += empty
        self.present += present
        self.first_empty_s[empty & np.isnan(self.first_empty_s)] = stamp_s

    def vacated(self) -> dict[str, float]:
        """uuid -> the first stamp its place was seen empty, for the boxes seen empty in at
        least ``MIN_EMPTY_FRAMES`` frames and in more frames than anything was seen in them."""
        out = (self.empty >= MIN_EMPTY_FRAMES) & (self.empty > self.present)
        return {self.uuids[i]: float(self.first_empty_s[i]) for i in np.flatnonzero(out)}


def _slab(origin: FloatArray, ray: FloatArray, lower: FloatArray, upper: FloatArray
          ) -> tuple[FloatArray, FloatArray]:
    """Where each ray ``origin + t · ray`` enters and leaves its box (t; the box's points
    given as ray targets lie inside it, so entry <= 1 <= exit)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / np.where(np.abs(ray) < 1e-12, 1e-12, ray)
        t1, t2 = (lower - origin) * inv, (upper - origin) * inv
    entry = np.minimum(t1, t2).max(axis=1)
    exit_ = np.maximum(t1, t2).min(axis=1)
    return np.maximum(entry, 0.0), exit_
