"""Class evidence for the mapped tables' bodies: the views in which the detector named them.

A table the background layer maps (its top plane) is one real object; its body, top and legs,
is a foreground instance too (``supports.table_bodies``). Like any object, that body takes the
name its views give it: the detector's ``dining table`` boxes are kept, per frame the detector
looked at, with the camera and a coarse depth image; when the bodies are known (at the end of
the session, from the background's final tables) each body is projected into those frames, and
a view names it when a table box overlaps its image box by ``NAMED_IOU`` while most of its
points are in sight there (not hidden behind something nearer). A body named in
``min_class_observations`` views, as many as a track's class needs, is a ``table``.

The detector's table classes are dropped from the frame's detections (``classes.py``): a table
box would otherwise name the chair in front of it, or the legs the background left over.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.match import iou_matrix
from hiper_cli.types import CameraIntrinsics, Detections, Frame

__all__ = ["TABLE_DETECTOR_CLASSES", "Scene", "TableViews", "View", "best_overlaps", "project"]

FloatArray = NDArray[np.float64]

TABLE_DETECTOR_CLASSES: tuple[str, ...] = ("dining table",)
"""The detector classes (COCO) that name a table."""
NAMED_IOU = 0.3  # a table box overlapping a body's image box this much names it in that view
DEPTH_STEP_PX = 8  # the depth kept per view: every 8th pixel (a 640 × 480 frame: 80 × 60 values)
HIDDEN_MARGIN_M = 0.15  # a body point this far behind the depth measured at its pixel is hidden
SEEN_SHARE = 0.5  # a view shows a body when this share of its points is in the image, not hidden
MIN_DEPTH_M = 0.1  # points nearer than this to the camera are behind it


@dataclass(frozen=True)
class View:
    """A kept detector frame: its camera, pose (map to camera), coarse depth and boxes."""

    T_cam_map: FloatArray
    camera: CameraIntrinsics
    depth_m: NDArray[np.float32]  # every DEPTH_STEP_PX-th pixel
    boxes_xyxy: FloatArray  # the table boxes the detector gave (pixels)


class TableViews:
    """The frames in which the detector named a table, kept for the bodies of mapped tables."""

    def __init__(self, min_score: float) -> None:
        self.min_score = min_score
        self._views: list[View] = []

    def __len__(self) -> int:
        return len(self._views)

    def add(self, frame: Frame, detections: Detections) -> None:
        """Keep ``frame``'s table boxes of ``detections`` (as the detector gave them, before the
        stage drops the table classes) scored ``min_score`` or more; nothing when there are none."""
        if len(detections) == 0:
            return
        names, scores = detections.class_names, detections.scores
        keep = [k for k, (name, score) in enumerate(zip(names, scores, strict=True))
                if name in TABLE_DETECTOR_CLASSES and score >= self.min_score]
        if not keep:
            return
        depth = np.ascontiguousarray(frame.depth_m[::DEPTH_STEP_PX, ::DEPTH_STEP_PX])
        T_cam_map = np.asarray(np.linalg.inv(frame.T_map_cam), dtype=np.float64)
        self._views.append(View(T_cam_map, frame.camera, depth,
                                 np.asarray(detections.xyxy[keep], dtype=np.float64)))

    def named_views(self, bodies: Sequence[tuple[Box3D, FloatArray]]) -> list[int]:
        """Per body (its box and points on its surface, map frame), in how many kept views a table
        box named it. Each box names at most one body, the one it overlaps most: a table seen
        in front of another is not evidence for both."""
        counts = [0] * len(bodies)
        scene = Scene(bodies)
        for view in self._views:
            boxes, shown, _ = scene.seen_in(view)
            for k in {k for k in best_overlaps(view.boxes_xyxy, boxes, shown) if k >= 0}:
                counts[k] += 1
        return counts


class Scene:
    """Objects' boxes and surface points (map frame), stacked to project them into a view at
    once."""

    def __init__(self, bodies: Sequence[tuple[Box3D, FloatArray]]) -> None:
        surfaces = [np.asarray(points, dtype=np.float64).reshape(-1, 3) for _, points in bodies]
        self.n = len(bodies)
        self.points = np.concatenate([*surfaces, np.zeros((0, 3))])
        self.owner = np.repeat(np.arange(self.n), [len(p) for p in surfaces])
        self.sizes = np.array([len(p) for p in surfaces], dtype=np.float64)
        self.corners = np.concatenate([*(box.corners() for box, _ in bodies), np.zeros((0, 3))])

    def seen_in(self, view: View) -> tuple[FloatArray, NDArray[np.bool_], NDArray[np.bool_]]:
        """Per object its image box (x0, y0, x1, y1, pixels, clipped to the image), whether
        ``view`` shows it (``SEEN_SHARE`` of its points in the image and not hidden, its box in
        front of the camera) and whether its whole box lies inside the image."""
        cam = view.camera
        u, v, z = project(view.T_cam_map, cam, self.points)
        inside = (z > MIN_DEPTH_M) & (u >= 0) & (u < cam.width) & (v >= 0) & (v < cam.height)
        rows = np.clip((v / DEPTH_STEP_PX).astype(np.int64), 0, view.depth_m.shape[0] - 1)
        cols = np.clip((u / DEPTH_STEP_PX).astype(np.int64), 0, view.depth_m.shape[1] - 1)
        measured = view.depth_m[rows, cols]
        seen = inside & ((measured <= 0) | (z <= measured + HIDDEN_MARGIN_M))
        shown = np.bincount(self.owner, weights=seen, minlength=self.n) >= SEEN_SHARE * self.sizes
        cu, cv, cz = (a.reshape(self.n, 8) for a in project(view.T_cam_map, cam, self.corners))
        front = cz > MIN_DEPTH_M
        x0 = np.clip(np.where(front, cu, np.inf).min(axis=1), 0, cam.width)
        x1 = np.clip(np.where(front, cu, -np.inf).max(axis=1), 0, cam.width)
        y0 = np.clip(np.where(front, cv, np.inf).min(axis=1), 0, cam.height)
        y1 = np.clip(np.where(front, cv, -np.inf).max(axis=1), 0, cam.height)
        shown &= (front.sum(axis=1) >= 2) & (x1 > x0) & (y1 > y0) & (self.sizes > 0)
        whole = np.all(front & (cu >= 0) & (cu < cam.width) & (cv >= 0) & (cv < cam.height), axis=1)
        return np.column_stack([x0, y0, x1, y1]), shown, whole


def best_overlaps(view_boxes: FloatArray, boxes: FloatArray, shown: NDArray[np.bool_]) -> list[int]:
    """Per box of ``view_boxes`` the object it names: of the objects ``shown`` (their image
    ``boxes``), the one it overlaps most, by ``NAMED_IOU`` at least; -1 for none."""
    index = np.flatnonzero(shown)
    if len(index) == 0 or len(view_boxes) == 0:
        return [-1] * len(view_boxes)
    iou = iou_matrix(view_boxes, boxes[index])
    best = np.argmax(iou, axis=1)
    return [int(index[b]) if row[b] >= NAMED_IOU else -1 for row, b in zip(iou, best, strict=True)]


def project(T_cam_map: FloatArray, cam: CameraIntrinsics, points_map: FloatArray) -> tuple[
        FloatArray, FloatArray, FloatArray]:
    """Pixel columns, rows and depths (m) of map points; points behind the camera get -1 pixels."""
    p = points_map @ T_cam_map[:3, :3].T + T_cam_map[:3, 3]
    z = p[:, 2]
    ahead = z > MIN_DEPTH_M
    safe = np.where(ahead, z, 1.0)
    u = np.where(ahead, cam.fx * p[:, 0] / safe + cam.cx, -1.0)
    v = np.where(ahead, cam.fy * p[:, 1] / safe + cam.cy, -1.0)
    return u, v, z
