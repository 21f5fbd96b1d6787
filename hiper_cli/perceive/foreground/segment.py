"""Foreground segmentation (the paper's Algorithm 3) on an organised depth image.

1. Downscale: take every ``pixel_step``-th pixel of the depth image (an organised subsample:
   no voxel grid, no sorting) and deproject it with cached pixel rays.
2. Filter the background: drop the points inside the background instances' boxes (map frame,
   grown by a margin); the points are moved into the map frame once and tested box by box.
3. Euclidean cluster extraction: two points join one cluster when they are at most
   ``cluster_neighbour_cells`` apart on the subsampled grid and closer than
   ``cluster_tolerance_m + cluster_tolerance_per_m · depth`` in 3D (surfaces seen at a
   grazing angle and the sensor's depth noise spread points further apart with range);
   clusters are the connected components of that graph, kept when their size lies in
   [``min_cluster_points``, ``max_cluster_points``] and their extent is below
   ``max_cluster_extent_m``.

Each kept cluster is a ``Blob``: its points in the camera and map frames, the full-resolution
pixel of every point, and the image box of its projection.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.types import CameraIntrinsics

__all__ = ["Blob", "SegmentStats", "inside_boxes", "segment"]

FloatArray = NDArray[np.float64]


@dataclass
class Blob:
    """One cluster: ``points_cam``/``points_map`` (N, 3) metres, ``pixels_uv`` (N, 2) int pixels,
    ``image_box_xyxy`` (4,) pixels (the bounding box of the projected cluster)."""

    points_cam: FloatArray
    points_map: FloatArray
    pixels_uv: NDArray[np.int32]
    image_box_xyxy: FloatArray

    @property
    def center_map(self) -> FloatArray:
        """Centre of the blob's axis-aligned box in the map frame."""
        lo, hi = self.points_map.min(axis=0), self.points_map.max(axis=0)
        return np.asarray((lo + hi) / 2.0, dtype=np.float64)

    @property
    def extent_map(self) -> FloatArray:
        return np.asarray(self.points_map.max(axis=0) - self.points_map.min(axis=0), dtype=np.float64)


@dataclass
class SegmentStats:
    """How many points each step kept (for reports and the ablation)."""

    points: int = 0
    after_background: int = 0
    clusters: int = 0
    rejected_clusters: int = 0
    timings_s: dict[str, float] = field(default_factory=dict)


@lru_cache(maxsize=8)
def _rays(
    camera: CameraIntrinsics, step: int
) -> tuple[FloatArray, FloatArray, NDArray[np.int32], NDArray[np.int32]]:
    """Normalised ray x/z and y/z for the subsampled grid, and its pixel coordinates."""
    off = step // 2
    us = np.arange(off, camera.width, step, dtype=np.int32)
    vs = np.arange(off, camera.height, step, dtype=np.int32)
    U, V = np.meshgrid(us, vs)
    rx = np.asarray((U - camera.cx) / camera.fx, dtype=np.float64)
    ry = np.asarray((V - camera.cy) / camera.fy, dtype=np.float64)
    return rx, ry, U, V


def inside_boxes(points: FloatArray, boxes: Sequence[Box3D], margin_m: float) -> NDArray[np.bool_]:
    """Which of ``points`` (N, 3) lie inside any of ``boxes`` (same frame) grown by ``margin_m``."""
    inside = np.zeros(len(points), dtype=bool)
    if len(points) == 0 or not boxes:
        return inside
    plo, phi = points.min(axis=0), points.max(axis=0)
    for box in boxes:
        lo, hi = box.aabb()
        if np.any(lo - margin_m > phi) or np.any(hi + margin_m < plo):
            continue  # no point can be inside
        half = box.extent_m / 2.0 + margin_m
        local = (points - box.center_m) @ box.R
        inside |= np.all(np.abs(local) <= half, axis=1)
    return inside


def _cluster_labels(
    P: FloatArray, valid: NDArray[np.bool_], tolerance_m: float, per_m: float, cells: int
) -> NDArray[np.int64]:
    """Connected components of the organised neighbour graph; -1 for invalid points."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    h, w = valid.shape
    index = np.arange(h * w).reshape(h, w)
    rows: list[NDArray[np.int64]] = []
    cols: list[NDArray[np.int64]] = []
    offsets = [(dy, dx) for dy in range(0, cells + 1) for dx in range(-cells, cells + 1) if (dy, dx) > (0, 0)]
    for dy, dx in offsets:
        ys0, ys1 = 0, h - dy
        xs0, xs1 = max(0, -dx), w - max(0, dx)
        a = (slice(ys0, ys1), slice(xs0, xs1))
        b = (slice(ys0 + dy, ys1 + dy), slice(xs0 + dx, xs1 + dx))
        both = valid[a] & valid[b]
        if not both.any():
            continue
        pa = P[a][both]
        diff = pa - P[b][both]
        tol = tolerance_m + per_m * pa[:, 2]
        close = np.einsum("ij,ij->i", diff, diff) <= tol * tol
        rows.append(index[a][both][close])
        cols.append(index[b][both][close])
    n = h * w
    r = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    c = np.concatenate(cols) if cols else np.zeros(0, dtype=np.int64)
    graph = coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)), shape=(n, n)).tocsr()
    _, labels = connected_components(graph, directed=False)
    labels = labels.astype(np.int64)
    labels[~valid.ravel()] = -1
    return labels


def _merge_fragments(
    groups: list[NDArray[np.int64]], map_full: FloatArray, grid_w: int, config: ForegroundConfig
) -> list[NDArray[np.int64]]:
    """Fold small fragments into a much larger neighbouring cluster.

    Surfaces seen at a grazing angle (the side of a body at the silhouette) break away from
    the object they belong to: consecutive samples are far apart in depth. A fragment smaller
    than ``fragment_ratio`` of a cluster whose grid box touches its own and whose centre is
    within ``fragment_distance_m`` joins that cluster.
    """
    if len(groups) < 2:
        return groups
    groups = sorted(groups, key=len, reverse=True)
    pad = config.cluster_neighbour_cells + 1
    boxes = []
    for g in groups:
        gy, gx = g // grid_w, g % grid_w
        boxes.append((gy.min() - pad, gx.min() - pad, gy.max() + pad, gx.max() + pad))
    centres = [map_full[g].mean(axis=0) for g in groups]
    kept: list[int] = []
    members: dict[int, list[NDArray[np.int64]]] = {}
    for i, g in enumerate(groups):
        target = None
        for j in kept:
            if len(g) > config.fragment_ratio * len(groups[j]):
                continue
            a, b = boxes[i], boxes[j]
            if a[0] > b[2] or b[0] > a[2] or a[1] > b[3] or b[1] > a[3]:
                continue
            if np.linalg.norm(centres[i] - centres[j]) <= config.fragment_distance_m:
                target = j
                break
        if target is None:
            kept.append(i)
            members[i] = [g]
        else:
            members[target].append(g)
    return [np.concatenate(members[i]) if len(members[i]) > 1 else members[i][0] for i in kept]


def segment(
    depth_m: NDArray[np.float32],
    camera: CameraIntrinsics,
    T_map_cam: FloatArray,
    background_boxes_map: Sequence[Box3D],
    config: ForegroundConfig,
) -> tuple[list[Blob], SegmentStats]:
    """Algorithm 3: the foreground blobs of one depth image (see the module docstring)."""
    import time

    stats = SegmentStats()
    t0 = time.perf_counter()
    step = config.pixel_step
    rx, ry, U, V = _rays(camera, step)
    off = step // 2
    z = depth_m[off::step, off::step].astype(np.float64)
    valid = (z >= config.min_depth_m) & (z <= config.max_depth_m) & np.isfinite(z)
    P = np.stack([rx * z, ry * z, z], axis=-1)  # (h, w, 3) camera frame
    stats.points = int(valid.sum())
    idx = np.flatnonzero(valid)
    P_flat = P.reshape(-1, 3)
    R, t = T_map_cam[:3, :3], T_map_cam[:3, 3]
    pts_map = P_flat[idx] @ R.T + t
    t1 = time.perf_counter()
    if config.background_filter and background_boxes_map:
        bg = inside_boxes(pts_map, background_boxes_map, config.background_margin_m)
        flat_valid = valid.ravel().copy()
        flat_valid[idx[bg]] = False
        valid = flat_valid.reshape(valid.shape)
    stats.after_background = int(valid.sum())
    t2 = time.perf_counter()
    map_full = np.zeros_like(P_flat)
    map_full[idx] = pts_map
    labels = _cluster_labels(
        P, valid, config.cluster_tolerance_m, config.cluster_tolerance_per_m, config.cluster_neighbour_cells
    )
    member = np.flatnonzero(labels >= 0)
    blobs: list[Blob] = []
    if len(member):
        lab = labels[member]
        order = np.argsort(lab, kind="stable")
        member, lab = member[order], lab[order]
        starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
        ends = np.r_[starts[1:], len(lab)]
        sizes = ends - starts
        U_flat, V_flat = U.ravel(), V.ravel()
        half = step / 2.0
        groups = [member[s:e] for s, e, size in zip(starts, ends, sizes, strict=True) if size >= 3]
        groups = _merge_fragments(groups, map_full, valid.shape[1], config)
        for sel in groups:
            size = len(sel)
            if size < config.min_cluster_points:
                continue
            if size > config.max_cluster_points:
                stats.rejected_clusters += 1
                continue
            pm = map_full[sel]
            if np.any(pm.max(axis=0) - pm.min(axis=0) > config.max_cluster_extent_m):
                stats.rejected_clusters += 1
                continue
            uv = np.stack([U_flat[sel], V_flat[sel]], axis=1).astype(np.int32)
            box = np.array(
                [
                    max(0.0, uv[:, 0].min() - half),
                    max(0.0, uv[:, 1].min() - half),
                    min(float(camera.width), uv[:, 0].max() + half),
                    min(float(camera.height), uv[:, 1].max() + half),
                ]
            )
            blobs.append(Blob(P_flat[sel], pm, uv, box))
    stats.clusters = len(blobs)
    t3 = time.perf_counter()
    stats.timings_s = {
        "deproject_s": t1 - t0,
        "background_filter_s": t2 - t1,
        "cluster_s": t3 - t2,
    }
    return blobs, stats
