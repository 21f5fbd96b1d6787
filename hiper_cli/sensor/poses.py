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

from hiper_cli.perceive.logs.trajectory import rotation_about
from hiper_cli.sensor.profiles import SensorProfile

__all__ = ["BIAS_CORRELATION_M", "PoseSource", "drifting_poses", "rotation_about"]

BIAS_CORRELATION_M = 5.0
METRES_PER_RADIAN = 0.5


def _angle(R: NDArray[np.float64]) -> float:
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)))


class PoseSource:
    """Feeds true poses in time order and returns the drifting estimates (the first is exact)."""

    def __init__(self, profile: SensorProfile, rng: np.random.Generator) -> None:
        self.profile = profile
        self.rng = rng
        self._drift_rad_per_m = float(np.radians(profile.drift_deg_per_m))
        self._noise_rad = float(np.radians(profile.pose_noise_deg)) / np.sqrt(3)
        self._bias_t = rng.standard_normal(3) * profile.drift_per_m / np.sqrt(3)
        self._bias_r = rng.standard_normal(3) * self._drift_rad_per_m / np.sqrt(3)
        self._last_true: NDArray[np.float64] | None = None
        self._estimate = np.eye(4)

    def _drift_step(self, T_map_cam: NDArray[np.float64]) -> None:
        assert self._last_true is not None
        step = np.linalg.inv(self._last_true) @ T_map_cam
        motion_m = float(np.linalg.norm(step[:3, 3])) + METRES_PER_RADIAN * _angle(step[:3, :3])
        keep = np.exp(-motion_m / BIAS_CORRELATION_M)
        fresh = np.sqrt(max(0.0, 1 - keep * keep)) / np.sqrt(3)
        self._bias_t = keep * self._bias_t + fresh * self.profile.drift_per_m * self.rng.standard_normal(3)
        self._bias_r = keep * self._bias_r + fresh * self._drift_rad_per_m * self.rng.standard_normal(3)
        noisy_step = step.copy()
        noisy_step[:3, 3] += self._bias_t * motion_m
        noisy_step[:3, :3] = step[:3, :3] @ rotation_about(self._bias_r * motion_m)
        self._estimate = self._estimate @ noisy_step

    def next(self, T_map_cam: NDArray[np.float64]) -> NDArray[np.float64]:
        """The estimate for the next true pose ``T_map_cam``."""
        T_true = np.asarray(T_map_cam, dtype=np.float64)
        if self.profile.exact_poses:
            return T_true.copy()
        if self._last_true is None:
            self._last_true, self._estimate = T_true, T_true.copy()
            return T_true.copy()
        self._drift_step(T_true)
        self._last_true = T_true
        jitter = np.eye(4)
        jitter[:3, :3] = rotation_about(self.rng.standard_normal(3) * self._noise_rad)
        jitter[:3, 3] = self.rng.standard_normal(3) * self.profile.pose_noise_m / np.sqrt(3)
        return np.asarray(self._estimate @ jitter)


def drifting_poses(T_map_cam: NDArray[np.float64], profile: SensorProfile,
                   rng: np.random.Generator) -> NDArray[np.float64]:
    """(N, 4, 4) estimated poses for the true ``T_map_cam``; the first pose is exact."""
    source = PoseSource(profile, rng)
    out = np.array([source.next(T) for T in T_map_cam], dtype=np.float64)
    return out.reshape(len(T_map_cam), 4, 4)
