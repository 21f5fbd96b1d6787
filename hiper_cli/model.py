"""The knowledge entities of the HIPer model: observations, instances, analyses, environments.

Observations (o) are anchored to the sensor frame and the pose id they were seen from, so an
optimised trajectory can recompute every instance. Instances (i) live in the map frame and keep
the uuids of the observations they were formed from. Analyses (a) hold learned features.

``World`` (the live instances the stages read) and ``FrameResult`` (what a stage made of one
frame) are shared by the recognition stages and the knowledge base.

High-level attributes (uuid, frame, last update, class, box) are plain fields; low-level data
(plane model and contour, point blobs, image boxes, trajectories, fused points) live in ``data``,
a JSON-serialisable dict. ``to_dict``/``from_dict`` give the document form stored in the
knowledge base. Units: metres, seconds, radians.
"""

from __future__ import annotations

import math
import os
import time
import uuid as _uuid
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError, DataError

__all__ = [
    "LAYERS",
    "ROW_POSITION",
    "ROW_STAMP",
    "ROW_STATE",
    "ROW_VELOCITY",
    "TRAJECTORY_COLUMNS",
    "Analysis",
    "Box3D",
    "Environment",
    "FrameResult",
    "Instance",
    "Layer",
    "Observation",
    "State",
    "TrackTrajectory",
    "World",
    "json_default",
    "new_uuid",
    "point_bounds",
]

Layer = Literal["environment", "background", "foreground", "map"]
LAYERS: tuple[str, ...] = ("environment", "background", "foreground", "map")
State = Literal["static", "dynamic"]

# A tracked instance's trajectory (``Instance.data["trajectory"]``): one row per update, map frame.
TRAJECTORY_COLUMNS = ("stamp_s", "x_map_m", "y_map_m", "z_map_m", "vx_map_mps", "vy_map_mps", "vz_map_mps")
ROW_STAMP = 0  # row[ROW_STAMP]: seconds
ROW_POSITION = slice(1, 4)  # row[ROW_POSITION]: x, y, z / m
ROW_VELOCITY = slice(4, 7)  # row[ROW_VELOCITY]: vx, vy, vz / (m/s)
ROW_STATE = slice(1, 7)  # position and velocity, the Kalman state


def new_uuid() -> str:
    """A time-ordered random UUID (RFC 9562 version 7: 48-bit Unix milliseconds, then 74
    random bits). Entities created close in time get neighbouring keys, so the knowledge base's
    uuid indexes grow at their end instead of touching a random page per insert (measured in
    docs/kb.md); still unique and opaque to every reader."""
    ms = time.time_ns() // 1_000_000
    rand = int.from_bytes(os.urandom(10), "big")
    value = (ms & 0xFFFF_FFFF_FFFF) << 80 | 0x7 << 76 | (rand >> 62 & 0xFFF) << 64 | 0b10 << 62
    return str(_uuid.UUID(int=value | rand & ((1 << 62) - 1)))


def json_default(value: Any) -> Any:
    """``default=`` for JSON encoders: arrays as lists, model objects as their ``to_dict()``."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if hasattr(value, "to_dict"):
        return value.to_dict()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def point_bounds(points: NDArray[Any]) -> tuple[NDArray[Any], NDArray[Any]]:
    """The per-column (min, max) of (N, D) points, each (D,), in their dtype.

    Reduces a transposed copy: numpy's axis-0 reductions over a few interleaved columns are
    slow (3000 points: 260 µs for both against 16 µs this way), and blobs are bounded many times
    a frame. The values are exactly those of ``min(axis=0)``/``max(axis=0)``.
    """
    columns = np.asarray(points).T.copy()
    return columns.min(axis=1), columns.max(axis=1)


# The corners of the unit cube [-1, 1]³, in ``Box3D.corners`` order.
CORNER_SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)


@dataclass(frozen=True)
class TrackTrajectory:
    """A tracked instance's trajectory with named columns (``TRAJECTORY_COLUMNS``).

    ``rows``: (N, 7) float64, time order. The stored form is ``Instance.data["trajectory"]``,
    a list of 7-number rows whose columns ``ROW_STAMP``, ``ROW_POSITION``, ``ROW_VELOCITY``
    name; tracking, the knowledge base and the evaluation read both through these names.
    """

    rows: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.rows.ndim != 2 or self.rows.shape[1] != len(TRAJECTORY_COLUMNS):
            raise DataError(f"trajectory: expected (N, {len(TRAJECTORY_COLUMNS)}) rows "
                            f"{list(TRAJECTORY_COLUMNS)}, got shape {self.rows.shape}")

    @classmethod
    def from_rows(cls, rows: Any) -> TrackTrajectory:
        """From the stored list of rows (or an array); no rows gives an empty trajectory."""
        array = np.asarray(rows if rows is not None else [], dtype=np.float64)
        return cls(array.reshape(-1, len(TRAJECTORY_COLUMNS)))

    def __len__(self) -> int:
        return int(self.rows.shape[0])

    @property
    def stamps_s(self) -> NDArray[np.float64]:
        return self.rows[:, ROW_STAMP]

    @property
    def position_map_m(self) -> NDArray[np.float64]:
        return self.rows[:, ROW_POSITION]

    @property
    def velocity_map_mps(self) -> NDArray[np.float64]:
        return self.rows[:, ROW_VELOCITY]

    @property
    def speed_xy_mps(self) -> NDArray[np.float64]:
        """Horizontal speed per row."""
        velocity = self.rows[:, ROW_VELOCITY]
        speed: NDArray[np.float64] = np.hypot(velocity[:, 0], velocity[:, 1])
        return speed


@dataclass(frozen=True)
class Box3D:
    """An oriented box: centre (3,) and full extent (3,) in metres, axes ``R`` (3×3) in its frame.

    The columns of ``R`` are the box axes expressed in the frame the box is given in.
    """

    center_m: NDArray[np.float64]
    extent_m: NDArray[np.float64]
    R: NDArray[np.float64] = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        c = np.asarray(self.center_m, dtype=np.float64).reshape(-1)
        e = np.asarray(self.extent_m, dtype=np.float64).reshape(-1)
        R = np.asarray(self.R, dtype=np.float64)
        if c.shape != (3,) or e.shape != (3,) or R.shape != (3, 3):
            raise DataError(
                f"box: expected centre (3,), extent (3,), R (3, 3); got {c.shape}, {e.shape}, {R.shape}"
            )
        # Boxes are made per observation and per frame: one sum first (NaN or inf when a value
        # is, or on overflow), the element-wise test only then.
        total = float(c.sum() + e.sum() + R.sum())
        finite = math.isfinite(total) or all(np.isfinite(a).all() for a in (c, e, R))
        if not finite:
            raise DataError("box: centre, extent and R must be finite")
        if e.min() < 0:
            raise DataError(f"box: extent must be non-negative, got {e.tolist()}")
        object.__setattr__(self, "center_m", c)
        object.__setattr__(self, "extent_m", e)
        object.__setattr__(self, "R", R)

    @classmethod
    def from_points(cls, points_m: NDArray[np.float64]) -> Box3D:
        """The axis-aligned box around (N, 3) points."""
        pts = np.asarray(points_m, dtype=np.float64).reshape(-1, 3)
        if len(pts) == 0:
            raise DataError("box: cannot bound an empty point set")
        lo, hi = point_bounds(pts)
        return cls((lo + hi) / 2.0, hi - lo)

    def corners(self) -> NDArray[np.float64]:
        """The 8 corners (8, 3) in the box's frame."""
        return self.center_m + (CORNER_SIGNS * (self.extent_m / 2.0)) @ self.R.T

    def transformed(self, T_b_a: NDArray[np.float64]) -> Box3D:
        """This box (given in frame a) expressed in frame b."""
        return Box3D(T_b_a[:3, :3] @ self.center_m + T_b_a[:3, 3], self.extent_m, T_b_a[:3, :3] @ self.R)

    def aabb(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(min, max) corners of the axis-aligned box that contains this box."""
        half = np.abs(self.R) @ (self.extent_m / 2.0)
        return self.center_m - half, self.center_m + half

    @property
    def volume_m3(self) -> float:
        return float(np.prod(self.extent_m))

    def to_dict(self) -> dict[str, Any]:
        return {
            "center_m": self.center_m.tolist(),
            "extent_m": self.extent_m.tolist(),
            "R": self.R.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Box3D:
        return cls(np.array(d["center_m"]), np.array(d["extent_m"]), np.array(d.get("R", np.eye(3))))


@dataclass
class Observation:
    """One perception of something at one instant, in the sensor frame of pose ``pose_id``.

    ``box`` is in ``frame_id`` (the camera optical frame for both layers).
    ``data`` (low-level): background: ``plane_cam`` [a, b, c, d] and ``contour_cam`` (K, 3);
    foreground: ``points_cam`` (subsampled (K, 3)), ``image_box_xyxy`` (pixels), ``detection``.
    """

    layer: Literal["background", "foreground"]
    class_name: str
    confidence: float
    stamp_s: float
    pose_id: int
    box: Box3D
    frame_id: str = "camera"
    instance_uuid: str | None = None
    data: dict[str, Any] = field(default_factory=dict)
    uuid: str = field(default_factory=new_uuid)

    def to_dict(self) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "type": "observation",
            "layer": self.layer,
            "class": self.class_name,
            "confidence": float(self.confidence),
            "stamp_s": float(self.stamp_s),
            "pose_id": int(self.pose_id),
            "frame_id": self.frame_id,
            "box": self.box.to_dict(),
            "instance_uuid": self.instance_uuid,
            "data": self.data,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Observation:
        return cls(
            layer=d["layer"],
            class_name=d["class"],
            confidence=float(d["confidence"]),
            stamp_s=float(d["stamp_s"]),
            pose_id=int(d["pose_id"]),
            box=Box3D.from_dict(d["box"]),
            frame_id=d.get("frame_id", "camera"),
            instance_uuid=d.get("instance_uuid"),
            data=d.get("data", {}),
            uuid=d["uuid"],
        )


@dataclass
class Instance:
    """A thing in the scene, aggregated from observations, in the map frame.

    ``data`` (low-level): background: ``plane_map`` [a, b, c, d], ``contour_map`` (K, 3);
    foreground: ``trajectory`` rows [stamp_s, x, y, z, vx, vy, vz] in the map frame.
    """

    layer: Literal["background", "foreground"]
    class_name: str
    box: Box3D
    first_seen_s: float
    last_seen_s: float
    state: State = "static"
    confidence: float = 1.0
    observation_uuids: list[str] = field(default_factory=list)
    frame_id: str = "map"
    data: dict[str, Any] = field(default_factory=dict)
    uuid: str = field(default_factory=new_uuid)

    def to_dict(self) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "type": "instance",
            "layer": self.layer,
            "class": self.class_name,
            "box": self.box.to_dict(),
            "first_seen_s": float(self.first_seen_s),
            "last_seen_s": float(self.last_seen_s),
            "state": self.state,
            "confidence": float(self.confidence),
            "observation_uuids": list(self.observation_uuids),
            "frame_id": self.frame_id,
            "data": self.data,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Instance:
        return cls(
            layer=d["layer"],
            class_name=d["class"],
            box=Box3D.from_dict(d["box"]),
            first_seen_s=float(d["first_seen_s"]),
            last_seen_s=float(d["last_seen_s"]),
            state=d.get("state", "static"),
            confidence=float(d.get("confidence", 1.0)),
            observation_uuids=list(d.get("observation_uuids", [])),
            frame_id=d.get("frame_id", "map"),
            data=d.get("data", {}),
            uuid=d["uuid"],
        )


@dataclass
class Analysis:
    """A learned feature: ``kind`` is ``ods``, ``size``, ``altitude``, ``heatmap``, ...

    ``values`` holds the numbers (for ``ods``: mean_mps, cl_mps, cu_mps, ratio, sigma_mps).
    """

    kind: str
    class_name: str
    t_start_s: float
    t_end_s: float
    values: dict[str, Any]
    created_s: float
    uuid: str = field(default_factory=new_uuid)

    def to_dict(self) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "type": "analysis",
            "kind": self.kind,
            "class": self.class_name,
            "t_start_s": self.t_start_s,
            "t_end_s": self.t_end_s,
            "values": self.values,
            "created_s": self.created_s,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Analysis:
        return cls(
            kind=d["kind"],
            class_name=d["class"],
            t_start_s=float(d["t_start_s"]),
            t_end_s=float(d["t_end_s"]),
            values=d["values"],
            created_s=float(d["created_s"]),
            uuid=d["uuid"],
        )


@dataclass
class Environment:
    """A place the robot knows; several sessions (logs) accumulate into one environment.

    ``data`` may hold the map (occupancy grid: ``resolution_m``, ``origin_m``, ``image``) and
    the robot trajectory rows [stamp_s, x, y, z, qx, qy, qz, qw].
    """

    name: str
    data: dict[str, Any] = field(default_factory=dict)
    uuid: str = field(default_factory=new_uuid)

    def to_dict(self) -> dict[str, Any]:
        return {"uuid": self.uuid, "type": "environment", "name": self.name, "data": self.data}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Environment:
        return cls(name=d["name"], data=d.get("data", {}), uuid=d["uuid"])


@dataclass
class World:
    """What the stages may read: live instances by uuid, per layer, and learned analyses."""

    background: dict[str, Instance] = field(default_factory=dict)
    foreground: dict[str, Instance] = field(default_factory=dict)
    analyses: list[Analysis] = field(default_factory=list)

    def layer(self, name: str) -> dict[str, Instance]:
        if name == "background":
            return self.background
        if name == "foreground":
            return self.foreground
        raise ConfigError(f"unknown layer {name!r}; expected 'background' or 'foreground'")

    def analysis(self, kind: str, class_name: str) -> Analysis | None:
        """The newest analysis of ``kind`` for ``class_name``, if any."""
        found = [a for a in self.analyses if a.kind == kind and a.class_name == class_name]
        return max(found, key=lambda a: a.created_s) if found else None

    def apply(self, result: FrameResult) -> None:
        for inst in result.instances:
            self.layer(inst.layer)[inst.uuid] = inst
        for uuid in result.deleted_instances:
            self.background.pop(uuid, None)
            self.foreground.pop(uuid, None)


@dataclass
class FrameResult:
    """What one stage made of one frame.

    ``instances`` are created or updated (upserted by uuid); ``deleted_instances`` are uuids
    merged away. ``timings_s`` holds named durations (e.g. ``background_s``) for reports;
    ``counts`` named counts of what the stage did (e.g. ``found_again``), summed per run.
    ``skipped`` is a reason when the stage did not process the frame (e.g. not a keyframe).
    """

    observations: list[Observation] = field(default_factory=list)
    instances: list[Instance] = field(default_factory=list)
    deleted_instances: list[str] = field(default_factory=list)
    timings_s: dict[str, float] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    skipped: str | None = None

    def extend(self, other: FrameResult) -> None:
        self.observations.extend(other.observations)
        self.instances.extend(other.instances)
        self.deleted_instances.extend(other.deleted_instances)
        self.timings_s.update(other.timings_s)
        for name, n in other.counts.items():
            self.counts[name] = self.counts.get(name, 0) + n
