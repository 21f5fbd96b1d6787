"""TUM trajectories: read, validate, write and interpolate ``T_map_cam`` over time.

A TUM trajectory file holds one pose per line, ``stamp tx ty tz qx qy qz qw``: the
camera's position in the map (metres) and its orientation as a unit quaternion (x, y, z, w);
lines starting with ``#`` are comments. Interpolation is linear in position and spherical
(slerp) in orientation.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError

__all__ = [
    "Trajectory",
    "matrix_to_quat_xyzw",
    "quat_xyzw_to_matrix",
    "read_tum_trajectory",
    "rotation_about",
    "rotation_angle_rad",
    "rotation_vector",
    "write_tum_trajectory",
]

FloatArray = NDArray[np.float64]

# A quaternion whose norm is further than this from 1 is a broken file, not rounding.
QUAT_NORM_TOLERANCE = 1e-2
MAX_POSITION_M = 1e6  # 1000 km from the map origin: a robot log never goes there; a pose that does is damage
MAX_STAMP_S = 1e11  # Unix time and log time both fit


def rotation_about(rotvec: FloatArray) -> FloatArray:
    """3×3 rotation of the rotation vector ``rotvec`` (axis × angle in radians; Rodrigues)."""
    angle = float(np.linalg.norm(rotvec))
    if angle < 1e-12:
        return np.eye(3)
    k = rotvec / angle
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    R: FloatArray = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * (K @ K)
    return R


def rotation_angle_rad(R: FloatArray) -> float:
    """The angle (radians) of the 3×3 rotation ``R``."""
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)))


def rotation_vector(R: FloatArray) -> FloatArray:
    """The rotation vector of ``R`` (axis × angle; the inverse of ``rotation_about``), for
    angles well under 180°."""
    angle = rotation_angle_rad(R)
    if angle < 1e-12:
        return np.zeros(3)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    out: FloatArray = w * (angle / (2.0 * np.sin(angle)))
    return out


def quat_xyzw_to_matrix(quat_xyzw: FloatArray) -> FloatArray:
    """(..., 4) unit quaternions (x, y, z, w) to (..., 3, 3) rotation matrices."""
    q = np.asarray(quat_xyzw, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    R = np.empty((*q.shape[:-1], 3, 3), dtype=np.float64)
    R[..., 0, 0] = 1 - 2 * (y * y + z * z)
    R[..., 0, 1] = 2 * (x * y - z * w)
    R[..., 0, 2] = 2 * (x * z + y * w)
    R[..., 1, 0] = 2 * (x * y + z * w)
    R[..., 1, 1] = 1 - 2 * (x * x + z * z)
    R[..., 1, 2] = 2 * (y * z - x * w)
    R[..., 2, 0] = 2 * (x * z - y * w)
    R[..., 2, 1] = 2 * (y * z + x * w)
    R[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def matrix_to_quat_xyzw(R: FloatArray) -> FloatArray:
    """A 3×3 rotation matrix to a unit quaternion (x, y, z, w) with w >= 0."""
    R = np.asarray(R, dtype=np.float64)
    trace = R[0, 0] + R[1, 1] + R[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = [(R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * np.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s, (R[2, 1] - R[1, 2]) / s]
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * np.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s, (R[0, 2] - R[2, 0]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s, (R[1, 0] - R[0, 1]) / s]
    quat = np.array(q, dtype=np.float64)
    quat /= np.linalg.norm(quat)
    return -quat if quat[3] < 0 else quat


@dataclass(frozen=True)
class Trajectory:
    """Poses ``T_map_cam`` at strictly increasing stamps.

    ``stamps_s``: (N,) float64; ``positions_m``: (N, 3) float64 (camera origin in the map);
    ``quats_xyzw``: (N, 4) float64 unit quaternions. ``source`` names the file or topic.
    """

    stamps_s: FloatArray
    positions_m: FloatArray
    quats_xyzw: FloatArray
    source: str = ""

    def __post_init__(self) -> None:
        stamps = np.asarray(self.stamps_s, dtype=np.float64).reshape(-1)
        pos = np.asarray(self.positions_m, dtype=np.float64).reshape(-1, 3)
        quats = np.asarray(self.quats_xyzw, dtype=np.float64).reshape(-1, 4)
        where = self.source or "trajectory"
        if not (len(stamps) == len(pos) == len(quats)):
            raise LogError(
                f"{where}: {len(stamps)} stamps, {len(pos)} positions, {len(quats)} quaternions; "
                "expected the same count"
            )
        if len(stamps) == 0:
            raise LogError(f"{where}: no poses; expected lines 'stamp tx ty tz qx qy qz qw'")
        bad = ~(np.isfinite(stamps) & np.all(np.isfinite(pos), axis=1) & np.all(np.isfinite(quats), axis=1))
        if np.any(bad):
            i = int(np.argmax(bad))
            raise LogError(f"{where}: pose {i} (stamp {stamps[i]}) contains NaN or infinite values; "
                           "fix or drop that pose")
        far = (np.abs(stamps) > MAX_STAMP_S) | np.any(np.abs(pos) > MAX_POSITION_M, axis=1)
        if np.any(far):
            i = int(np.argmax(far))
            raise LogError(f"{where}: pose {i} (stamp {stamps[i]:g}) lies at {pos[i].tolist()} m; expected "
                           f"positions within {MAX_POSITION_M:g} m and stamps within {MAX_STAMP_S:g} s")
        norms = np.linalg.norm(quats, axis=1)
        off = np.abs(norms - 1.0) > QUAT_NORM_TOLERANCE
        if np.any(off):
            i = int(np.argmax(off))
            raise LogError(f"{where}: pose {i} (stamp {stamps[i]}) has a quaternion of norm "
                           f"{norms[i]:.4f}; expected a unit quaternion (qx qy qz qw)")
        steps = np.diff(stamps)
        if np.any(steps <= 0):
            i = int(np.argmax(steps <= 0)) + 1
            raise LogError(f"{where}: pose {i} stamp {stamps[i]} does not increase after {stamps[i - 1]}; "
                           "sort the poses by time and drop duplicates")
        object.__setattr__(self, "stamps_s", stamps)
        object.__setattr__(self, "positions_m", pos)
        object.__setattr__(self, "quats_xyzw", quats / norms[:, None])

    def __len__(self) -> int:
        return len(self.stamps_s)

    @classmethod
    def from_matrices(cls, stamps_s: FloatArray, T_map_cam: FloatArray, source: str = "") -> Trajectory:
        """From (N,) stamps and (N, 4, 4) poses."""
        T = np.asarray(T_map_cam, dtype=np.float64).reshape(-1, 4, 4)
        if not np.all(np.isfinite(T)):
            i = int(np.argmax(~np.all(np.isfinite(T.reshape(len(T), -1)), axis=1)))
            raise LogError(f"{source or 'trajectory'}: pose {i} contains NaN or infinite values; "
                           "fix or drop that pose")
        quats = np.array([matrix_to_quat_xyzw(m[:3, :3]) for m in T]).reshape(-1, 4)
        return cls(np.asarray(stamps_s, dtype=np.float64), T[:, :3, 3], quats, source)

    def matrices(self) -> FloatArray:
        """(N, 4, 4) ``T_map_cam`` at ``stamps_s``."""
        return _compose(self.positions_m, self.quats_xyzw)

    def interpolate(self, stamps_s: FloatArray, max_extrapolation_s: float = 0.0
                    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Poses at ``stamps_s``: (M, 4, 4) ``T_map_cam`` and an (M,) mask of stamps covered.

        A stamp is covered when it lies within the trajectory's time span, widened by
        ``max_extrapolation_s`` on both ends (there the end pose is held). Uncovered stamps
        get the identity.
        """
        query = np.asarray(stamps_s, dtype=np.float64).reshape(-1)
        t = self.stamps_s
        valid = (query >= t[0] - max_extrapolation_s) & (query <= t[-1] + max_extrapolation_s)
        clamped = np.clip(query, t[0], t[-1])
        hi = np.clip(np.searchsorted(t, clamped, side="left"), 1, max(len(t) - 1, 1))
        lo = hi - 1
        if len(t) == 1:
            lo = hi = np.zeros_like(hi)
            alpha = np.zeros_like(clamped)
        else:
            alpha = (clamped - t[lo]) / (t[hi] - t[lo])
        pos = self.positions_m[lo] + alpha[:, None] * (self.positions_m[hi] - self.positions_m[lo])
        quats = _slerp(self.quats_xyzw[lo], self.quats_xyzw[hi], alpha)
        T = _compose(pos, quats)
        T[~valid] = np.eye(4)
        return T, valid


def _compose(positions_m: FloatArray, quats_xyzw: FloatArray) -> FloatArray:
    T = np.tile(np.eye(4), (len(positions_m), 1, 1))
    T[:, :3, :3] = quat_xyzw_to_matrix(quats_xyzw)
    T[:, :3, 3] = positions_m
    return T


def _slerp(q0: FloatArray, q1: FloatArray, alpha: FloatArray) -> FloatArray:
    dot = np.sum(q0 * q1, axis=1)
    q1 = np.where(dot[:, None] < 0, -q1, q1)
    dot = np.abs(dot)
    out = np.empty_like(q0)
    near = dot > 0.9995
    a = alpha[:, None]
    out[near] = q0[near] + a[near] * (q1[near] - q0[near])
    far = ~near
    if np.any(far):
        theta = np.arccos(np.clip(dot[far], -1.0, 1.0))[:, None]
        sin = np.sin(theta)
        out[far] = (np.sin((1 - a[far]) * theta) * q0[far] + np.sin(a[far] * theta) * q1[far]) / sin
    unit: FloatArray = out / np.linalg.norm(out, axis=1, keepdims=True)
    return unit


def read_tum_trajectory(path: str | Path) -> Trajectory:
    """Read a TUM trajectory file; errors name the file and line."""
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError as err:
        raise LogError(f"{path}: trajectory file not found; pass an existing TUM trajectory") from err
    except (OSError, UnicodeDecodeError) as err:
        raise LogError(f"{path}: cannot read the trajectory ({err}); expected a TUM text file") from err
    rows: list[list[float]] = []
    lines: list[int] = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.replace(",", " ").split()
        if len(parts) != 8:
            raise LogError(f"{path}:{number}: expected 8 values 'stamp tx ty tz qx qy qz qw', "
                           f"got {len(parts)}")
        try:
            values = [float(p) for p in parts]
        except ValueError as err:
            raise LogError(f"{path}:{number}: not a number ({err}); expected 'stamp tx ty tz qx qy qz qw'"
                           ) from err
        if not all(np.isfinite(values)):
            raise LogError(f"{path}:{number}: pose contains NaN or infinite values; fix or drop that line")
        if abs(values[0]) > MAX_STAMP_S or max(abs(v) for v in values[1:4]) > MAX_POSITION_M:
            raise LogError(f"{path}:{number}: pose at {values[1:4]} m, stamp {values[0]:g} s; expected "
                           f"positions within {MAX_POSITION_M:g} m and stamps within {MAX_STAMP_S:g} s")
        norm = float(np.linalg.norm(values[4:]))
        if abs(norm - 1.0) > QUAT_NORM_TOLERANCE:
            raise LogError(f"{path}:{number}: quaternion norm is {norm:.4f}; expected a unit quaternion "
                           "(qx qy qz qw)")
        if rows and values[0] <= rows[-1][0]:
            raise LogError(f"{path}:{number}: stamp {parts[0]} does not increase after the previous line; "
                           "sort the poses by time and drop duplicates")
        rows.append(values)
        lines.append(number)
    if not rows:
        raise LogError(f"{path}: no poses; expected lines 'stamp tx ty tz qx qy qz qw'")
    data = np.array(rows, dtype=np.float64)
    return Trajectory(data[:, 0], data[:, 1:4], data[:, 4:8], source=str(path))


def write_tum_trajectory(path: str | Path, trajectory: Trajectory) -> None:
    """Write a TUM trajectory file (stamps with microsecond resolution)."""
    lines = ["# timestamp tx ty tz qx qy qz qw"]
    for stamp, pos, quat in zip(trajectory.stamps_s, trajectory.positions_m, trajectory.quats_xyzw,
                                strict=True):
        lines.append(f"{stamp:.6f} " + " ".join(f"{v:.9f}" for v in (*pos, *quat)))
    Path(path).write_text("\n".join(lines) + "\n")
