"""A pose source that is not the truth: visual-SLAM-like drift plus per-frame noise.

The estimate integrates the true frame-to-frame motion with an error that grows with the motion:
a translation bias of ``drift_per_m`` metres per metre travelled and a rotation bias of
``drift_deg_per_m`` degrees per metre (per radian turned, counted as 0.5 m), both slowly
changing direction (correlation over ``BIAS_CORRELATION_M`` of motion), as a visual odometry
front end drifts; rotation errors also bend the later path. White noise of ``pose_noise_m`` and
``pose_noise_deg`` is added on top without accumulating (the jitter of a tracker).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.sensor.profiles import SensorProfile

__all__ = ["BIAS_CORRELATION_M", "drifting_poses", "rotation_about"]

BIAS_CORRELATION_M = 5.0
METRES_PER_RADIAN = 0.5


def rotation_about(rotvec: NDArray[np.float64]) -> NDArray[np.float64]:
    """3×3 rotation of the rotation vector ``rotvec`` (radians)."""
    angle = float(np.linalg.norm(rotvec))
    if angle < 1e-12:
        return np.eye(3)
    k = rotvec / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * (K @ K)


def _angle(R: NDArray[np.float64]) -> float:
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)))


def drifting_poses(T_map_cam: NDArray[np.float64], profile: SensorProfile,
                   rng: np.random.Generator) -> NDArray[np.float64]:
    """(N, 4, 4) estimated poses for the true ``T_map_cam``; the first pose is exact."""
    n = len(T_map_cam)
    out = np.array(T_map_cam, dtype=np.float64, copy=True)
    if n == 0 or profile.exact_poses:
        return out
    drift_rad_per_m = np.radians(profile.drift_deg_per_m)
    bias_t = rng.standard_normal(3) * profile.drift_per_m / np.sqrt(3)
    bias_r = rng.standard_normal(3) * drift_rad_per_m / np.sqrt(3)
    estimate = out[0].copy()
    for i in range(1, n):
        step = np.linalg.inv(T_map_cam[i - 1]) @ T_map_cam[i]
        motion_m = float(np.linalg.norm(step[:3, 3])) + METRES_PER_RADIAN * _angle(step[:3, :3])
        keep = np.exp(-motion_m / BIAS_CORRELATION_M)
        fresh = np.sqrt(max(0.0, 1 - keep * keep)) / np.sqrt(3)
        bias_t = keep * bias_t + fresh * profile.drift_per_m * rng.standard_normal(3)
        bias_r = keep * bias_r + fresh * drift_rad_per_m * rng.standard_normal(3)
        noisy_step = step.copy()
        noisy_step[:3, 3] += bias_t * motion_m
        noisy_step[:3, :3] = step[:3, :3] @ rotation_about(bias_r * motion_m)
        estimate = estimate @ noisy_step
        out[i] = estimate
    jitter = np.repeat(np.eye(4)[None], n, axis=0)
    noise_rad = np.radians(profile.pose_noise_deg) / np.sqrt(3)
    for i in range(1, n):
        jitter[i, :3, :3] = rotation_about(rng.standard_normal(3) * noise_rad)
        jitter[i, :3, 3] = rng.standard_normal(3) * profile.pose_noise_m / np.sqrt(3)
    return np.asarray(out @ jitter)
