"""Correcting a session's drift along its path: one pose correction per segment, against the
place's map.

One rigid ``T_map_log`` cannot carry a whole drifting log onto the map: the log's odometry
drifts along its path (some 0.5 % of the distance and 0.1°/m) and so did the session that
built the map. Change detection compares what this session sees with what the map holds at
the same spot, so what matters is that the two agree locally, where the objects are.

So the log is cut into keyframes every ``SEGMENT_M`` of motion (metres plus
``METRES_PER_RADIAN`` per radian turned). At each, the background cloud of the frames within
``WINDOW_M`` of motion around it (log frame) is registered to the map by the conditioned
point-to-plane ICP of ``perceive.align_start``, starting from the previous keyframe's
transform: the directions the window constrains move, the others keep the previous value.
A fit with too few points on the map, or one that moves more than ``MAX_SEGMENT_CHANGE`` from
the previous keyframe (drift is slow; a jump is a wrong fit), is not used and the previous
transform carries on. A frame's transform is interpolated between the keyframes around it
(translation linearly, rotation along the geodesic), so the correction is smooth.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.align import BackgroundCloud
from hiper_cli.perceive.align_start import MapSurface, refine
from hiper_cli.perceive.logs.trajectory import rotation_about, rotation_angle_rad, rotation_vector

__all__ = ["MAX_SEGMENT_CHANGE", "METRES_PER_RADIAN", "SEGMENT_M", "WINDOW_M", "PathCorrection",
           "correct_path", "motion_m", "travelled_m"]

FloatArray = NDArray[np.float64]

SEGMENT_M = 1.0  # a keyframe every this much motion
WINDOW_M = 3.0  # a keyframe's cloud: the frames within half of this of motion around it
STEP_M = 0.2  # ... one frame per this much motion
MIN_INLIERS = 0.3  # below this share of the window's points on the map, its fit is not used
MAX_SEGMENT_CHANGE = (0.1, 1.0)  # metres (at the keyframe), degrees from the previous keyframe
METRES_PER_RADIAN = 0.5


def motion_m(T_a: FloatArray, T_b: FloatArray) -> float:
    """The motion from pose ``T_a`` to ``T_b``: metres plus ``METRES_PER_RADIAN`` per radian."""
    step = np.linalg.inv(T_a) @ T_b
    return float(np.linalg.norm(step[:3, 3])) + METRES_PER_RADIAN * rotation_angle_rad(step[:3, :3])


def travelled_m(T_log_cam: FloatArray) -> FloatArray:
    """Per pose, the motion since the first: metres plus ``METRES_PER_RADIAN`` per radian."""
    out = np.zeros(len(T_log_cam))
    for k in range(1, len(T_log_cam)):
        out[k] = out[k - 1] + motion_m(T_log_cam[k - 1], T_log_cam[k])
    return out


def _change(T_a: FloatArray, T_b: FloatArray, at_log: FloatArray) -> tuple[float, float]:
    """How far ``T_b`` carries the log point ``at_log`` from where ``T_a`` does (m), and the
    angle between them (degrees)."""
    moved = T_b[:3, :3] @ at_log + T_b[:3, 3] - (T_a[:3, :3] @ at_log + T_a[:3, 3])
    return float(np.linalg.norm(moved)), float(np.degrees(rotation_angle_rad(T_a[:3, :3].T @ T_b[:3, :3])))


@dataclass(frozen=True)
class PathCorrection:
    """``T_map_log`` per keyframe (``keys_m``: the motion where it lies), interpolated per
    pose by its motion ``travelled_m``; ``used``: keyframes whose own fit was used;
    ``largest``: the largest correction from the start's transform (m at the keyframe, deg)."""

    travelled_m: FloatArray
    keys_m: FloatArray
    T_keys: FloatArray
    used: int
    largest: tuple[float, float]

    def T_map_log(self, pose_id: int) -> FloatArray:
        s = float(self.travelled_m[pose_id])
        k = int(np.searchsorted(self.keys_m, s, side="right")) - 1
        if k >= len(self.keys_m) - 1:
            out: FloatArray = self.T_keys[-1]
            return out
        k = max(k, 0)
        a = (s - self.keys_m[k]) / max(self.keys_m[k + 1] - self.keys_m[k], 1e-12)
        T0, T1 = self.T_keys[k], self.T_keys[k + 1]
        T = np.eye(4)
        T[:3, :3] = T0[:3, :3] @ rotation_about(a * rotation_vector(T0[:3, :3].T @ T1[:3, :3]))
        T[:3, 3] = (1 - a) * T0[:3, 3] + a * T1[:3, 3]
        return T

    def note(self) -> str:
        return (f"corrected along its path: {self.used} of {len(self.keys_m) - 1} segments re-localised on "
                f"the map, up to {self.largest[0]:.3f} m, {self.largest[1]:.2f} deg from the start's fit")


def _frame_clouds(reader: Any, s: FloatArray) -> dict[int, FloatArray]:
    """Background points (log frame, voxel centroids) of one frame per ``STEP_M`` of motion; a
    frame whose images cannot be read is passed over (perception skips it too)."""
    clouds: dict[int, FloatArray] = {}
    last = -np.inf
    for k in range(len(s)):
        if s[k] - last >= STEP_M or k == len(s) - 1:
            try:
                frame = reader.read_frame(k)
            except LogError:
                continue
            cloud = BackgroundCloud()
            cloud.add_frame(frame)
            clouds[k] = cloud.points()
            last = s[k]
    return clouds


def correct_path(reader: Any, map_points: FloatArray, T_start: FloatArray) -> PathCorrection:
    """The log's drift corrected against the map along its path, from ``T_start`` (the
    session's transform, right at its start); see the module docstring."""
    poses = np.asarray(reader.info().T_map_cam, dtype=np.float64)
    s = travelled_m(poses)
    clouds = _frame_clouds(reader, s)
    picked = np.array(sorted(clouds), dtype=np.int64)
    surface = MapSurface(map_points)
    keys = np.arange(0.0, s[-1] + SEGMENT_M, SEGMENT_M) if len(s) else np.zeros(1)
    T_prev = np.asarray(T_start, dtype=np.float64)
    T_keys, used, largest = [T_prev], 0, (0.0, 0.0)
    for key in keys[1:]:
        near = picked[np.abs(s[picked] - key) <= WINDOW_M / 2]
        at_log = poses[int(np.argmin(np.abs(s - key))), :3, 3]
        window = BackgroundCloud()
        for k in near:
            window.add_points(clouds[int(k)])
        points = window.points()
        if len(points) >= 20:
            fit = refine(points, surface, T_prev)
            metres, degrees = _change(T_prev, fit.T_map_log, at_log)
            if (fit.inliers >= MIN_INLIERS and fit.constrained > 0
                    and metres <= MAX_SEGMENT_CHANGE[0] and degrees <= MAX_SEGMENT_CHANGE[1]):
                T_prev, used = fit.T_map_log, used + 1
        T_keys.append(T_prev)
        from_start = _change(np.asarray(T_start, dtype=np.float64), T_prev, at_log)
        largest = (max(largest[0], from_start[0]), max(largest[1], from_start[1]))
    return PathCorrection(s, keys, np.stack(T_keys), used, largest)
