"""Write ``Frame``s as a TUM RGB-D folder that ``open_log`` reads back.

Layout: ``rgb/<stem>.png`` (8-bit colour; ``.jpg`` when ``rgb_jpeg_quality`` is given),
``depth/<stem>.png`` (uint16, metres × ``camera.depth_scale``; depths beyond 65535 units or
invalid become 0), ``rgb.txt``,
``depth.txt`` (``stamp path``), ``groundtruth.txt`` (TUM trajectory of ``T_map_cam``),
``camera.json`` and, when any frame carries detections, ``detections.jsonl``.
``<stem>`` is the stamp with six decimals; ``write`` returns it so callers can put
companion files (ground-truth masks) beside the images under the same name.

    with TumWriter("out/log", camera) as writer:
        for frame in frames:
            writer.write(frame)
"""

from __future__ import annotations

import json
from pathlib import Path
from types import TracebackType
from typing import IO

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.trajectory import matrix_to_quat_xyzw
from hiper_cli.types import CameraIntrinsics, Frame

__all__ = ["TumWriter", "depth_to_uint16"]

UINT16_MAX = 65535


def depth_to_uint16(depth_m: NDArray[np.float32], depth_scale: float) -> NDArray[np.uint16]:
    """Metres to integer units (``depth_scale`` per metre); invalid or unrepresentable -> 0."""
    units = np.rint(np.nan_to_num(depth_m, nan=0.0, posinf=0.0, neginf=0.0).astype(np.float64) * depth_scale)
    units[(units < 0) | (units > UINT16_MAX)] = 0
    return units.astype(np.uint16)


class TumWriter:
    """Writes a TUM RGB-D folder frame by frame; the text files are flushed after every frame."""

    def __init__(self, root: str | Path, camera: CameraIntrinsics, *, overwrite: bool = False,
                 rgb_jpeg_quality: int | None = None) -> None:
        self.root = Path(root)
        self.camera = camera
        self.rgb_jpeg_quality = rgb_jpeg_quality
        if self.root.exists() and any(self.root.iterdir()) and not overwrite:
            raise LogError(f"{self.root}: folder exists and is not empty; choose another output or "
                           "pass --overwrite")
        (self.root / "rgb").mkdir(parents=True, exist_ok=True)
        (self.root / "depth").mkdir(parents=True, exist_ok=True)
        (self.root / "camera.json").write_text(json.dumps(camera.to_dict(), indent=2) + "\n")
        self._rgb = self._open("rgb.txt", "# color images\n# timestamp filename\n")
        self._depth = self._open("depth.txt", "# depth maps\n# timestamp filename\n")
        self._poses = self._open("groundtruth.txt", "# ground truth trajectory (T_map_cam)\n"
                                                    "# timestamp tx ty tz qx qy qz qw\n")
        self._detections: IO[str] | None = None
        self._last_stamp_s = -np.inf
        self.frames = 0

    def _open(self, name: str, header: str) -> IO[str]:
        handle = (self.root / name).open("w")
        handle.write(header)
        return handle

    def write(self, frame: Frame) -> str:
        """Append one frame; returns the file stem of its images (``f"{stamp_s:.6f}"``)."""
        import cv2

        if frame.stamp_s <= self._last_stamp_s:
            raise LogError(f"{self.root}: frame stamp {frame.stamp_s:.6f} does not increase after "
                           f"{self._last_stamp_s:.6f}; write frames in time order")
        if (frame.width, frame.height) != (self.camera.width, self.camera.height):
            raise LogError(f"{self.root}: frame is {frame.width}×{frame.height} but the writer's camera is "
                           f"{self.camera.width}×{self.camera.height}")
        stem = f"{frame.stamp_s:.6f}"
        rgb_ext = "png" if self.rgb_jpeg_quality is None else "jpg"
        rgb_name, depth_name = f"rgb/{stem}.{rgb_ext}", f"depth/{stem}.png"
        depth_units = depth_to_uint16(frame.depth_m, self.camera.depth_scale)
        quality = self.rgb_jpeg_quality
        rgb_params = [] if quality is None else [cv2.IMWRITE_JPEG_QUALITY, quality]
        for name, image, params in ((rgb_name, np.ascontiguousarray(frame.rgb[:, :, ::-1]), rgb_params),
                                    (depth_name, depth_units, [])):
            if not cv2.imwrite(str(self.root / name), image, params):
                raise LogError(f"{self.root / name}: cannot write the image; check the disk and permissions")
        T = frame.T_map_cam
        values = (*T[:3, 3], *matrix_to_quat_xyzw(T[:3, :3]))
        self._rgb.write(f"{stem} {rgb_name}\n")
        self._depth.write(f"{stem} {depth_name}\n")
        self._poses.write(f"{stem} " + " ".join(f"{v:.9f}" for v in values) + "\n")
        if frame.detections is not None:
            if self._detections is None:
                self._detections = (self.root / "detections.jsonl").open("w")
            record = {"stamp_s": round(frame.stamp_s, 6), "detections": frame.detections.to_records()}
            self._detections.write(json.dumps(record) + "\n")
        for handle in (self._rgb, self._depth, self._poses, self._detections):
            if handle is not None:
                handle.flush()
        self._last_stamp_s = frame.stamp_s
        self.frames += 1
        return stem

    def close(self) -> None:
        for handle in (self._rgb, self._depth, self._poses, self._detections):
            if handle is not None and not handle.closed:
                handle.close()

    def __enter__(self) -> TumWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
