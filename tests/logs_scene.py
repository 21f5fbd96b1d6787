"""A tiny RGB-D scene built in code, shared by the log reader tests."""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.logs.trajectory import quat_xyzw_to_matrix
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAMERA = CameraIntrinsics(width=32, height=24, fx=30.0, fy=30.0, cx=15.5, cy=11.5, depth_scale=5000.0)
T0_S = 1_700_000_000.0
RATE_HZ = 10.0


def pose(k: int) -> np.ndarray:
    yaw = 0.1 * k
    half = yaw / 2
    # camera optical frame (z forward) looking along the map's x axis, then yawing about map z
    R_map_cam0 = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    R = quat_xyzw_to_matrix(np.array([0.0, 0.0, np.sin(half), np.cos(half)])) @ R_map_cam0
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = [0.2 * k, 0.05 * k, 1.2]
    return T


def make_frames(n: int = 6, seed: int = 0, detections: bool = True, camera: CameraIntrinsics = CAMERA
                ) -> list[Frame]:
    rng = np.random.default_rng(seed)
    frames = []
    for k in range(n):
        rgb = rng.integers(0, 256, size=(camera.height, camera.width, 3), dtype=np.uint8)
        depth = rng.uniform(0.5, 4.0, size=(camera.height, camera.width))
        depth = (np.rint(depth * 1000.0) / 1000.0).astype(np.float32)  # exact in mm and 1/5000 m
        depth[0, :3] = 0.0  # some invalid pixels
        dets = None
        if detections:
            box = {"xyxy": [1.0 + k, 2.0, 10.0 + k, 12.0], "class": "cup", "score": 0.75}
            dets = Detections.from_records([box] if k % 2 == 0 else [])
        frames.append(Frame(stamp_s=round(T0_S + k / RATE_HZ, 6), rgb=rgb, depth_m=depth, camera=camera,
                            T_map_cam=pose(k), pose_id=k, detections=dets, source=f"scene {k}"))
    return frames
