"""A small tf buffer: transforms between named frames over time, chains composed on lookup.

Edges come from ``/tf`` (time series, interpolated like a trajectory) and ``/tf_static``
(constant). ``lookup(parent, child, stamps)`` finds the chain of edges linking the two
frames (walking edges in either direction) and composes ``T_parent_child`` at each stamp.
Frame names lose a leading ``/`` (ROS 1 style).
"""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.trajectory import QUAT_NORM_TOLERANCE, Trajectory, quat_xyzw_to_matrix

__all__ = ["TfTree", "pose_msg_to_matrix", "transform_msg_to_matrix"]

FloatArray = NDArray[np.float64]


def _matrix(xyz: tuple[float, float, float], quat_xyzw: tuple[float, float, float, float], where: str
            ) -> FloatArray:
    values = np.array([*xyz, *quat_xyzw], dtype=np.float64)
    if not np.all(np.isfinite(values)):
        raise LogError(f"{where}: pose contains NaN or infinite values ({values.tolist()}); fix the "
                       "recording or pass --poses traj.txt")
    norm = float(np.linalg.norm(values[3:]))
    if abs(norm - 1.0) > QUAT_NORM_TOLERANCE:
        raise LogError(f"{where}: quaternion norm is {norm:.4f}; expected a unit quaternion")
    T = np.eye(4)
    T[:3, :3] = quat_xyzw_to_matrix(values[3:])
    T[:3, 3] = values[:3]
    return T


def transform_msg_to_matrix(transform: Any, where: str) -> FloatArray:
    """A ``geometry_msgs/Transform`` as a 4×4 matrix."""
    t, q = transform.translation, transform.rotation
    return _matrix((t.x, t.y, t.z), (q.x, q.y, q.z, q.w), where)


def pose_msg_to_matrix(pose: Any, where: str) -> FloatArray:
    """A ``geometry_msgs/Pose`` as a 4×4 matrix."""
    p, q = pose.position, pose.orientation
    return _matrix((p.x, p.y, p.z), (q.x, q.y, q.z, q.w), where)


class TfTree:
    """Transforms ``T_parent_child`` between frames, static or over time."""

    def __init__(self) -> None:
        self._static: dict[tuple[str, str], FloatArray] = {}
        self._dynamic: dict[tuple[str, str], list[tuple[float, FloatArray]]] = {}
        self._trajectories: dict[tuple[str, str], Trajectory] = {}

    def add(self, parent: str, child: str, stamp_s: float, T_parent_child: FloatArray, static: bool) -> None:
        key = (parent.lstrip("/"), child.lstrip("/"))
        if static:
            self._static[key] = T_parent_child
        else:
            self._dynamic.setdefault(key, []).append((stamp_s, T_parent_child))
            self._trajectories.pop(key, None)

    def frames(self) -> list[str]:
        return sorted({f for key in (*self._static, *self._dynamic) for f in key})

    def _path(self, parent: str, child: str) -> list[tuple[str, str, bool]] | None:
        """Edges (parent, child, forward) from ``parent`` to ``child``; None when unconnected."""
        neighbours: dict[str, list[tuple[str, tuple[str, str, bool]]]] = {}
        for a, b in (*self._static, *self._dynamic):
            neighbours.setdefault(a, []).append((b, (a, b, True)))
            neighbours.setdefault(b, []).append((a, (a, b, False)))
        previous: dict[str, tuple[str, tuple[str, str, bool]] | None] = {parent: None}
        queue = deque([parent])
        while queue:
            frame = queue.popleft()
            if frame == child:
                break
            for nxt, edge in neighbours.get(frame, []):
                if nxt not in previous:
                    previous[nxt] = (frame, edge)
                    queue.append(nxt)
        if child not in previous:
            return None
        edges: list[tuple[str, str, bool]] = []
        node = child
        while (step := previous[node]) is not None:
            node, edge = step
            edges.append(edge)
        return edges[::-1]

    def connected(self, parent: str, child: str) -> bool:
        return parent == child or self._path(parent, child) is not None

    def _trajectory(self, key: tuple[str, str], where: str) -> Trajectory:
        if key not in self._trajectories:
            rows = sorted(self._dynamic[key], key=lambda r: r[0])
            keep = [0] + [i for i in range(1, len(rows)) if rows[i][0] > rows[i - 1][0]]
            self._trajectories[key] = Trajectory.from_matrices(
                np.array([rows[i][0] for i in keep]), np.stack([rows[i][1] for i in keep]),
                source=f"{where} {key[0]} -> {key[1]}",
            )
        return self._trajectories[key]

    def lookup(self, parent: str, child: str, stamps_s: FloatArray, max_dt_s: float, where: str
               ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """(M, 4, 4) ``T_parent_child`` at ``stamps_s`` and the mask of stamps every edge covers."""
        parent, child = parent.lstrip("/"), child.lstrip("/")
        stamps = np.asarray(stamps_s, dtype=np.float64).reshape(-1)
        T = np.tile(np.eye(4), (len(stamps), 1, 1))
        valid = np.ones(len(stamps), dtype=bool)
        if parent == child:
            return T, valid
        path = self._path(parent, child)
        if path is None:
            seen = ", ".join(self.frames()) or "none"
            raise LogError(f"{where}: no tf chain from '{parent}' to '{child}' (frames seen: {seen}); pass "
                           "--map-frame and --camera-frame, or --poses traj.txt")
        for a, b, forward in path:
            if (a, b) in self._static:
                T_edge = np.broadcast_to(self._static[(a, b)], T.shape)
            else:
                T_edge, ok = self._trajectory((a, b), where).interpolate(stamps, max_extrapolation_s=max_dt_s)
                valid &= ok
            T = T @ (T_edge if forward else np.linalg.inv(T_edge))
        return T, valid
