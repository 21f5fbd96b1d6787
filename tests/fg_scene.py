"""Tiny ray-cast scenes of axis-aligned boxes for the foreground tests (no simulator needed)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiper_cli.model import Box3D, Instance
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAMERA = CameraIntrinsics(width=160, height=120, fx=100.0, fy=100.0, cx=80.0, cy=60.0)


@dataclass
class SceneBox:
    id: int
    center: np.ndarray
    extent: np.ndarray
    class_name: str
    background: bool = False


def pose_looking_x(x: float = 0.0, y: float = 0.0, z: float = 1.0) -> np.ndarray:
    """T_map_cam of a camera at (x, y, z) looking along map +x (optical frame: z forward)."""
    T = np.eye(4)
    T[:3, :3] = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    T[:3, 3] = [x, y, z]
    return T


def room() -> list[SceneBox]:
    return [
        SceneBox(1, np.array([5.0, 0.0, -0.05]), np.array([20.0, 20.0, 0.1]), "floor", True),
        SceneBox(2, np.array([6.05, 0.0, 1.5]), np.array([0.1, 20.0, 3.0]), "wall", True),
    ]


def person(id_: int, x: float, y: float) -> SceneBox:
    return SceneBox(id_, np.array([x, y, 0.85]), np.array([0.3, 0.5, 1.7]), "person")


def render(boxes: list[SceneBox], T_map_cam: np.ndarray, camera: CameraIntrinsics = CAMERA):
    """Depth (H, W) float32 and instance ids (H, W) by slab ray casting."""
    H, W = camera.height, camera.width
    u, v = np.meshgrid(np.arange(W) + 0.5, np.arange(H) + 0.5)
    d_cam = np.stack([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u)], -1)
    R, o = T_map_cam[:3, :3], T_map_cam[:3, 3]
    d_map = d_cam.reshape(-1, 3) @ R.T
    best_t = np.full(len(d_map), np.inf)
    ids = np.zeros(len(d_map), dtype=np.uint16)
    with np.errstate(divide="ignore", invalid="ignore"):
        for b in boxes:
            lo, hi = b.center - b.extent / 2, b.center + b.extent / 2
            t1, t2 = (lo - o) / d_map, (hi - o) / d_map
            tmin = np.nanmax(np.minimum(t1, t2), axis=1)
            tmax = np.nanmin(np.maximum(t1, t2), axis=1)
            hit = (tmax >= tmax * 0 + np.maximum(tmin, 0)) & (tmax > 0)
            t = np.where(tmin > 0, tmin, tmax)
            closer = hit & (t < best_t)
            best_t[closer] = t[closer]
            ids[closer] = b.id
    depth = np.where(np.isfinite(best_t), best_t, 0.0).reshape(H, W).astype(np.float32)  # z = t (d_cam z = 1)
    return depth, ids.reshape(H, W)


def truth_detections(boxes: list[SceneBox], ids: np.ndarray) -> Detections:
    """Perfect detections: the pixel box of every visible foreground box."""
    records = []
    for b in boxes:
        if b.background:
            continue
        ys, xs = np.nonzero(ids == b.id)
        if len(xs) < 10:
            continue
        records.append(
            {"xyxy": [xs.min(), ys.min(), xs.max() + 1, ys.max() + 1], "class": b.class_name, "score": 0.9}
        )
    return Detections.from_records(records)


def make_frame(boxes: list[SceneBox], T_map_cam: np.ndarray, stamp_s: float, pose_id: int) -> Frame:
    depth, ids = render(boxes, T_map_cam)
    rgb = np.zeros((CAMERA.height, CAMERA.width, 3), dtype=np.uint8)
    return Frame(
        stamp_s, rgb, depth, CAMERA, T_map_cam, pose_id, detections=truth_detections(boxes, ids),
        extras={"ids": ids},
    )


def background_instances(boxes: list[SceneBox]) -> dict[str, Instance]:
    out = {}
    for b in boxes:
        if b.background:
            inst = Instance("background", b.class_name, Box3D(b.center, b.extent), 0.0, 0.0)
            out[inst.uuid] = inst
    return out
