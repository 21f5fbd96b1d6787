"""Pose rows that a straight line between their neighbours gives: a row a frame stays (its
stamp, for ``kb check`` and the frame count), its matrix only where the motion bends.

A camera at 15-30 Hz moves smoothly: linear interpolation of the translation and of the
rotation (about one axis) between rows a second apart is within a centimetre and half a
degree of most rows in between (bookstore: 46 of 597 matrices needed). ``thin_session`` drops
the others' matrices (an empty text); ``pose_at`` gives a row's matrix back, interpolated
from the nearest rows of its session that have one.
"""

from __future__ import annotations

import json
from itertools import pairwise
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.logs.trajectory import rotation_about

__all__ = ["POSE_TOL_DEG", "POSE_TOL_M", "matrices", "pose_at", "thin_session"]

POSE_TOL_M = 0.01  # an interpolated pose lies this close to the one recorded ...
POSE_TOL_DEG = 0.5  # ... and turned this little from it
SPAN_ROWS = 40  # rows between two kept matrices at most (the check is quadratic in it)
F64 = NDArray[np.float64]


def _log_so3(R: F64) -> F64:
    """The rotation vector (axis times angle, radians) of rotation matrix ``R``."""
    cos = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    angle = float(np.arccos(cos))
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-9:
        return 0.5 * w
    if np.pi - angle < 1e-6:  # half a turn: the axis from the symmetric part
        axis = np.sqrt(np.clip((np.diag(R) + 1.0) / 2.0, 0.0, None))
        k = int(np.argmax(axis))
        axis = (R[:, k] + np.eye(3)[k]) / np.linalg.norm(R[:, k] + np.eye(3)[k])
        return np.asarray(axis * angle, dtype=np.float64)
    return np.asarray(w * (angle / (2.0 * np.sin(angle))), dtype=np.float64)


def interpolate(T0: F64, T1: F64, a: float) -> F64:
    """The pose a fraction ``a`` of the way from ``T0`` to ``T1`` (translation on a line,
    rotation about one axis)."""
    T = np.eye(4)
    T[:3, 3] = (1.0 - a) * T0[:3, 3] + a * T1[:3, 3]
    T[:3, :3] = T0[:3, :3] @ rotation_about(a * _log_so3(T0[:3, :3].T @ T1[:3, :3]))
    return T


def _turns_rad(R: F64) -> F64:
    """The angles (radians) of rotations ``R`` (M, 3, 3): the norms of their rotation vectors,
    as ``_log_so3`` gives them."""
    cos = np.clip((np.trace(R, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    w = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], axis=1)
    w_norm = np.linalg.norm(w, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        general = w_norm * (angle / (2.0 * np.sin(angle)))
    return np.asarray(np.where(angle < 1e-9, 0.5 * w_norm, np.where(np.pi - angle < 1e-6, angle, general)))


def _rotations_about(rotvecs: F64) -> F64:
    """(M, 3, 3) rotations of the rotation vectors ``rotvecs`` (M, 3) (``rotation_about``, batched)."""
    angle = np.linalg.norm(rotvecs, axis=1)
    small = angle < 1e-12
    k = rotvecs / np.where(small, 1.0, angle)[:, None]
    K = np.zeros((len(k), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    R = np.eye(3) + np.sin(angle)[:, None, None] * K + (1 - np.cos(angle))[:, None, None] * (K @ K)
    R[small] = np.eye(3)
    return np.asarray(R, dtype=np.float64)


def _line_holds(stamps: F64, poses: F64, i: int, end: int) -> bool:
    """Whether every row strictly between rows ``i`` and ``end`` lies within ``POSE_TOL_M`` and
    ``POSE_TOL_DEG`` of the pose ``interpolate`` gives it between those two (all rows at once)."""
    T0, T1 = poses[i], poses[end]
    a = (stamps[i + 1:end] - stamps[i]) / (stamps[end] - stamps[i])
    moved = (1.0 - a)[:, None] * T0[:3, 3] + a[:, None] * T1[:3, 3]
    turned = T0[:3, :3] @ _rotations_about(a[:, None] * _log_so3(T0[:3, :3].T @ T1[:3, :3]))
    seen = poses[i + 1:end]
    off_m = np.linalg.norm(moved - seen[:, :3, 3], axis=1)
    off_deg = np.degrees(_turns_rad(np.transpose(turned, (0, 2, 1)) @ seen[:, :3, :3]))
    return bool(np.all((off_m <= POSE_TOL_M) & (off_deg <= POSE_TOL_DEG)))


def _keep(stamps: list[float], poses: list[F64]) -> list[int]:
    """Indices of the rows whose matrices stay: greedily the longest stretch from each kept
    row whose rows in between the line to its end reproduces."""
    keep = [0]
    i = 0
    n = len(stamps)
    t, T = np.asarray(stamps, dtype=np.float64), np.asarray(poses, dtype=np.float64)
    while i < n - 1:
        j = i + 1
        while j + 1 < n and j + 1 - i <= SPAN_ROWS and _line_holds(t, T, i, j + 1):
            j += 1
        keep.append(j)
        i = j
    return keep


def thin_session(db: Any, session_id: int, before_s: float = float("inf")) -> int:
    """Drop the matrices of a session's pose rows stamped before ``before_s`` that their
    neighbours give (module docstring); a session thinned already is left as it is. Returns
    the number of matrices dropped."""
    rows = db.execute("SELECT pose_id, stamp_s, T_map_cam FROM poses WHERE session_id = ? AND stamp_s < ? "
                      "ORDER BY stamp_s, pose_id", (session_id, before_s)).fetchall()
    if len(rows) < 3 or any(not text for _, _, text in rows):
        return 0
    stamps = [float(s) for _, s, _ in rows]
    if any(b <= a for a, b in pairwise(stamps)):
        return 0  # repeated stamps: nothing to interpolate between
    poses = [np.asarray(json.loads(text), dtype=np.float64) for _, _, text in rows]
    kept = set(_keep(stamps, poses))
    dropped = [(session_id, int(rows[k][0])) for k in range(len(rows)) if k not in kept]
    db.executemany("UPDATE poses SET T_map_cam = '' WHERE session_id = ? AND pose_id = ?", dropped)
    return len(dropped)


def pose_at(db: Any, session_id: int, stamp_s: float, text: str) -> list[list[float]]:
    """The matrix of a pose row: its own, or interpolated between the nearest rows of its
    session before and after it that keep one."""
    if text:
        return list(json.loads(text))
    before = db.execute("SELECT stamp_s, T_map_cam FROM poses WHERE session_id = ? AND stamp_s < ? AND "
                        "T_map_cam != '' ORDER BY stamp_s DESC LIMIT 1", (session_id, stamp_s)).fetchone()
    after = db.execute("SELECT stamp_s, T_map_cam FROM poses WHERE session_id = ? AND stamp_s > ? AND "
                       "T_map_cam != '' ORDER BY stamp_s LIMIT 1", (session_id, stamp_s)).fetchone()
    if before is None or after is None:  # not written by thin_session, which keeps both ends
        found = before or after
        return [] if found is None else list(json.loads(found[1]))
    a = (stamp_s - float(before[0])) / (float(after[0]) - float(before[0]))
    T = interpolate(np.asarray(json.loads(before[1])), np.asarray(json.loads(after[1])), a)
    return [[round(float(v), 6) for v in row] for row in T.tolist()]


def matrices(stamps_s: list[float], texts: list[str]) -> F64:
    """(N, 4, 4) matrices of a session's pose rows (stamps and matrix texts, in stamp order),
    the empty ones interpolated between the nearest rows that keep one."""
    out = np.zeros((len(texts), 4, 4))
    known = [k for k, text in enumerate(texts) if text]
    for k in known:
        out[k] = np.asarray(json.loads(texts[k]), dtype=np.float64)
    for lo, hi in pairwise(known):
        for k in range(lo + 1, hi):
            a = (stamps_s[k] - stamps_s[lo]) / (stamps_s[hi] - stamps_s[lo])
            out[k] = interpolate(out[lo], out[hi], a)
    return out
