"""What every log reader shares: the frame index, ``LogInfo``, iteration with counted skips.

A reader first builds an index (one ``FrameEntry`` per frame: stamp, pose, where its images
are) without decoding images; ``info()`` comes from the index alone. Iterating decodes the
images; a frame whose images cannot be read is skipped and recorded in ``skipped`` as
``(source, reason)``; when no frame at all can be read, iteration raises ``LogError``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.types import CameraIntrinsics, Detections, Frame

__all__ = ["FrameEntry", "IndexedLog", "LogInfo", "StampGap", "find_stamp_gaps"]

FloatArray = NDArray[np.float64]

# A step between frames longer than this many times the median step is a gap.
GAP_FACTOR = 2.0
# Give up early when this many frames in a row from the start cannot be read.
MAX_LEADING_FAILURES = 25


@dataclass(frozen=True)
class StampGap:
    """A hole in the frame stream: no frame between ``after_stamp_s`` and ``after_stamp_s + gap_s``."""

    after_stamp_s: float
    gap_s: float

    def to_dict(self) -> dict[str, float]:
        return {"after_stamp_s": self.after_stamp_s, "gap_s": self.gap_s}


def find_stamp_gaps(stamps_s: FloatArray, factor: float = GAP_FACTOR) -> tuple[StampGap, ...]:
    """Steps longer than ``factor`` × the median step."""
    if len(stamps_s) < 3:
        return ()
    steps = np.diff(stamps_s)
    median = float(np.median(steps))
    if median <= 0:
        return ()
    long = np.flatnonzero(steps > factor * median)
    return tuple(StampGap(float(stamps_s[i]), float(steps[i])) for i in long)


@dataclass(frozen=True)
class FrameEntry:
    """One frame of the index: its stamp, pose, images' locations and detections."""

    stamp_s: float
    T_map_cam: FloatArray
    source: str
    locator: Any
    detections: Detections | None = None


@dataclass(frozen=True)
class LogInfo:
    """What a log holds, known without decoding its images.

    ``stamps_s`` (N,) and ``T_map_cam`` (N, 4, 4) list every frame; ``sources`` maps a role
    (``rgb``, ``depth``, ``poses``, ``camera``, ``detections``) to its file or topic;
    ``skipped`` lists frames dropped while indexing (for example, no pose at that stamp).
    """

    path: str
    format: str
    frames: int
    camera: CameraIntrinsics
    pose_source: str
    has_detections: bool
    sources: dict[str, str]
    stamps_s: FloatArray
    T_map_cam: FloatArray
    stamp_gaps: tuple[StampGap, ...] = ()
    skipped: tuple[tuple[str, str], ...] = ()

    @property
    def duration_s(self) -> float:
        return float(self.stamps_s[-1] - self.stamps_s[0]) if self.frames else 0.0

    @property
    def rate_hz(self) -> float:
        return (self.frames - 1) / self.duration_s if self.frames > 1 and self.duration_s > 0 else 0.0

    @property
    def resolution(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return (self.camera.width, self.camera.height)

    def to_dict(self, frames: bool = False) -> dict[str, Any]:
        """JSON form; ``frames=True`` adds every frame's stamp and pose (x y z qx qy qz qw)."""
        out: dict[str, Any] = {
            "path": self.path,
            "format": self.format,
            "frames": self.frames,
            "first_stamp_s": round(float(self.stamps_s[0]), 6) if self.frames else None,
            "last_stamp_s": round(float(self.stamps_s[-1]), 6) if self.frames else None,
            "duration_s": round(self.duration_s, 6),
            "rate_hz": round(self.rate_hz, 4),
            "resolution": list(self.resolution),
            "camera": self.camera.to_dict(),
            "pose_source": self.pose_source,
            "has_detections": self.has_detections,
            "sources": dict(self.sources),
            "stamp_gaps": [g.to_dict() for g in self.stamp_gaps],
            "skipped": [{"source": s, "reason": r} for s, r in self.skipped],
        }
        if frames:
            from hiper_cli.perceive.logs.trajectory import matrix_to_quat_xyzw

            out["frame_list"] = [
                {
                    "pose_id": i,
                    "stamp_s": round(float(stamp), 6),
                    "pose_xyz_qxyzw": [round(float(v), 6) for v in
                                       (*T[:3, 3], *matrix_to_quat_xyzw(T[:3, :3]))],
                }
                for i, (stamp, T) in enumerate(zip(self.stamps_s, self.T_map_cam, strict=True))
            ]
        return out


@dataclass(eq=False)
class IndexedLog:
    """Base of the readers: subclasses fill ``entries`` and implement ``_read_images``."""

    path: str
    format: str
    camera: CameraIntrinsics
    entries: list[FrameEntry]
    pose_source: str
    sources: dict[str, str]
    has_detections: bool = False
    index_skipped: list[tuple[str, str]] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)
    max_rate_hz: float | None = None
    """Iterate at most this many frames per second of log time (``kept_ids``); None: all."""

    def __len__(self) -> int:
        return len(self.entries)

    def kept_ids(self) -> list[int]:
        """The pose ids that iterating reads: every frame, or with ``max_rate_hz`` the first
        frame and then each one at least ``1 / max_rate_hz`` after the one kept before it, less
        a quarter of the log's median frame step (stamp jitter must not skip one more). The
        others are never decoded: a 30 Hz log read at 15 Hz costs half the decoding."""
        if not self.max_rate_hz or len(self.entries) < 2:
            return list(range(len(self.entries)))
        stamps = np.array([e.stamp_s for e in self.entries], dtype=np.float64)
        period_s = 1.0 / float(self.max_rate_hz) - 0.25 * float(np.median(np.diff(stamps)))
        kept, last_s = [0], float(stamps[0])
        for k in range(1, len(stamps)):
            if stamps[k] - last_s >= period_s:
                kept.append(k)
                last_s = float(stamps[k])
        return kept

    def _read_images(self, entry: FrameEntry) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        raise NotImplementedError

    def info(self) -> LogInfo:
        stamps = np.array([e.stamp_s for e in self.entries], dtype=np.float64)
        poses = (np.stack([e.T_map_cam for e in self.entries]) if self.entries
                 else np.zeros((0, 4, 4), dtype=np.float64))
        return LogInfo(
            path=self.path,
            format=self.format,
            frames=len(self.entries),
            camera=self.camera,
            pose_source=self.pose_source,
            has_detections=self.has_detections,
            sources=dict(self.sources),
            stamps_s=stamps,
            T_map_cam=poses,
            stamp_gaps=find_stamp_gaps(stamps),
            skipped=tuple(self.index_skipped),
        )

    def _decoded(self) -> Iterator[tuple[int, tuple[NDArray[np.uint8], NDArray[np.float32]] | LogError]]:
        """Every kept frame's images in order, or the error that kept them from being read."""
        for pose_id in self.kept_ids():
            try:
                yield pose_id, self._read_images(self.entries[pose_id])
            except LogError as err:
                yield pose_id, err

    def read_frame(self, pose_id: int) -> Frame:
        """Decode frame ``pose_id`` (raises ``LogError`` when its images cannot be read)."""
        if not 0 <= pose_id < len(self.entries):
            raise LogError(f"{self.path}: frame {pose_id} does not exist; the log has {len(self.entries)} "
                           "frames")
        return self._make_frame(pose_id, *self._read_images(self.entries[pose_id]))

    def _make_frame(self, pose_id: int, rgb: NDArray[np.uint8], depth_m: NDArray[np.float32]) -> Frame:
        entry = self.entries[pose_id]
        if rgb.shape[:2] != depth_m.shape:
            raise LogError(f"{entry.source}: rgb is {rgb.shape[1]}×{rgb.shape[0]} but depth is "
                           f"{depth_m.shape[1]}×{depth_m.shape[0]}; register depth to the colour camera")
        if rgb.shape[:2] != (self.camera.height, self.camera.width):
            raise LogError(f"{entry.source}: image is {rgb.shape[1]}×{rgb.shape[0]} but the camera "
                           f"intrinsics are for {self.camera.width}×{self.camera.height}; pass the right "
                           "camera.json or camera flags")
        return Frame(
            stamp_s=entry.stamp_s,
            rgb=rgb,
            depth_m=depth_m,
            camera=self.camera,
            T_map_cam=entry.T_map_cam,
            pose_id=pose_id,
            detections=entry.detections,
            source=entry.source,
        )

    def __iter__(self) -> Iterator[Frame]:
        self.skipped = list(self.index_skipped)
        yielded = 0
        first_reason = ""
        for pose_id, result in self._decoded():
            entry = self.entries[pose_id]
            try:
                if isinstance(result, LogError):
                    raise result
                frame = self._make_frame(pose_id, *result)
            except LogError as err:
                self.skipped.append((entry.source, str(err)))
                first_reason = first_reason or str(err)
                if yielded == 0 and pose_id + 1 >= MAX_LEADING_FAILURES:
                    raise LogError(f"{self.path}: the first {pose_id + 1} frames cannot be read; first "
                                   f"problem: {first_reason}") from err
                continue
            yielded += 1
            yield frame
        if yielded == 0 and self.entries:
            raise LogError(f"{self.path}: none of the {len(self.kept_ids())} frames can be read; first "
                           f"problem: {first_reason}")
