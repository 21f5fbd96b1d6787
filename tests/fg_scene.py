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
    relief_m: float = 0.0
    """The middle half of the box's width, as the camera sees it, is this much nearer than the
    sides: a body (chest before the arms) rather than a flat panel."""


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
    """A standing person: a 0.3 x 0.5 x 1.7 m box whose middle (the chest) stands 0.1 m before
    its sides (a person is no flat panel)."""
    return SceneBox(id_, np.array([x, y, 0.85]), np.array([0.3, 0.5, 1.7]), "person", relief_m=0.1)


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
            if b.relief_m > 0 and hit.any():
                cols = u.reshape(-1)[hit]
                half = (cols.max() - cols.min()) / 4.0
                middle = np.abs(u.reshape(-1) - (cols.min() + cols.max()) / 2.0) <= half
                t = np.where(hit & middle, t - b.relief_m, t)
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


def chair(id_: int, x: float, y: float) -> SceneBox:
    return SceneBox(id_, np.array([x, y, 0.45]), np.array([0.5, 0.5, 0.9]), "chair")


def write_sim_log(root, seconds: float = 3.0, rate_hz: float = 30.0, speed_mps: float = 0.6,
                  fp_every: int = 0) -> None:
    """A ``hiper sim``-shaped log: a person walking past a chair in a room, static camera.

    ``fp_every``: add a false-positive detection (instance_id null) every n-th frame.
    """
    import json

    import cv2

    from hiper_cli.perceive.logs import TumWriter

    root.mkdir(parents=True, exist_ok=True)
    (root / "gt" / "instance_ids").mkdir(parents=True)
    statics = [*room(), chair(11, 4.0, 1.0)]
    T = pose_looking_x()
    tracks, det_lines = [], []
    n = int(seconds * rate_hz)
    with TumWriter(root, CAMERA, overwrite=True) as writer:
        for k in range(n):
            t = 100.0 + k / rate_hz
            y = -1.2 + speed_mps * (t - 100.0)
            walker = person(10, 3.0, y)
            boxes = [*statics, walker]
            depth, ids = render(boxes, T)
            frame = Frame(t, np.zeros((CAMERA.height, CAMERA.width, 3), np.uint8), depth, CAMERA, T, k)
            stem = writer.write(frame)
            cv2.imwrite(str(root / "gt" / "instance_ids" / f"{stem}.png"), ids)
            tracks.append(f"{t:.6f},10,3.0,{y:.6f},0.85,0.0,{speed_mps},0.0")
            records = []
            for b in (walker, statics[-1]):
                ys, xs = np.nonzero(ids == b.id)
                if len(xs):
                    records.append({"xyxy": [float(xs.min()), float(ys.min()), float(xs.max() + 1),
                                             float(ys.max() + 1)], "class": b.class_name, "score": 0.9,
                                    "instance_id": b.id})
            if fp_every and k % fp_every == 0:
                fp = {"xyxy": [10.0, 10.0, 30.0, 40.0], "class": "tv", "score": 0.5, "instance_id": None}
                records.append(fp)
            det_lines.append(json.dumps({"stamp_s": round(t, 6), "detections": records}))
    instances = [
        {"id": b.id, "name": b.class_name, "class": b.class_name,
         "layer": "background" if b.background else "foreground", "state": "static",
         "box": Box3D(b.center, b.extent).to_dict(), "plane": None, "speed_mps": None}
        for b in statics
    ]
    instances.append({"id": 10, "name": "person_0", "class": "person", "layer": "foreground",
                      "state": "dynamic",
                      "box": Box3D(person(10, 3.0, -1.2).center, person(10, 3, 0).extent).to_dict(),
                      "plane": None, "speed_mps": speed_mps})
    world = {"world": "fg_test", "seed": 5, "rate_hz": rate_hz, "instances": instances,
             "phases": [{"name": "operation", "t_start_s": 100.0, "t_end_s": 100.0 + seconds}]}
    (root / "gt" / "world.json").write_text(json.dumps(world))
    (root / "gt" / "tracks.csv").write_text("stamp_s,id,x,y,z,vx,vy,vz\n" + "\n".join(tracks) + "\n")
    (root / "gt" / "detections.jsonl").write_text("\n".join(det_lines) + "\n")
    (root / "gt" / "noise.json").write_text("{}")
