"""Places seen empty: an earlier session's static object whose box this session's camera saw
through, while nothing stood in front of it, is no longer where that session left it.

Each frame, rays to points of each object are followed to the depth measured at their pixels:
to the points of its surface the earlier session observed (``data["surface_map"]``,
``surface_samples.py``), or, for an instance without them, to its box (its centre and four
points halfway to its sides, at the centre's height). A ray whose return lies beyond its point
(beyond the box's far side, for a box point) by ``THROUGH_MARGIN_M`` passed through empty
space; one whose return lies at the point (within the box) hit the object; one nearer is
occluded and says nothing. A frame where most of a box's usable rays passed through counts
as empty, one where half of them hit counts as present. A box empty in ``MIN_EMPTY_FRAMES``
frames, and in more frames than present, was vacated.

A surface point lets a ray tell an object gone from in front of a wall, or a cup gone from a
table seen from above, when the wall or table lies ``THROUGH_MARGIN_M`` behind the point on
the ray; points within ``SUPPORT_MARGIN_M`` of its foot are left out, as the floor or table
under them returns at their depth whether the object is there or not. A box point cannot: the
wall or table is the box's far side, so such a place is told empty only from a view low
enough for rays to pass the box's far side above the surface.

Two sessions' views of one object lie apart by their pose error (drift, alignment: up to
``POSE_SLACK_M``), which for a cup is more than its size: rays aimed at its old points pass it
by and end on the wall behind. So a surface point of an object no wider than ``SMALL_M`` (where
that shift moves the rays off most of it) is seen through only when nothing stands within
``POSE_SLACK_M`` of it either: probes around it (``PROBE_OFFSETS``, horizontal, at its
height) whose rays end at their own depth met a surface there, and the point counts as hit.
The margins grow with the depth noise at the point's range (``NOISE_PER_M2`` · z², three
sigma). A larger object keeps most of its rays on it through that shift, and its probes
would meet the wall or the furniture it stood against.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Instance
from hiper_cli.perceive.foreground.reidentify import POSE_SLACK_M

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
SUPPORT_MARGIN_M = 0.05  # surface points this near the object's lowest one are not aimed at
NOISE_PER_M2 = 0.0017  # depth noise (1 sigma) per squared metre of range
SMALL_M = 3 * POSE_SLACK_M  # footprint's larger side: the pose slack is a large share of it
_ANGLES = np.radians(np.arange(0, 360, 45))
PROBE_OFFSETS = np.concatenate([
    np.stack([r * np.cos(_ANGLES), r * np.sin(_ANGLES), np.zeros(len(_ANGLES))], axis=1)
    for r in (POSE_SLACK_M / 2, POSE_SLACK_M)])  # around a surface point: where it may be now


class EmptyPlaces:
    """The places of earlier static instances (their observed surface points, or their box),
    and per instance the frames that saw its place empty (and the first such stamp) and the
    frames that saw something there."""

    def __init__(self, instances: Sequence[Instance]) -> None:
        self.uuids = [inst.uuid for inst in instances]
        n = len(self.uuids)
        offsets = np.zeros((len(SAMPLE_OFFSETS), 3))
        offsets[:, :2] = SAMPLE_OFFSETS
        points, lower, upper, owner, on_surface, small = [], [], [], [], [], []
        for k, inst in enumerate(instances):
            surface = np.asarray(inst.data.get("surface_map") or [], dtype=np.float64).reshape(-1, 3)
            if len(surface):  # a point at the object's foot: the support under it answers for it
                surface = surface[surface[:, 2] >= surface[:, 2].min() + SUPPORT_MARGIN_M]
            seen = len(surface) > 0
            if seen:  # a surface point: near and far side at its depth
                lo = hi = surface
            else:
                box_lo, box_hi = inst.box.aabb()
                surface = (box_lo + box_hi) / 2.0 + offsets * (box_hi - box_lo) / 2.0
                lo, hi = np.broadcast_to(box_lo, surface.shape), np.broadcast_to(box_hi, surface.shape)
            points.append(surface)
            lower.append(lo)
            upper.append(hi)
            owner.append(np.full(len(surface), k))
            on_surface.append(np.full(len(surface), seen))
            small.append(np.full(len(surface), seen and float(np.max(inst.box.extent_m[:2])) <= SMALL_M))
        # per ray target: its point, the box it judges (lower, upper corners), whose it is
        self._points = np.concatenate(points) if points else np.zeros((0, 3))
        self._lower = np.concatenate(lower) if lower else np.zeros((0, 3))
        self._upper = np.concatenate(upper) if upper else np.zeros((0, 3))
        self._owner = np.concatenate(owner) if owner else np.zeros(0, dtype=np.int64)
        self._on_surface = np.concatenate(on_surface) if on_surface else np.zeros(0, dtype=bool)
        self._probe = np.concatenate(small) if small else np.zeros(0, dtype=bool)  # probed around
        self.empty = np.zeros(n, dtype=np.int64)
        self.present = np.zeros(n, dtype=np.int64)
        self.first_empty_s = np.full(n, np.nan)

    def look(self, project: Projector, camera_map_m: FloatArray, stamp_s: float) -> None:
        """Count this frame's verdict on every box (``project``: map points to (in view, their
        depth, the depth measured at their pixel); ``camera_map_m``: the camera centre)."""
        n, points = len(self.uuids), self._points
        ok, z, measured = project(points)
        entry, exit_ = _slab(camera_map_m, points - camera_map_m, self._lower, self._upper)
        entry, exit_ = np.where(self._on_surface, 1.0, entry), np.where(self._on_surface, 1.0, exit_)
        # depth grows linearly along a ray from the camera: the box spans these depths on it
        near_m, far_m = entry * z, exit_ * z
        noise = 3.0 * NOISE_PER_M2 * z * z
        ray_usable = ok & (measured > 0) & (measured >= near_m - HIT_MARGIN_M - noise)
        near_hit = self._probed(project)
        ray_through = ray_usable & (measured > far_m + THROUGH_MARGIN_M + noise) & ~near_hit
        ray_hit = ray_usable & ((measured <= far_m + HIT_MARGIN_M + noise) | near_hit)
        usable, through, hit = (np.bincount(self._owner, weights=a, minlength=n)
                                for a in (ray_usable, ray_through, ray_hit))
        judged = usable >= MIN_RAYS
        empty = judged & (through >= EMPTY_SHARE * usable)
        present = judged & (hit >= PRESENT_SHARE * usable)
        self.empty += empty
        self.present += present
        self.first_empty_s[empty & np.isnan(self.first_empty_s)] = stamp_s

    def _probed(self, project: Projector) -> NDArray[np.bool_]:
        """Per ray target: a surface point of a small object with a surface met within
        ``POSE_SLACK_M`` of it (a probe's ray ending at the probe's depth); False for the
        others."""
        surface = np.flatnonzero(self._probe)
        out = np.zeros(len(self._points), dtype=bool)
        if len(surface) == 0:
            return out
        probes = (self._points[surface, None, :] + PROBE_OFFSETS[None, :, :]).reshape(-1, 3)
        ok, z, measured = project(probes)
        met = ok & (measured > 0) & (np.abs(measured - z) <= HIT_MARGIN_M + 3.0 * NOISE_PER_M2 * z * z)
        out[surface] = met.reshape(len(surface), len(PROBE_OFFSETS)).any(axis=1)
        return out

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
