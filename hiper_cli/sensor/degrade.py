"""Degrade a log: every frame as a profile's sensor would see it, poses from a drifting estimate.

``DegradedLog`` wraps any ``LogReader``; ``degrade_log`` writes it as a TUM folder (colour as
JPEG at the profile's quality) and keeps the truth beside it: the input's ``gt/`` is copied and
``gt/groundtruth.txt`` holds the exact trajectory (the folder's own ``groundtruth.txt`` is the
drifting estimate hiper reads), ``gt/sensor.json`` the profile, seed and pose error.
A frame's randomness is seeded by (seed, frame index), so a seed gives identical output.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.logs import LogReader
from hiper_cli.perceive.logs.base import LogInfo
from hiper_cli.perceive.logs.convert import ConvertResult, convert_log
from hiper_cli.perceive.logs.trajectory import matrix_to_quat_xyzw
from hiper_cli.sensor.colour import degrade_rgb, image_flow_px_per_s
from hiper_cli.sensor.depth import degrade_depth
from hiper_cli.sensor.poses import drifting_poses
from hiper_cli.sensor.profiles import SensorProfile
from hiper_cli.types import Frame

__all__ = ["DegradeResult", "DegradedLog", "degrade_frame", "degrade_log", "luma", "pose_error",
           "write_trajectory"]

_POSE_STREAM = 0x5E50  # the pose source's own random stream, apart from the frames'


def luma(rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Grey level (ITU-R 601) of an RGB image: a stand-in for the IR reflectance."""
    grey = rgb[..., 0] * 0.299 + rgb[..., 1] * 0.587 + rgb[..., 2] * 0.114
    out: NDArray[np.uint8] = grey.astype(np.uint8)
    return out


def degrade_frame(frame: Frame, flow_px_per_s: NDArray[np.float64], profile: SensorProfile,
                  rng: np.random.Generator, *, jpeg: bool = True) -> Frame:
    """``frame`` with the profile's depth and colour artefacts (the pose is left as it is)."""
    depth = degrade_depth(frame.depth_m, luma(frame.rgb), frame.camera, profile, rng)
    rgb = degrade_rgb(frame.rgb, flow_px_per_s, profile, jpeg=jpeg)
    return replace(frame, rgb=rgb, depth_m=depth)


def pose_error(T_true: NDArray[np.float64], T_est: NDArray[np.float64]) -> dict[str, float]:
    """Translation error of the estimate: RMS, largest and last (m), and the last rotation error (deg)."""
    if len(T_true) == 0:
        return {"rms_m": 0.0, "max_m": 0.0, "final_m": 0.0, "final_deg": 0.0}
    err = np.linalg.norm(T_true[:, :3, 3] - T_est[:, :3, 3], axis=1)
    R = T_true[-1, :3, :3].T @ T_est[-1, :3, :3]
    final_deg = float(np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0))))
    return {"rms_m": round(float(np.sqrt(np.mean(err ** 2))), 4), "max_m": round(float(err.max()), 4),
            "final_m": round(float(err[-1]), 4), "final_deg": round(final_deg, 3)}


class DegradedLog:
    """A ``LogReader`` giving ``reader``'s frames as ``profile``'s sensor and pose source see them."""

    def __init__(self, reader: LogReader, profile: SensorProfile, seed: int = 0, *,
                 jpeg: bool = True) -> None:
        self.reader = reader
        self.profile = profile
        self.seed = seed
        self.jpeg = jpeg
        self.skipped: list[tuple[str, str]] = []
        info = reader.info()
        self.T_map_cam_true = info.T_map_cam
        self.stamps_s = info.stamps_s
        pose_rng = np.random.default_rng([seed, _POSE_STREAM])
        self.T_map_cam_est = drifting_poses(info.T_map_cam, profile, pose_rng)

    def __len__(self) -> int:
        return len(self.reader)

    def info(self) -> LogInfo:
        info = self.reader.info()
        source = info.pose_source
        if not self.profile.exact_poses:
            source = f"{source}, drifting ({self.profile.name})"
        return replace(info, T_map_cam=self.T_map_cam_est, pose_source=source)

    def _flow(self, frame: Frame) -> NDArray[np.float64]:
        i, n = frame.pose_id, len(self.stamps_s)
        if n < 2:
            return np.zeros(2)
        a, b = (i, i + 1) if i + 1 < n else (i - 1, i)
        return image_flow_px_per_s(self.T_map_cam_true[a], self.T_map_cam_true[b],
                                   float(self.stamps_s[b] - self.stamps_s[a]), frame.camera, frame.depth_m)

    def _degrade(self, frame: Frame) -> Frame:
        rng = np.random.default_rng([self.seed, frame.pose_id])
        out = degrade_frame(frame, self._flow(frame), self.profile, rng, jpeg=self.jpeg)
        return replace(out, T_map_cam=self.T_map_cam_est[frame.pose_id])

    def __iter__(self) -> Iterator[Frame]:
        for frame in self.reader:
            yield self._degrade(frame)
        self.skipped = list(self.reader.skipped)

    def read_frame(self, pose_id: int) -> Frame:
        return self._degrade(self.reader.read_frame(pose_id))


@dataclass(frozen=True)
class DegradeResult:
    convert: ConvertResult
    profile: SensorProfile
    seed: int
    pose_error: dict[str, float]
    gt_copied: bool

    def to_dict(self) -> dict[str, Any]:
        return {**self.convert.to_dict(), "profile": self.profile.name, "seed": self.seed,
                "pose_error": self.pose_error, "gt_copied": self.gt_copied}


def write_trajectory(path: Path, stamps_s: NDArray[np.float64], T_map_cam: NDArray[np.float64]) -> None:
    """A TUM trajectory file: ``stamp tx ty tz qx qy qz qw`` per pose (the exact one, beside a log)."""
    lines = ["# exact trajectory (T_map_cam) of the degraded log", "# timestamp tx ty tz qx qy qz qw"]
    for stamp, T in zip(stamps_s, T_map_cam, strict=True):
        values = (*T[:3, 3], *matrix_to_quat_xyzw(T[:3, :3]))
        lines.append(f"{stamp:.6f} " + " ".join(f"{v:.9f}" for v in values))
    path.write_text("\n".join(lines) + "\n")


def degrade_log(reader: LogReader, out: str | Path, profile: SensorProfile, seed: int = 0, *,
                overwrite: bool = False, on_frame: Callable[[Frame], None] | None = None) -> DegradeResult:
    """Write ``reader`` as ``profile``'s sensor sees it to the TUM folder ``out``, truth in ``out/gt``."""
    log = DegradedLog(reader, profile, seed, jpeg=False)
    quality = profile.jpeg_quality or None
    result = convert_log(log, out, "tum", overwrite=overwrite, on_frame=on_frame, rgb_jpeg_quality=quality)
    gt = Path(out) / "gt"
    source_gt = Path(reader.info().path) / "gt"
    copied = source_gt.is_dir()
    if copied:
        shutil.copytree(source_gt, gt, dirs_exist_ok=True)
    gt.mkdir(exist_ok=True)
    write_trajectory(gt / "groundtruth.txt", log.stamps_s, log.T_map_cam_true)
    errors = pose_error(log.T_map_cam_true, log.T_map_cam_est)
    (gt / "sensor.json").write_text(json.dumps(
        {"profile": profile.to_dict(), "seed": seed, "source": str(reader.info().path),
         "pose_error": errors, "note": "../groundtruth.txt is the drifting estimate; "
                                       "groundtruth.txt here is the exact trajectory"}, indent=2) + "\n")
    return DegradeResult(result, profile, seed, errors, copied)
