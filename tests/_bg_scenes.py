"""Tiny analytic scenes for the background tests: axis-aligned boxes ray-cast into depth images."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiper_cli.types import CameraIntrinsics, Frame

CAMERA = CameraIntrinsics(width=640, height=480, fx=525.0, fy=525.0, cx=319.5, cy=239.5)


@dataclass(frozen=True)
class SceneBox:
    id: int
    class_name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]


def box_room(size=(6.0, 5.0, 2.6), thickness=0.1, start_id=1, door=None):
    """Floor, ceiling and four walls around [0, sx] × [0, sy] × [0, sz] (inner faces).

    ``door`` = (x0, x1, height): a doorway in the wall at y = sy (that wall becomes 3 boxes).
    """
    sx, sy, sz = size
    t = thickness
    boxes = [
        SceneBox(start_id, "floor", (-t, -t, -t), (sx + t, sy + t, 0.0)),
        SceneBox(start_id + 1, "ceiling", (-t, -t, sz), (sx + t, sy + t, sz + t)),
        SceneBox(start_id + 2, "wall", (-t, -t, 0.0), (0.0, sy + t, sz)),
        SceneBox(start_id + 3, "wall", (sx, -t, 0.0), (sx + t, sy + t, sz)),
        SceneBox(start_id + 4, "wall", (-t, -t, 0.0), (sx + t, 0.0, sz)),
    ]
    if door is None:
        boxes.append(SceneBox(start_id + 5, "wall", (-t, sy, 0.0), (sx + t, sy + t, sz)))
    else:
        x0, x1, dh = door
        boxes += [
            SceneBox(start_id + 5, "wall", (-t, sy, 0.0), (x0, sy + t, sz)),
            SceneBox(start_id + 5, "wall", (x1, sy, 0.0), (sx + t, sy + t, sz)),
            SceneBox(start_id + 5, "wall", (x0, sy, dh), (x1, sy + t, sz)),
        ]
    return boxes


def look_at(position, target):
    """T_map_cam of an optical camera at ``position`` looking at ``target`` (z up)."""
    p = np.asarray(position, float)
    z = np.asarray(target, float) - p
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, y, z], axis=1)
    T[:3, 3] = p
    return T


def render(boxes, T_map_cam, camera=CAMERA, noise_m=0.0, seed=0, step=4):
    """(depth_m float32, ids uint16) of the boxes seen from T_map_cam.

    Only every ``step``-th pixel is ray-cast and copied to its step×step block: the stage
    samples every 4th pixel (8th for RANSAC), so it sees exact values, 16× faster to make.
    """
    full_h, full_w = camera.height, camera.width
    u, v = np.meshgrid(np.arange(0, full_w, step, dtype=float), np.arange(0, full_h, step, dtype=float))
    h, w = u.shape
    d_cam = np.stack([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u)], -1)
    d_map = d_cam.reshape(-1, 3) @ T_map_cam[:3, :3].T
    o = T_map_cam[:3, 3]
    best = np.full(len(d_map), np.inf)
    ids = np.zeros(len(d_map), np.uint16)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d_map
        for box in boxes:
            t1 = (np.asarray(box.lo) - o) * inv
            t2 = (np.asarray(box.hi) - o) * inv
            tmin = np.nanmax(np.minimum(t1, t2), axis=1)
            tmax = np.nanmin(np.maximum(t1, t2), axis=1)
            hit = (tmax >= tmin) & (tmin > 1e-6) & (tmin < best)
            best[hit] = tmin[hit]
            ids[hit] = box.id
    depth = np.where(np.isfinite(best), best, 0.0).reshape(h, w)
    if noise_m > 0:
        rng = np.random.default_rng(seed)
        depth = depth + (depth > 0) * rng.normal(0.0, noise_m, depth.shape) * depth**2
    ids = ids.reshape(h, w)

    def up(a):
        return np.repeat(np.repeat(a, step, axis=0), step, axis=1)[:full_h, :full_w]

    return up(depth).astype(np.float32), up(ids)


def make_frame(boxes, T_map_cam, pose_id=0, stamp_s=None, noise_m=0.0, camera=CAMERA):
    depth, ids = render(boxes, T_map_cam, camera, noise_m=noise_m, seed=pose_id)
    rgb = np.zeros((camera.height, camera.width, 3), np.uint8)
    stamp = float(pose_id) * 0.5 if stamp_s is None else stamp_s
    return Frame(stamp, rgb, depth, camera, T_map_cam, pose_id, extras={"gt_ids": ids})


def with_dropouts(frame, share, seed=0):
    """``frame`` with ``share`` of its 4×4-pixel blocks returning no depth, as a real camera's
    dark and glossy patches and grazing surfaces do (docs/sensors.md)."""
    import dataclasses

    rng = np.random.default_rng(seed)
    h, w = frame.depth_m.shape
    lost = np.repeat(np.repeat(rng.random((h // 4, w // 4)) < share, 4, axis=0), 4, axis=1)
    return dataclasses.replace(frame, depth_m=np.where(lost, 0.0, frame.depth_m).astype(np.float32))
