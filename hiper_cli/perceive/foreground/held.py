"""The detections of the detector's last look, held for the frames it does not look at.

With ``detector_hz`` set (``perceive --detector-hz``; 0 by default: every frame), the detector looks
that many times a second; the frames between are segmented and tracked all the same. Their blobs
are named by the last look's detections, each box moved to where the camera sees it now: its
corners are lifted to the depth of what the box held (the median depth of its inner half) and
projected into the new view. At 30 Hz the last look is at most a few frames old: a static thing
moves in the image by the camera's motion alone, a person by a few pixels of its own. The held
names shape the frame's blobs as the detector's would (split and joined, ``refine.py``), guide
the association and count in a track's class vote as the frame's own would: at the sensor rate
consecutive looks were near copies of each other, and the vote's thresholds (views before a
class wins, full views that refuse one) count frames (counted only at the looks, they cost as
much accuracy: ``docs/results/2026-12-07-two-rates.md``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.types import CameraIntrinsics, Detections, Frame

__all__ = ["HeldDetections"]

FloatArray = NDArray[np.float64]
INNER_SHARE = 0.5
"""The depth of a box is the median over this share of its width and height, centred (the rim
of a box holds the background around the thing)."""
DEPTH_STEP_PX = 4
"""Every this many pixels of that inner part are read (the median needs no more)."""


class HeldDetections:
    """The last look's detections, with the depth of each box and the camera that saw them."""

    def __init__(self) -> None:
        self._dets: Detections | None = None
        self._depth_m: FloatArray = np.zeros(0)
        self._T_map_cam: FloatArray = np.eye(4)

    def keep(self, frame: Frame, dets: Detections) -> None:
        """Hold ``dets``, the detector's look at ``frame``."""
        self._dets, self._T_map_cam = dets, frame.T_map_cam
        self._depth_m = np.array([_box_depth_m(frame.depth_m, box) for box in dets.xyxy])

    def at(self, frame: Frame) -> Detections:
        """The held detections as ``frame``'s camera sees them (none before the first look)."""
        dets = self._dets
        if dets is None or not len(dets):
            return Detections.empty()
        cam = frame.camera
        T_cam_map = np.linalg.inv(frame.T_map_cam)
        T_new_old = T_cam_map @ self._T_map_cam
        xyxy = dets.xyxy.copy()
        for k, (box, z) in enumerate(zip(dets.xyxy, self._depth_m, strict=True)):
            if z > 0:
                xyxy[k] = _moved(box, float(z), T_new_old, cam)
        return Detections(xyxy, dets.class_names, dets.scores)


def _box_depth_m(depth_m: NDArray[np.floating], box: FloatArray) -> float:
    """Median valid depth (m) of the inner part of image box ``box``; 0 when none."""
    x0, y0, x1, y1 = box
    mx, my = (x1 - x0) * (1 - INNER_SHARE) / 2, (y1 - y0) * (1 - INNER_SHARE) / 2
    h, w = depth_m.shape
    u0, u1 = int(np.clip(x0 + mx, 0, w - 1)), int(np.clip(x1 - mx, 0, w - 1)) + 1
    v0, v1 = int(np.clip(y0 + my, 0, h - 1)), int(np.clip(y1 - my, 0, h - 1)) + 1
    inner = depth_m[v0:v1:DEPTH_STEP_PX, u0:u1:DEPTH_STEP_PX]
    valid = inner[inner > 0]
    return float(np.median(valid)) if valid.size else 0.0


def _moved(box: FloatArray, z_m: float, T_new_old: FloatArray, cam: CameraIntrinsics) -> FloatArray:
    """Image box ``box`` of the old view, its corners at depth ``z_m``, as the new view sees it
    (clipped to the image); unchanged when a corner falls behind the new camera."""
    fx, fy, cx, cy = cam.fx, cam.fy, cam.cx, cam.cy
    u = np.array([box[0], box[2], box[0], box[2]])
    v = np.array([box[1], box[1], box[3], box[3]])
    old = np.stack([(u - cx) / fx * z_m, (v - cy) / fy * z_m, np.full(4, z_m)], axis=1)
    new = old @ T_new_old[:3, :3].T + T_new_old[:3, 3]
    if np.any(new[:, 2] <= 1e-3):
        return box
    un, vn = fx * new[:, 0] / new[:, 2] + cx, fy * new[:, 1] / new[:, 2] + cy
    width, height = cam.width, cam.height
    x0, x1 = np.clip([un.min(), un.max()], 0.0, float(width))
    y0, y1 = np.clip([vn.min(), vn.max()], 0.0, float(height))
    return np.array([x0, y0, x1, y1])
