"""Foreground segmentation (the paper's Algorithm 3) on an organised depth image.

1. Downscale: take every ``pixel_step``-th pixel of the depth image (an organised subsample:
   no voxel grid, no sorting) and deproject it with cached pixel rays.
2. Filter the background (``background_filter.py``): drop the points inside the background
   instances' boxes (map frame, grown by a margin that grows with the squared depth like the
   sensor noise). Points up to ``max_depth_slack_m`` beyond the range are kept for objects
   that stand across it.
3. Euclidean cluster extraction: two points join one cluster when they are at most
   grid neighbours (8-neighbourhood, or up to ``cluster_neighbour_cells`` apart along a row or
   a column, which bridges missing samples) and closer than
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

from hiper_cli.model import Box3D, point_bounds
from hiper_cli.perceive.foreground.background_filter import (
    BACKGROUND_MARGIN_PER_M2,
    MAX_DEPTH_SLACK_M,
    background_mask,
)
from hiper_cli.perceive.foreground.config import SegmentConfig
from hiper_cli.types import CameraIntrinsics

__all__ = [
    "Blob", "SegmentStats", "boxes_within", "cell_inverse", "concat_blobs", "grid_components", "image_box",
    "pixels_in_boxes", "segment", "sub_blob", "support_below",
]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
CLUSTER_TOLERANCE_PER_M: float = 0.04
"""... plus this much per metre of depth (grazing surfaces, depth noise)."""
CLUSTER_NEIGHBOUR_CELLS: int = 2
"""How far (in subsampled grid cells) a neighbour may be; bridges small depth holes."""
FRAGMENT_RATIO: float = 0.25
"""A cluster smaller than this share of a touching, nearby cluster is a fragment of it ..."""
FRAGMENT_DISTANCE_M: float = 0.3
"""... when its centre is this close to that cluster's box (grazing sides, heads)."""
SUPPORT_GAP_M: float = 0.1
"""A blob whose base is at most the filter margin plus this above a floor or table top
stands on it: its box reaches down to the support (a wider gap, to catch chairs whose thin
legs lose their lowest samples, moves the centre away from what the sensor sees)."""
SUPPORT_EDGE_BAND_M: float = 0.01
"""... unless its lowest points (within this of its lowest) reach the image's lower edge: its
base is out of view (a chair cut there by its front legs, its back feet in view, stands)."""
MAX_CLUSTER_POINTS: int = 8000
MAX_CLUSTER_EXTENT_M: float = 3.0
"""Clusters longer than this in any direction are structure (walls, floor), not objects."""
JOIN_CONTAINMENT: float = 0.8
"""Share of a blob's pixels that must lie in the (grown) detection box to join ..."""

FloatArray = NDArray[np.float64]


@dataclass
class Blob:
    """One cluster: ``points_cam``/``points_map`` (N, 3) metres, ``pixels_uv`` (N, 2) int pixels,
    ``image_box_xyxy`` (4,) pixels (the bounding box of the projected cluster)."""

    points_cam: FloatArray
    points_map: FloatArray
    pixels_uv: NDArray[np.int32]
    image_box_xyxy: FloatArray
    support_z_m: float | None = None
    """Top of the floor or table the blob stands on, when the background filter cut its base."""
    fragment: bool = False
    """Fewer points than ``min_cluster_points``: kept only to be joined to an object (refine)."""
    _bounds: tuple[FloatArray, FloatArray] | None = field(default=None, init=False, repr=False, compare=False)
    _mean: FloatArray | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def bounds_map(self) -> tuple[FloatArray, FloatArray]:
        """(min, max) corners (3,) of the points, map frame; computed once (a blob's points do
        not change: a part of it is a new blob), not to be modified."""
        if self._bounds is None:
            self._bounds = point_bounds(self.points_map)
        return self._bounds

    def _z_range(self) -> tuple[float, float]:
        lo_m, hi_m = self.bounds_map
        lo, hi = float(lo_m[2]), float(hi_m[2])
        if self.support_z_m is not None and self.support_z_m < lo:
            lo = self.support_z_m
        return lo, hi

    @property
    def center_map_m(self) -> FloatArray:
        """Where the blob is, map frame: the centroid of its points horizontally (robust to
        depth noise, which moves the box's extreme points) and the middle of its vertical
        extent (the box centre height, independent of how densely each part was sampled)."""
        if self._mean is None:
            self._mean = np.asarray(self.points_map.mean(axis=0), dtype=np.float64)
        centre = self._mean.copy()
        z_lo, z_hi = self._z_range()
        centre[2] = (z_lo + z_hi) / 2.0
        return centre

    @property
    def extent_map_m(self) -> FloatArray:
        lo, hi = self.bounds_map
        extent = hi - lo
        z_lo, z_hi = self._z_range()
        extent[2] = z_hi - z_lo
        return np.asarray(extent, dtype=np.float64)


def image_box(uv: NDArray[np.int32], step: int, width: int, height: int) -> FloatArray:
    """The image box (xyxy pixels) of sampled pixels ``uv`` (N, 2): each sample covers
    ``step`` pixels, clipped to the image."""
    half = step / 2.0
    lo, hi = point_bounds(uv)
    return np.array(
        [
            max(0.0, lo[0] - half),
            max(0.0, lo[1] - half),
            min(float(width), hi[0] + half),
            min(float(height), hi[1] + half),
        ]
    )


def pixels_in_boxes(uv: NDArray[np.int32], boxes: FloatArray) -> NDArray[np.bool_]:
    """(N, K): pixel n inside box k (xyxy, pixel centres, half-open like the image box)."""
    u = uv[:, 0:1].astype(np.float64) + 0.5
    v = uv[:, 1:2].astype(np.float64) + 0.5
    in_u = (u >= boxes[None, :, 0]) & (u <= boxes[None, :, 2])
    return np.asarray(in_u & (v >= boxes[None, :, 1]) & (v <= boxes[None, :, 3]))


def boxes_within(outer_xyxy: FloatArray, boxes: FloatArray, share: float) -> NDArray[np.bool_]:
    """(K,): whether ``share`` of box k's area (xyxy, (K, 4)) lies inside ``outer_xyxy``."""
    lo = np.maximum(outer_xyxy[None, :2], boxes[:, :2])
    hi = np.minimum(outer_xyxy[None, 2:], boxes[:, 2:])
    area = np.maximum(np.prod(boxes[:, 2:] - boxes[:, :2], axis=1), 1e-9)
    return np.asarray(np.prod(np.clip(hi - lo, 0.0, None), axis=1) >= share * area)


def sub_blob(blob: Blob, sel: NDArray[np.int64], step: int, width: int, height: int) -> Blob:
    """The points ``sel`` of ``blob`` as a blob of their own (its support and fragment flag)."""
    uv = blob.pixels_uv[sel]
    box = image_box(uv, step, width, height)
    return Blob(blob.points_cam[sel], blob.points_map[sel], uv, box, blob.support_z_m, blob.fragment)


def concat_blobs(
    blobs: Sequence[Blob], step: int, width: int, height: int, support_z_m: float | None = None
) -> Blob:
    """The points of ``blobs`` as one blob, standing on ``support_z_m``."""
    whole = Blob(
        np.concatenate([b.points_cam for b in blobs]),
        np.concatenate([b.points_map for b in blobs]),
        np.concatenate([b.pixels_uv for b in blobs]),
        np.zeros(4),
        support_z_m,
    )
    return sub_blob(whole, np.arange(len(whole.points_cam)), step, width, height)


@dataclass
class SegmentStats:
    """How many points each step kept (for reports and the ablation)."""

    points: int = 0
    after_background: int = 0
    clusters: int = 0
    rejected_clusters: int = 0
    timings_s: dict[str, float] = field(default_factory=dict)
    large: list[Blob] = field(default_factory=list)
    """The clusters rejected as too large for one object (``MAX_CLUSTER_POINTS``,
    ``MAX_CLUSTER_EXTENT_M``): structure, or a rack or a row of shelves seen along its length.
    The static map (``solid_map.py``) still takes their surface."""


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


def cell_inverse(points_xy: FloatArray, cell_m: float) -> NDArray[np.int64]:
    """The index of each point's horizontal cell (``cell_m`` wide) among the occupied cells,
    numbered in (x, y) order: ``np.unique(cells, axis=0, return_inverse=True)`` on one integer
    key per point, several times faster."""
    cells = np.floor(points_xy / cell_m).astype(np.int64)
    cells -= cells.min(axis=0)
    flat = cells[:, 0] * (int(cells[:, 1].max()) + 1) + cells[:, 1]
    _, inverse = np.unique(flat, return_inverse=True)
    return np.asarray(inverse.reshape(-1), dtype=np.int64)


def _cluster_labels(
    P: FloatArray, valid: NDArray[np.bool_], tolerance_m: float, per_m: float, cells: int
) -> NDArray[np.int64]:
    """Connected components of the organised neighbour graph; -1 for invalid points.

    Only the valid points are visited, so the cost follows the number of points left after
    the background filter (the paper's observation: filtering speeds up segmentation).
    """
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    h, w = valid.shape
    labels = np.full(h * w, -1, dtype=np.int64)
    idx = np.flatnonzero(valid.ravel())
    n = len(idx)
    if n == 0:
        return labels
    # Compact indices on a grid padded by ``cells`` columns on both sides and rows below: a
    # neighbour is then a constant offset away, with no bounds tests.
    padded_w = w + 2 * cells
    compact = np.full((h + cells) * padded_w, -1, dtype=np.int32)
    ys, xs = np.divmod(idx, w)
    at = ys * padded_w + xs + cells
    compact[at] = np.arange(n, dtype=np.int32)
    flat = P.reshape(-1, 3)
    X, Y, Z = flat[idx, 0], flat[idx, 1], flat[idx, 2]
    tol = tolerance_m + per_m * Z
    tol2 = tol * tol
    rows: list[NDArray[np.int64]] = []
    cols: list[NDArray[np.int32]] = []
    # The 8-neighbourhood, plus straight jumps of up to ``cells`` over missing samples.
    offsets = [(0, 1), (1, -1), (1, 0), (1, 1)] + [(0, k) for k in range(2, cells + 1)]
    offsets += [(k, 0) for k in range(2, cells + 1)]
    for dy, dx in offsets:
        nb = compact[at + (dy * padded_w + dx)]
        src = np.flatnonzero(nb >= 0)
        nb = nb[src]
        d = X[src] - X[nb]
        dist2 = d * d
        d = Y[src] - Y[nb]
        dist2 += d * d
        d = Z[src] - Z[nb]
        dist2 += d * d
        close = dist2 <= tol2[src]
        rows.append(src[close])
        cols.append(nb[close])
    r = np.concatenate(rows)
    c = np.concatenate(cols)
    # float64 weights (what the graph routines take, not a copy to convert) and the weak
    # components of the one-way edges: the components of the undirected graph, without
    # adding its transpose first.
    graph = csr_matrix((np.ones(len(r)), (r, c)), shape=(n, n))
    _, comp = connected_components(graph, directed=True, connection="weak")
    labels[idx] = comp
    return labels


def grid_components(
    blob: Blob, sel: NDArray[np.int64], step: int, config: SegmentConfig
) -> list[NDArray[np.int64]]:
    """The connected parts of the points ``sel`` of ``blob`` (indices into ``sel``), linked
    as the segmentation links points (``_cluster_labels`` on the blob's own sampling grid);
    ordered by their first point in ``sel``."""
    if len(sel) == 0:
        return []
    grid = (blob.pixels_uv[sel] // step).astype(np.int64)
    grid -= grid.min(axis=0)
    width, height = int(grid[:, 0].max()) + 1, int(grid[:, 1].max()) + 1
    points = np.zeros((height, width, 3))
    valid = np.zeros((height, width), dtype=bool)
    points[grid[:, 1], grid[:, 0]] = blob.points_cam[sel]
    valid[grid[:, 1], grid[:, 0]] = True
    labels = _cluster_labels(
        points, valid, config.cluster_tolerance_m, CLUSTER_TOLERANCE_PER_M,
        CLUSTER_NEIGHBOUR_CELLS,
    )[grid[:, 1] * width + grid[:, 0]]
    _, first = np.unique(labels, return_index=True)
    return [np.flatnonzero(labels == labels[i]) for i in np.sort(first)]


def _merge_fragments(
    member: NDArray[np.int64], starts: NDArray[np.int64], map_full: FloatArray, grid_w: int,
    config: SegmentConfig, min_size: int = 3,
) -> list[NDArray[np.int64]]:
    """The clusters of at least ``min_size`` points, small fragments folded into a much
    larger neighbouring cluster. The clusters are the consecutive slices of ``member`` (grid
    indices) that begin at ``starts``.

    Surfaces seen at a grazing angle (the side of a body at the silhouette) break away from
    the object they belong to: consecutive samples are far apart in depth; so does a head
    above a thin neck. A fragment smaller than ``fragment_ratio`` of a cluster whose grid box
    touches its own and whose centre is within ``fragment_distance_m`` of that cluster's box
    (map frame) joins that cluster.
    """
    ends = np.r_[starts[1:], len(member)]
    sizes = ends - starts
    keep = np.flatnonzero(sizes >= min_size)
    if len(keep) < 2:
        return [member[starts[k]:ends[k]] for k in keep]
    # Every cluster's box and grid box at once (reductions over the slices); a centre only
    # when a fragment's grid box touches a larger cluster's.
    pts = map_full[member]
    lows = np.minimum.reduceat(pts, starts, axis=0)
    highs = np.maximum.reduceat(pts, starts, axis=0)
    pad = CLUSTER_NEIGHBOUR_CELLS + 1
    gy, gx = member // grid_w, member % grid_w
    grid_boxes = np.stack([
        np.minimum.reduceat(gy, starts) - pad, np.minimum.reduceat(gx, starts) - pad,
        np.maximum.reduceat(gy, starts) + pad, np.maximum.reduceat(gx, starts) + pad,
    ], axis=1).tolist()
    order = keep[np.argsort(-sizes[keep], kind="stable")].tolist()  # largest first
    kept: list[int] = []
    members: dict[int, list[NDArray[np.int64]]] = {}
    ratio, reach = FRAGMENT_RATIO, FRAGMENT_DISTANCE_M
    for i in order:
        target = None
        a = grid_boxes[i]
        centre: FloatArray | None = None
        for j in kept:
            if sizes[i] > ratio * sizes[j]:
                continue
            b = grid_boxes[j]
            if a[0] > b[2] or b[0] > a[2] or a[1] > b[3] or b[1] > a[3]:
                continue
            if centre is None:
                centre = pts[starts[i]:ends[i]].mean(axis=0)
            gap = np.maximum(np.maximum(lows[j] - centre, centre - highs[j]), 0.0)
            if np.linalg.norm(gap) <= reach:
                target = j
                break
        group = member[starts[i]:ends[i]]
        if target is None:
            kept.append(i)
            members[i] = [group]
        else:
            members[target].append(group)
    return [np.concatenate(members[i]) if len(members[i]) > 1 else members[i][0] for i in kept]


def support_below(
    blob: Blob, supports: Sequence[Box3D], config: SegmentConfig, image_height: int | None = None
) -> float | None:
    """Top height of the support the blob stands on, if its base is within the filter margin
    plus ``support_gap_m`` above it (thin legs and feet lose their lowest samples to the margin
    and to the subsampling). None for a blob whose lowest points (``support_edge_band_m``)
    reach the lower edge of the image (``image_height``): its base is out of view, and its box
    stays what the camera sees."""
    lo, hi = blob.bounds_map
    edge_v = None if image_height is None else image_height - config.pixel_step
    if edge_v is not None and blob.image_box_xyxy[3] >= edge_v:
        # Cut by the lower edge: the base is out of view when the lowest points are at the edge
        # (a chair's front legs may be cut while its back feet stand in view).
        low = blob.points_map[:, 2] <= lo[2] + SUPPORT_EDGE_BAND_M
        if np.any(blob.pixels_uv[low, 1] >= edge_v):
            return None
    depth = float(np.median(blob.points_cam[:, 2]))
    margin = config.background_margin_m + BACKGROUND_MARGIN_PER_M2 * depth * depth
    best: float | None = None
    for box in supports:
        b_lo, b_hi = box.aabb()
        if b_lo[0] > hi[0] or b_hi[0] < lo[0] or b_lo[1] > hi[1] or b_hi[1] < lo[1]:
            continue  # not under the blob
        top = float(b_hi[2])
        if 0.0 <= lo[2] - top <= margin + SUPPORT_GAP_M and (best is None or top > best):
            best = top
    return best


def segment(
    depth_m: NDArray[np.float32],
    camera: CameraIntrinsics,
    T_map_cam: FloatArray,
    background_boxes_map: Sequence[Box3D],
    config: SegmentConfig,
    support_boxes_map: Sequence[Box3D] = (),
    keep_fragments: bool = False,
) -> tuple[list[Blob], SegmentStats]:
    """Algorithm 3: the foreground blobs of one depth image (see the module docstring).

    ``support_boxes_map`` are the horizontal background boxes (floor, tables): a blob whose
    base lies within the filter margin above one of them stands on it, and its box reaches
    down to it (the filter removed its lowest points together with the support).
    ``keep_fragments``: clusters of 3 to ``min_cluster_points`` points are returned too, as
    blobs with ``fragment=True`` (for ``refine_blobs`` to join them to their object).
    """
    import time

    stats = SegmentStats()
    t0 = time.perf_counter()
    step = config.pixel_step
    rx, ry, U, V = _rays(camera, step)
    off = step // 2
    z = depth_m[off::step, off::step].astype(np.float64)
    valid = (z >= config.min_depth_m) & (z <= config.max_depth_m + MAX_DEPTH_SLACK_M) & np.isfinite(z)
    P = np.stack([rx * z, ry * z, z], axis=-1)  # (h, w, 3) camera frame
    stats.points = int(valid.sum())
    P_flat = P.reshape(-1, 3)
    map_full = P_flat @ T_map_cam[:3, :3].T + T_map_cam[:3, 3]
    t1 = time.perf_counter()
    if config.background_filter and background_boxes_map:
        valid = background_mask(depth_m, z, valid, rx, ry, camera, T_map_cam, background_boxes_map, config)
    stats.after_background = int(valid.sum())
    t2 = time.perf_counter()
    labels = _cluster_labels(
        P, valid, config.cluster_tolerance_m, CLUSTER_TOLERANCE_PER_M, CLUSTER_NEIGHBOUR_CELLS
    )
    member = np.flatnonzero(labels >= 0)
    blobs: list[Blob] = []
    if len(member):
        lab = labels[member]
        order = np.argsort(lab, kind="stable")
        member, lab = member[order], lab[order]
        starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
        U_flat, V_flat = U.ravel(), V.ravel()
        groups = _merge_fragments(member, starts, map_full, valid.shape[1], config)
        for sel in groups:
            size = len(sel)
            fragment = size < config.min_cluster_points
            if fragment and not keep_fragments:
                continue
            if MAX_DEPTH_SLACK_M > 0 and np.median(P_flat[sel, 2]) > config.max_depth_m:
                continue  # beyond the range: the slack only keeps the far side of nearer objects
            pm = map_full[sel]
            lo, hi = point_bounds(pm)
            uv = np.stack([U_flat[sel], V_flat[sel]], axis=1).astype(np.int32)
            box = image_box(uv, step, camera.width, camera.height)
            blob = Blob(P_flat[sel], pm, uv, box, fragment=fragment)
            if size > MAX_CLUSTER_POINTS or np.any(hi - lo > MAX_CLUSTER_EXTENT_M):
                stats.rejected_clusters += 1
                stats.large.append(blob)
                continue
            blob._bounds = (lo, hi)
            if config.background_filter and support_boxes_map:
                blob.support_z_m = support_below(blob, support_boxes_map, config, camera.height)
            blobs.append(blob)
    stats.clusters = sum(1 for b in blobs if not b.fragment)
    t3 = time.perf_counter()
    stats.timings_s = {
        "deproject_s": t1 - t0,
        "background_filter_s": t2 - t1,
        "cluster_s": t3 - t2,
    }
    return blobs, stats
