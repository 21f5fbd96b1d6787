"""Assemble live RGB-D frames: pair colour and depth by stamp, give each the pose at its stamp.

Messages arrive one by one from any thread (``add_*``); colour and depth are kept as raw CDR
with only their headers read, so a frame dropped for lack of time costs no decoding. A colour
image becomes a frame once a depth image lies within ``max_dt_s`` of it, the camera is known
and the poses (tf or an odometry/pose topic) cover its stamp. Ready frames wait in a bounded
slot (``capacity``); when perception falls behind, the oldest waiting frame is dropped and
counted, so what is perceived next is always the newest frame.
"""

from __future__ import annotations

import struct
import threading
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.ros_types import typestore
from hiper_cli.perceive.logs.tf import TfTree, pose_msg_to_matrix, transform_msg_to_matrix
from hiper_cli.perceive.logs.trajectory import Trajectory
from hiper_cli.types import CameraIntrinsics

__all__ = ["FrameSync", "RawImage", "ReadyFrame"]

WINDOW_S = 5.0  # unpaired images older than this (behind the newest stamp) are forgotten
POSE_WINDOW_S = 2.0  # poses kept for interpolation, behind the newest pose
FloatArray = NDArray[np.float64]


def header_of(raw: bytes) -> tuple[float, str]:
    """(stamp_s, frame_id) from CDR bytes of a message that starts with a ``std_msgs/Header``."""
    if len(raw) < 16:
        raise LogError(f"CDR message of {len(raw)} bytes is too short for a header")
    order = "<" if raw[1] == 1 else ">"
    sec, nsec, length = struct.unpack_from(order + "iII", raw, 4)
    frame_id = bytes(raw[16:16 + max(length - 1, 0)]).decode(errors="replace")
    return sec + nsec * 1e-9, frame_id.lstrip("/")


def _stamp(header: Any) -> float:
    return float(header.stamp.sec) + float(header.stamp.nanosec) * 1e-9


@dataclass(frozen=True)
class RawImage:
    """One undecoded image message: its stamp, frame, CDR bytes and when it was sent (wall s)."""

    stamp_s: float
    frame_id: str
    raw: bytes
    sent_s: float
    msgtype: str = "sensor_msgs/msg/Image"  # or sensor_msgs/msg/CompressedImage


@dataclass(frozen=True)
class ReadyFrame:
    """A colour/depth pair with its pose and camera, not yet decoded."""

    rgb: RawImage
    depth: RawImage
    T_map_cam: FloatArray
    camera: CameraIntrinsics


@dataclass
class FrameSync:
    """See the module docstring. ``pose_kind``: ``tf``, or ``odometry``/``pose`` for a pose topic."""

    max_dt_s: float
    capacity: int = 1
    pose_kind: str = "tf"
    map_frame: str = "map"
    camera_frame: str | None = None
    camera: CameraIntrinsics | None = None
    depth_scale: float = 1000.0
    assembled: int = 0
    dropped: int = 0
    unmatched: int = 0
    restarts: int = 0
    _newest_s: dict[str, float] = field(default_factory=dict)  # per stream: its newest stamp
    _tree_cache: TfTree | None = None
    _pose_newest_s: float = float("-inf")
    _rgb: list[RawImage] = field(default_factory=list)
    _depth: list[RawImage] = field(default_factory=list)
    _tf_static: dict[tuple[str, str], FloatArray] = field(default_factory=dict)
    _tf: deque[tuple[float, str, str, FloatArray]] = field(default_factory=deque)
    _poses: deque[tuple[float, FloatArray, str]] = field(default_factory=deque)
    _ready: deque[ReadyFrame] = field(default_factory=deque)
    _cond: threading.Condition = field(default_factory=threading.Condition)

    # --- input (any thread) -------------------------------------------------------------
    def add_image(self, role: str, raw: bytes, sent_s: float, msgtype: str = "sensor_msgs/msg/Image") -> None:
        stamp, frame_id = header_of(raw)
        with self._cond:
            self._check_clock(stamp, role)
            image = RawImage(stamp, frame_id, raw, sent_s, msgtype)
            (self._rgb if role == "rgb" else self._depth).append(image)
            self._advance()

    def add_camera_info(self, raw: bytes) -> None:
        if self.camera is not None:
            return
        from hiper_cli.perceive.logs.rosbag import camera_from_info

        msg = typestore(False).deserialize_cdr(raw, "sensor_msgs/msg/CameraInfo")
        camera = camera_from_info(msg, self.depth_scale, "live CameraInfo")
        with self._cond:
            self.camera = camera
            self._advance()

    def add_tf(self, raw: bytes, static: bool) -> None:
        msg = typestore(False).deserialize_cdr(raw, "tf2_msgs/msg/TFMessage")
        with self._cond:
            for tr in msg.transforms:
                T = transform_msg_to_matrix(tr.transform, "live /tf")
                parent, child = str(tr.header.frame_id).lstrip("/"), str(tr.child_frame_id).lstrip("/")
                if static:
                    self._tf_static[(parent, child)] = T
                else:
                    self._check_clock(_stamp(tr.header), "tf")
                    self._tf.append((_stamp(tr.header), parent, child, T))
            self._tree_cache = None
            self._advance()

    def add_pose(self, raw: bytes, msgtype: str) -> None:
        msg = typestore(False).deserialize_cdr(raw, msgtype)
        pose = msg.pose.pose if hasattr(msg.pose, "covariance") else msg.pose
        child = str(getattr(msg, "child_frame_id", "")).lstrip("/")
        with self._cond:
            self._check_clock(_stamp(msg.header), "pose")
            self._poses.append((_stamp(msg.header), pose_msg_to_matrix(pose, f"live {msgtype}"), child))
            self._advance()

    # --- output (the perceiving thread) -----------------------------------------------
    def take(self, timeout_s: float) -> ReadyFrame | None:
        """The oldest ready frame, waiting up to ``timeout_s``; ``None`` when none came."""
        with self._cond:
            if not self._ready:
                self._cond.wait(timeout_s)
            return self._ready.popleft() if self._ready else None

    def wake(self) -> None:
        """Release a ``take`` waiting now (to stop)."""
        with self._cond:
            self._cond.notify_all()

    # --- assembly (under the lock) ------------------------------------------------------
    def _check_clock(self, stamp_s: float, stream: str) -> None:
        """A stamp far behind its stream's newest: the publisher started over (a restarted replay,
        a robot rebooted with sim time); what was buffered belongs to the old clock."""
        newest = self._newest_s.get(stream, float("-inf"))
        if stamp_s < newest - WINDOW_S:
            self.unmatched += len(self._rgb)
            self._rgb, self._depth = [], []
            self._tf.clear()
            self._poses.clear()
            self._tree_cache = None
            self._pose_newest_s = float("-inf")
            self.restarts += 1
            self._newest_s = {}
        self._newest_s[stream] = max(self._newest_s.get(stream, float("-inf")), stamp_s)
        if stream in ("tf", "pose"):
            self._pose_newest_s = max(self._pose_newest_s, stamp_s)

    def _tree(self) -> TfTree:
        if self._tree_cache is not None:
            return self._tree_cache
        tree = self._tree_cache = TfTree()
        for (parent, child), T in self._tf_static.items():
            tree.add(parent, child, 0.0, T, True)
        for stamp, parent, child, T in self._tf:
            tree.add(parent, child, stamp, T, False)
        return tree

    def _pose_at(self, stamp_s: float, camera_frame: str) -> FloatArray | None:
        stamps = np.array([stamp_s])
        tree = self._tree()
        if self.pose_kind == "tf":
            if not tree.connected(self.map_frame, camera_frame):
                return None
            T, ok = tree.lookup(self.map_frame, camera_frame, stamps, self.max_dt_s, "live /tf")
            return T[0] if ok[0] else None
        rows = sorted(self._poses, key=lambda r: r[0])
        keep = [r for i, r in enumerate(rows) if i == 0 or r[0] > rows[i - 1][0]]
        if not keep:
            return None
        trajectory = Trajectory.from_matrices(np.array([r[0] for r in keep]), np.stack([r[1] for r in keep]),
                                              source="live poses")
        T, ok = trajectory.interpolate(stamps, max_extrapolation_s=self.max_dt_s)
        child = keep[0][2]
        if ok[0] and child and child != camera_frame and tree.connected(child, camera_frame):
            T_child_cam, ok = tree.lookup(child, camera_frame, stamps, self.max_dt_s, "live /tf")
            T = T @ T_child_cam
        return T[0] if ok[0] else None

    def _tf_static_only(self) -> bool:
        """Poses from /tf_static alone (a fixed camera): every stamp is covered."""
        return self.pose_kind == "tf" and not self._tf and bool(self._tf_static)

    def _advance(self) -> None:
        """Turn every colour image that can become a frame into one; forget what is too old."""
        if self.camera is None or not self._rgb:
            return
        self._rgb.sort(key=lambda m: m.stamp_s)
        emitted = False
        for rgb in list(self._rgb):
            if rgb.stamp_s > self._pose_newest_s + self.max_dt_s and not self._tf_static_only():
                break  # no pose covers this stamp yet (nor any later one)
            depth = min(self._depth, key=lambda m: abs(m.stamp_s - rgb.stamp_s), default=None)
            if depth is None or abs(depth.stamp_s - rgb.stamp_s) > self.max_dt_s:
                continue
            T = self._pose_at(rgb.stamp_s, self.camera_frame or rgb.frame_id)
            if T is None:
                continue
            older = [m for m in self._rgb if m.stamp_s < rgb.stamp_s]
            self.unmatched += len(older)
            self._rgb = [m for m in self._rgb if m.stamp_s > rgb.stamp_s]
            self._depth = [m for m in self._depth if m.stamp_s > depth.stamp_s]
            self.assembled += 1
            if len(self._ready) >= self.capacity:
                self._ready.popleft()
                self.dropped += 1
            self._ready.append(ReadyFrame(rgb, depth, T, self.camera))
            emitted = True
        horizon = max(self._newest_s.get("rgb", float("-inf")), self._newest_s.get("depth", float("-inf")))
        stale = [m for m in self._rgb if m.stamp_s < horizon - WINDOW_S]
        self.unmatched += len(stale)
        self._rgb = [m for m in self._rgb if m.stamp_s >= horizon - WINDOW_S]
        self._depth = [m for m in self._depth if m.stamp_s >= horizon - WINDOW_S]
        pose_horizon = self._pose_newest_s - POSE_WINDOW_S
        while self._tf and self._tf[0][0] < pose_horizon:
            self._tf.popleft()
            self._tree_cache = None
        while self._poses and self._poses[0][0] < pose_horizon:
            self._poses.popleft()
        if emitted:
            self._cond.notify_all()
