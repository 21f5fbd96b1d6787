"""Typed, validated core types that every stage exchanges.

Units: metres, seconds, radians. Frames: ``T_a_b`` maps coordinates in frame ``b`` into
frame ``a`` (4×4 homogeneous). The camera frame is the optical frame: x right, y down,
z forward. The map frame has z up.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import DataError

__all__ = ["CameraIntrinsics", "Detections", "Frame", "check_pose"]

FloatArray = NDArray[np.float64]


def _describe(array: Any) -> str:
    if isinstance(array, np.ndarray):
        return f"{array.shape} {array.dtype}"
    return type(array).__name__


def check_pose(T: Any, name: str = "T_map_cam") -> FloatArray:
    """Return ``T`` as a float64 4×4 rigid transform, or raise ``DataError`` saying why not."""
    if not isinstance(T, np.ndarray) or T.shape != (4, 4):
        raise DataError(f"{name}: expected a (4, 4) array, got {_describe(T)}")
    T = T.astype(np.float64, copy=False)
    pose: FloatArray = T
    if not np.all(np.isfinite(T)):
        raise DataError(f"{name}: pose contains NaN or infinite values; fix or drop that pose")
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], atol=1e-6):
        raise DataError(f"{name}: last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    R = T[:3, :3]
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-3) or np.linalg.det(R) < 0:
        raise DataError(f"{name}: rotation part is not a proper rotation (R·Rᵀ ≠ I or det < 0)")
    return pose


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics of a width × height image, focal lengths and centre in pixels.

    ``depth_scale`` converts raw integer depth to metres (TUM: 5000 units per metre).
    ``distortion`` holds OpenCV plumb-bob coefficients (k1, k2, p1, p2, k3) when known.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    depth_scale: float = 5000.0
    distortion: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.width <= 0 or self.height <= 0:
            raise DataError(f"camera: width and height must be positive, got {self.width}×{self.height}")
        values = (self.fx, self.fy, self.cx, self.cy, self.depth_scale)
        if not all(np.isfinite(v) for v in values) or self.fx <= 0 or self.fy <= 0:
            raise DataError(
                f"camera: fx, fy must be positive and all values finite, got "
                f"fx={self.fx} fy={self.fy} cx={self.cx} cy={self.cy} depth_scale={self.depth_scale}"
            )
        if self.depth_scale <= 0:
            raise DataError(f"camera: depth_scale must be positive, got {self.depth_scale}")

    @property
    def K(self) -> FloatArray:
        """The 3×3 camera matrix."""
        return np.array(
            [[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]], dtype=np.float64
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``camera.json`` form: width, height, fx, fy, cx, cy, depth_scale, distortion."""
        out: dict[str, Any] = {
            "width": self.width,
            "height": self.height,
            "fx": self.fx,
            "fy": self.fy,
            "cx": self.cx,
            "cy": self.cy,
            "depth_scale": self.depth_scale,
        }
        if self.distortion:
            out["distortion"] = list(self.distortion)
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "camera.json") -> CameraIntrinsics:
        """Build from the ``camera.json`` form; ``source`` names the file in errors."""
        missing = [k for k in ("width", "height", "fx", "fy", "cx", "cy") if k not in data]
        if missing:
            raise DataError(f"{source}: missing keys {missing}; expected width, height, fx, fy, cx, cy")
        width = int(_camera_number(data, "width", source, 1, 16384, integer=True))
        height = int(_camera_number(data, "height", source, 1, 16384, integer=True))
        distortion = data.get("distortion") or []
        if not isinstance(distortion, list) or len(distortion) > 14:
            raise DataError(f"{source}: 'distortion' is {str(distortion)[:40]!r}; expected a list of at most "
                            "14 OpenCV coefficients")
        return cls(
            width=width,
            height=height,
            fx=_camera_number(data, "fx", source, 1e-3, 1e6),
            fy=_camera_number(data, "fy", source, 1e-3, 1e6),
            cx=_camera_number(data, "cx", source, 0.0, float(width)),
            cy=_camera_number(data, "cy", source, 0.0, float(height)),
            depth_scale=_camera_number({"depth_scale": 5000.0, **data}, "depth_scale", source, 1e-3, 1e7),
            distortion=tuple(_camera_number({"k": v}, "k", f"{source}: distortion", -1e6, 1e6)
                             for v in distortion),
        )


def _camera_number(data: dict[str, Any], key: str, source: str, lo: float, hi: float, *,
                   integer: bool = False) -> float:
    """``data[key]`` as a JSON number in [lo, hi] (a whole one when ``integer``): a boolean,
    a text or a number out of range is a ``DataError`` naming the key and the range."""
    value = data[key]
    kind = "an integer" if integer else "a number"
    if isinstance(value, bool) or not isinstance(value, int | float):
        shown = str(value).lower() if isinstance(value, bool) else repr(str(value)[:40])
        raise DataError(f"{source}: '{key}' is {shown}; expected {kind} in [{lo:g}, {hi:g}]")
    if isinstance(value, int) and not -1e15 < value < 1e15:
        raise DataError(f"{source}: '{key}' is {str(value)[:20]}...; expected {kind} in [{lo:g}, {hi:g}]")
    number = float(value)
    if not (np.isfinite(number) and lo <= number <= hi) or (integer and number != int(number)):
        raise DataError(f"{source}: '{key}' is {value!r}; expected {kind} in [{lo:g}, {hi:g}]")
    return number


@dataclass(frozen=True)
class Detections:
    """2D detections of one image.

    ``xyxy``: (N, 4) float64 pixel boxes (x_min, y_min, x_max, y_max);
    ``class_names``: N strings (COCO names for COCO detectors); ``scores``: (N,) float64 in [0, 1].
    """

    xyxy: FloatArray
    class_names: tuple[str, ...]
    scores: FloatArray

    def __post_init__(self) -> None:
        xyxy = np.asarray(self.xyxy, dtype=np.float64)
        if xyxy.size == 0:
            xyxy = xyxy.reshape(0, 4)
        if xyxy.ndim != 2 or xyxy.shape[1] != 4:
            raise DataError(f"detections: xyxy expected (N, 4) float, got {_describe(xyxy)}")
        scores = np.asarray(self.scores, dtype=np.float64).reshape(-1)
        names = tuple(self.class_names)
        if not (len(names) == len(scores) == len(xyxy)):
            raise DataError(
                f"detections: {len(xyxy)} boxes, {len(names)} class names and {len(scores)} scores; "
                "expected the same count"
            )
        if not np.all(np.isfinite(xyxy)) or not np.all(np.isfinite(scores)):
            raise DataError("detections: boxes and scores must be finite")
        if np.any(xyxy[:, 2] < xyxy[:, 0]) or np.any(xyxy[:, 3] < xyxy[:, 1]):
            raise DataError("detections: boxes must satisfy x_max >= x_min and y_max >= y_min")
        object.__setattr__(self, "xyxy", xyxy)
        object.__setattr__(self, "scores", scores)
        object.__setattr__(self, "class_names", names)

    def __len__(self) -> int:
        return len(self.class_names)

    def subset(self, keep: NDArray[np.bool_]) -> Detections:
        """The detections where ``keep`` (N,) is true, in their order."""
        return Detections(self.xyxy[keep], tuple(n for n, k in zip(self.class_names, keep, strict=True) if k),
                          self.scores[keep])

    @classmethod
    def empty(cls) -> Detections:
        return cls(np.zeros((0, 4)), (), np.zeros(0))

    @classmethod
    def from_records(cls, records: Sequence[dict[str, Any]]) -> Detections:
        """From dicts ``{"xyxy": [x0, y0, x1, y1], "class": name, "score": s}``."""
        if not records:
            return cls.empty()
        return cls(
            np.array([r["xyxy"] for r in records], dtype=np.float64),
            tuple(str(r["class"]) for r in records),
            np.array([float(r.get("score", 1.0)) for r in records]),
        )

    def to_records(self) -> list[dict[str, Any]]:
        return [
            {"xyxy": [float(v) for v in box], "class": name, "score": float(score)}
            for box, name, score in zip(self.xyxy, self.class_names, self.scores, strict=True)
        ]


@dataclass(frozen=True)
class Frame:
    """One synchronised RGB-D frame with its pose.

    ``rgb``: (H, W, 3) uint8, RGB order. ``depth_m``: (H, W) float32 metres, 0 = invalid.
    ``T_map_cam``: (4, 4) float64, camera optical frame into the map frame.
    ``pose_id``: index of the pose in the log's trajectory (observations anchor to it).
    ``detections``: 2D detections recorded in the log, if any.
    ``source``: where the frame came from (file names or bag topic and index), for messages.
    """

    stamp_s: float
    rgb: NDArray[np.uint8]
    depth_m: NDArray[np.float32]
    camera: CameraIntrinsics
    T_map_cam: FloatArray
    pose_id: int
    detections: Detections | None = None
    source: str = ""
    extras: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        where = f"frame {self.pose_id}" + (f" ({self.source})" if self.source else "")
        if not np.isfinite(self.stamp_s):
            raise DataError(f"{where}: stamp_s must be finite, got {self.stamp_s}")
        rgb = self.rgb
        if not isinstance(rgb, np.ndarray) or rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
            raise DataError(f"{where}: rgb expected (H, W, 3) uint8, got {_describe(rgb)}")
        depth = self.depth_m
        if not isinstance(depth, np.ndarray) or depth.ndim != 2 or depth.dtype != np.float32:
            raise DataError(f"{where}: depth_m expected (H, W) float32, got {_describe(depth)}")
        if depth.shape != rgb.shape[:2]:
            raise DataError(
                f"{where}: depth {depth.shape} and rgb {rgb.shape[:2]} differ in size; "
                "register depth to the colour camera first"
            )
        if (self.camera.height, self.camera.width) != depth.shape:
            raise DataError(
                f"{where}: image is {depth.shape[1]}×{depth.shape[0]} but the camera intrinsics are "
                f"for {self.camera.width}×{self.camera.height}; pass the right camera.json or flags"
            )
        object.__setattr__(self, "T_map_cam", check_pose(self.T_map_cam, f"{where}: T_map_cam"))

    @property
    def height(self) -> int:
        return int(self.depth_m.shape[0])

    @property
    def width(self) -> int:
        return int(self.depth_m.shape[1])
