"""Aligning a session to the place: the rigid transform from a log's frame into the map frame,
found from the static background.

A robot starts each session in a new odometry frame, so a second log of a place has poses in
another frame than the map its knowledge base holds. The background (floor, walls, furniture)
is the same, so its point clouds register: FPFH features matched by RANSAC give a coarse
transform (global: any offset, any turn), point-to-plane ICP refines it. ``fitness`` is the
share of the log's points within ``ICP_FINE_M`` of the map after alignment; a low one means
the log shows another place (or too little of this one) and is refused by the caller.

``BackgroundCloud`` gathers a voxel cloud (centroid per voxel) from frames: the map's, to
store, and a log's, to align.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.types import Frame

__all__ = ["BackgroundCloud", "Registration", "register"]

FloatArray = NDArray[np.float64]

VOXEL_M = 0.08  # the stored cloud: one centroid per voxel
PIXEL_STRIDE = 6  # every sixth pixel of every sixth row
MAX_DEPTH_M = 4.5
FEATURE_VOXEL_M = 0.15  # global registration works on a coarser cloud
ICP_COARSE_M = 0.3
ICP_FINE_M = 0.05


_KEY_BITS = 21  # voxel indices within +-2**20 (80 km at 8 cm) pack into one int64


def _unique_rows(keys: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.intp]]:
    """``np.unique(keys, axis=0, return_inverse=True)`` for (N, 3) integer voxel indices: the
    same sorted rows and inverse, from one packed int64 per row (a 1-D sort, not a sort of
    rows: some ten times faster)."""
    half = 1 << (_KEY_BITS - 1)
    if len(keys) == 0 or int(keys.min()) < -half or int(keys.max()) >= half:
        uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
        return uniq, inverse.reshape(-1)
    shifted = keys + half
    packed = (shifted[:, 0] << (2 * _KEY_BITS)) | (shifted[:, 1] << _KEY_BITS) | shifted[:, 2]
    codes, inverse = np.unique(packed, return_inverse=True)
    mask = (1 << _KEY_BITS) - 1
    uniq = np.stack([codes >> (2 * _KEY_BITS), (codes >> _KEY_BITS) & mask, codes & mask], axis=1) - half
    return uniq, inverse.reshape(-1)


class BackgroundCloud:
    """A voxel-downsampled cloud (voxel centroids, map or log frame) grown frame by frame."""

    def __init__(self, voxel_m: float = VOXEL_M) -> None:
        self.voxel_m = voxel_m
        self._sum: dict[tuple[int, int, int], list[float]] = {}  # x, y, z sums of the voxel's points
        self._n: dict[tuple[int, int, int], int] = {}

    def add_points(self, points: FloatArray) -> None:
        if len(points) == 0:
            return
        keys = np.floor(points / self.voxel_m).astype(np.int64)
        uniq, inverse = _unique_rows(keys)
        # per voxel, the sums of its points in input order (as ``np.add.at``), one pass per axis
        sums = np.stack([np.bincount(inverse, weights=points[:, k], minlength=len(uniq)) for k in range(3)],
                        axis=1)
        counts = np.bincount(inverse, minlength=len(uniq))
        for key, s, n in zip(map(tuple, uniq.tolist()), sums.tolist(), counts.tolist(), strict=True):
            old = self._sum.get(key)
            if old is not None:
                self._sum[key] = [old[0] + s[0], old[1] + s[1], old[2] + s[2]]
                self._n[key] += n
            else:
                self._sum[key] = s
                self._n[key] = n

    def add_frame(self, frame: Frame, T_map_cam: FloatArray | None = None) -> None:
        """The frame's depth returns (sparse pixels, up to ``MAX_DEPTH_M``) in the frame of
        ``T_map_cam`` (default: the frame's own pose)."""
        T = frame.T_map_cam if T_map_cam is None else T_map_cam
        depth = frame.depth_m[::PIXEL_STRIDE, ::PIXEL_STRIDE].astype(np.float64)
        cam = frame.camera
        v, u = np.mgrid[0:frame.depth_m.shape[0]:PIXEL_STRIDE, 0:frame.depth_m.shape[1]:PIXEL_STRIDE]
        ok = (depth > 0.2) & (depth < MAX_DEPTH_M)
        z = depth[ok]
        x = (u[ok] - cam.cx) / cam.fx * z
        y = (v[ok] - cam.cy) / cam.fy * z
        pts = np.stack([x, y, z], axis=1)
        self.add_points(pts @ np.asarray(T)[:3, :3].T + np.asarray(T)[:3, 3])

    def points(self) -> FloatArray:
        if not self._sum:
            return np.zeros((0, 3))
        sums = np.array(list(self._sum.values()), dtype=np.float64)
        return sums / np.array(list(self._n.values()), dtype=np.float64)[:, None]

    def __len__(self) -> int:
        return len(self._sum)


@dataclass(frozen=True)
class Registration:
    """``T_map_log`` carries log-frame points into the map frame; ``fitness``: share of the
    log's points within ``ICP_FINE_M`` of the map after it; ``rmse_m`` their mean distance."""

    T_map_log: FloatArray
    fitness: float
    rmse_m: float


def _cloud(points: FloatArray, voxel_m: float) -> Any:
    import open3d as o3d

    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    pcd = pcd.voxel_down_sample(voxel_m)
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=voxel_m * 2.5, max_nn=30))
    return pcd


def _features(pcd: Any, voxel_m: float) -> Any:
    import open3d as o3d

    return o3d.pipelines.registration.compute_fpfh_feature(  # type: ignore[call-arg]
        pcd, o3d.geometry.KDTreeSearchParamHybrid(radius=voxel_m * 5.0, max_nn=100))


def _refine(source: Any, target: Any, T0: FloatArray) -> Registration:
    """Point-to-plane ICP from ``T0``, coarse then fine; fitness at ``ICP_FINE_M``."""
    import open3d as o3d

    reg = o3d.pipelines.registration
    T = np.asarray(T0)
    for dist in (ICP_COARSE_M, 0.12, ICP_FINE_M):
        T = np.asarray(reg.registration_icp(source, target, dist, T,
                                            reg.TransformationEstimationPointToPlane(),
                                            reg.ICPConvergenceCriteria(max_iteration=60)).transformation)
    ev = reg.evaluate_registration(source, target, ICP_FINE_M, T)
    return Registration(T.copy(), float(ev.fitness), float(ev.inlier_rmse))


def register(log_points: FloatArray, map_points: FloatArray, *, tries: int = 3,
             seed: int = 0) -> Registration:
    """The transform from the log's frame into the map's: ICP from where the log stands first
    (a log in the map frame already, or nearly), else FPFH + RANSAC global registration (best
    of ``tries`` runs) refined by ICP; the best fitness wins."""
    import open3d as o3d

    reg = o3d.pipelines.registration
    o3d.utility.random.seed(seed)
    fine_src, fine_tgt = _cloud(log_points, VOXEL_M), _cloud(map_points, VOXEL_M)
    best = _refine(fine_src, fine_tgt, np.eye(4))
    if best.fitness >= 0.9:  # a log in the map frame already (the same log again, a shared map)
        return best
    src, tgt = _cloud(log_points, FEATURE_VOXEL_M), _cloud(map_points, FEATURE_VOXEL_M)
    f_src, f_tgt = _features(src, FEATURE_VOXEL_M), _features(tgt, FEATURE_VOXEL_M)
    dist = FEATURE_VOXEL_M * 1.5
    for _ in range(tries):
        coarse = reg.registration_ransac_based_on_feature_matching(
            src, tgt, f_src, f_tgt, True, dist, reg.TransformationEstimationPointToPoint(False), 3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(dist)],
            reg.RANSACConvergenceCriteria(100000, 0.999))
        found = _refine(fine_src, fine_tgt, np.asarray(coarse.transformation))
        if found.fitness > best.fitness:
            best = found
    return best
