"""The background filter of the foreground segmentation (step 2 of Algorithm 3).

The points of a frame's subsampled grid that lie inside a background instance's box (map
frame, grown by a margin) are not foreground. ``background_mask`` tests them: each sample at
the mean depth of its pixel block (``background_block_mean``: a quarter of the noise, so a
tight margin), each face of a box grown by ``background_margin_m`` plus the depth noise
(``background_margin_per_m2`` · depth²) projected on the face's normal. The points are moved
into the map frame once; each box visits only the grid rectangle it projects to
(``_box_rois``; a box reaching behind the camera is cut at the camera first), largest boxes
first, its thinnest axis first, and the test runs in place (``_within``). ``inside_boxes`` is
the same test point by point (the reference the tests compare with); ``table_leg_boxes`` are
the boxes under a table top's edges that the stage adds for its legs.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import CORNER_SIGNS, Box3D, point_bounds
from hiper_cli.perceive.foreground.config import BackgroundFilterConfig
from hiper_cli.types import CameraIntrinsics

__all__ = ["background_mask", "inside_boxes", "table_leg_boxes"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
MAX_DEPTH_SLACK_M: float = 0.3
"""... and points up to this much farther are kept, so that an object standing across the
limit keeps its far side (a hard cut at 5 m moved a far chair's centre towards the camera)."""
BACKGROUND_MARGIN_PER_M2: float = 0.0015
"""... plus this times the squared depth (structured-light depth noise grows with z²)."""
BACKGROUND_NOISE_ALONG_RAY: bool = True
"""The z² part grows a box face by the noise projected on the face's normal (depth noise
lies along the viewing ray: a floor seen at a grazing angle needs little of it) ..."""
BACKGROUND_NOISE_MIN_COS: float = 0.25
"""... at least this share of it (edges, flying pixels)."""
BACKGROUND_BLOCK_MEAN: bool = True
"""The filter tests each sample at the mean depth of its ``pixel_step`` × ``pixel_step``
pixel block, on the block centre's ray, where that mean is within
``background_block_tolerance`` filter margins of the sample's own depth (elsewhere the block
straddles an edge and the sample itself is tested). Sixteen pixels average the depth noise
down about four times, so a bed's head board or a chair's feet stand out from the wall or
floor behind them; the points themselves keep their own depth. Where a foot meets the floor
the block mixes both, and a floor sample may stay with the object."""
BACKGROUND_BLOCK_TOLERANCE: float = 2.0
TABLE_LEG_BAND_M: float = 0.0
"""Filter a band this wide under the edges of every background table top: its legs (0: off;
needs accurate table boxes: with the background stage's table estimates it cut chairs)."""

FloatArray = NDArray[np.float64]


def background_mask(
    depth_m: NDArray[np.float32],
    z: FloatArray,
    valid: NDArray[np.bool_],
    rx: FloatArray,
    ry: FloatArray,
    camera: CameraIntrinsics,
    T_map_cam: FloatArray,
    boxes_map: Sequence[Box3D],
    config: BackgroundFilterConfig,
) -> NDArray[np.bool_]:
    """``valid`` (h, w) without the grid samples inside ``boxes_map``; ``z`` (h, w) the
    samples' depths, ``rx``/``ry`` their rays (x/z, y/z), ``depth_m`` the full image (for the
    block means)."""
    step = config.pixel_step
    R, t = T_map_cam[:3, :3], T_map_cam[:3, 3]
    noise = BACKGROUND_MARGIN_PER_M2 * z * z
    if BACKGROUND_NOISE_ALONG_RAY:
        margin, along = np.full(z.shape, config.background_margin_m), noise
    else:
        margin, along = config.background_margin_m + noise, None
    # The points tested (block means where usable) as map-frame columns, and their unit
    # viewing rays: x = rx·z, y = ry·z, so the ray is (rx, ry, 1) normalised, whatever z.
    ray_x, ray_y, z_test = rx, ry, z
    if BACKGROUND_BLOCK_MEAN and step > 1:
        tol = BACKGROUND_BLOCK_TOLERANCE * (config.background_margin_m + noise)
        z_test, use = _block_mean_depth(depth_m, step, z, tol)
        centre = (step - 1) / 2.0 - step // 2  # the block's centre, from its sample's pixel
        ray_x = np.where(use, rx + centre / camera.fx, rx)
        ray_y = np.where(use, ry + centre / camera.fy, ry)
    x_cam, y_cam = (ray_x * z_test).ravel(), (ray_y * z_test).ravel()
    z_cam = z_test.ravel()
    cols_map = [R[k, 0] * x_cam + R[k, 1] * y_cam + R[k, 2] * z_cam + t[k] for k in range(3)]
    rays_map = None
    if along is not None:
        inv_norm = 1.0 / np.sqrt(ray_x * ray_x + ray_y * ray_y + 1.0).ravel()
        ux, uy = ray_x.ravel() * inv_norm, ray_y.ravel() * inv_norm
        rays_map = [R[k, 0] * ux + R[k, 1] * uy + R[k, 2] * inv_norm for k in range(3)]
    return _filter_background(
        valid, cols_map, margin, boxes_map, camera, T_map_cam, step, config, along, rays_map
    )


def _block_mean_depth(
    depth_m: NDArray[np.float32], step: int, z: FloatArray, tol_m: FloatArray
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The mean depth of each grid sample's ``step`` × ``step`` pixel block (valid pixels
    only; it belongs to the block's centre pixel), and where to use it: where it is within
    ``tol_m`` (h, w) of the sample's own depth (elsewhere the block straddles an edge).

    The block mean of a planar patch lies on the plane, so it is as close to a wall or floor as
    the sample is, with the depth noise averaged over ``step``² pixels. One OpenCV area resize:
    well under a millisecond at 640×480.
    """
    import cv2

    h, w = z.shape
    if depth_m.shape == (h * step, w * step) and depth_m.dtype == np.float32:
        full = depth_m  # the usual case: the grid tiles the image
    else:
        full = np.zeros((h * step, w * step), dtype=np.float32)
        rows, cols = min(depth_m.shape[0], h * step), min(depth_m.shape[1], w * step)
        full[:rows, :cols] = depth_m[:rows, :cols]
    if full.size and not (np.isfinite(full.min()) and np.isfinite(full.max())):  # NaN, inf: rare
        full = np.nan_to_num(full, nan=0.0, posinf=0.0, neginf=0.0)
    valid = np.greater(full, 0.0, out=np.empty(full.shape, dtype=np.float32), casting="unsafe")
    sum_z = cv2.resize(full, (w, h), interpolation=cv2.INTER_AREA).astype(np.float64)
    count = cv2.resize(valid, (w, h), interpolation=cv2.INTER_AREA).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = sum_z / count
    use = (count > 0) & (np.abs(mean - z) <= tol_m)
    return np.where(use, mean, z), use


def inside_boxes(
    points: FloatArray, boxes: Sequence[Box3D], margin_m: float | FloatArray
) -> NDArray[np.bool_]:
    """Which of ``points`` (N, 3) lie inside any of ``boxes`` (same frame) grown by ``margin_m``
    (one value, or one per point)."""
    inside = np.zeros(len(points), dtype=bool)
    if len(points) == 0 or not boxes:
        return inside
    margin = np.asarray(margin_m, dtype=np.float64)
    max_margin = float(margin.max())
    per_point = margin.reshape(-1, 1) if margin.ndim else margin
    plo, phi = point_bounds(points)
    todo = np.arange(len(points))  # points not yet known to be inside: the set shrinks
    for box in sorted(boxes, key=lambda b: -b.volume_m3):  # floors and walls first
        lo, hi = box.aabb()
        if np.any(lo - max_margin > phi) or np.any(hi + max_margin < plo):
            continue  # no point can be inside
        if len(todo) == 0:
            break
        rel = points[todo] - box.center_m
        if not np.allclose(box.R, np.eye(3), atol=1e-9):
            rel = rel @ box.R
        local = np.abs(rel) - box.extent_m / 2.0
        m = per_point[todo] if per_point.ndim else per_point
        hit = np.all(local <= m, axis=1)
        inside[todo[hit]] = True
        todo = todo[~hit]
    return inside


# The 12 edges of a box as pairs of ``CORNER_SIGNS`` rows (rows that differ in one sign).
_EDGES = np.array([(i, i | bit) for bit in (4, 2, 1) for i in range(8) if not i & bit])
_NEAR_Z_M = 0.05  # boxes are cut at this depth (or half min_depth_m) before projecting


def _box_rois(
    boxes: Sequence[Box3D], margin_m: float, camera: CameraIntrinsics, T_cam_map: FloatArray, step: int,
    shape: tuple[int, int], config: BackgroundFilterConfig,
) -> list[tuple[slice, slice] | None]:
    """For each box (grown by a margin), the rows and columns of the subsampled grid it can
    cover; None when it is out of view.

    A box that reaches behind the camera (a wall or the floor beside the robot) is cut at
    ``_NEAR_Z_M`` (or half ``min_depth_m``: no point nearer is valid) first: its part in front
    of the camera is the convex hull of its corners there and the points where its edges cross
    that depth, and a projection maps that hull onto the hull of their images. (Taking the
    whole image for it tested every point of the frame.)
    """
    if not boxes:
        return []
    centres = np.stack([b.center_m for b in boxes])
    halves = np.stack([b.extent_m for b in boxes]) / 2.0 + margin_m
    R_cam = T_cam_map[:3, :3] @ np.stack([b.R for b in boxes])  # (B, 3, 3)
    # corners[b, k] = R_cam[b] @ (halves[b] * signs[k]) + centre of b in the camera frame
    corners = np.einsum("bij,bkj->bki", R_cam, halves[:, None, :] * CORNER_SIGNS)
    corners += (centres @ T_cam_map[:3, :3].T + T_cam_map[:3, 3])[:, None, :]
    z = corners[:, :, 2]
    h, w = shape
    reach_m = config.max_depth_m + MAX_DEPTH_SLACK_M
    lo_c, hi_c = corners.min(axis=1), corners.max(axis=1)
    gap_m = np.linalg.norm(np.maximum(np.maximum(lo_c, -hi_c), 0.0), axis=1)
    behind = np.all(z < config.min_depth_m, axis=1)
    near_z = max(min(_NEAR_Z_M, config.min_depth_m / 2.0), 1e-3)
    off = step // 2
    out: list[tuple[slice, slice] | None] = []
    for b in range(len(boxes)):
        if behind[b] or gap_m[b] > reach_m:
            out.append(None)  # behind the camera, or farther than the sensor sees
            continue
        pts = corners[b]
        if np.any(z[b] < near_z):
            za, zb = z[b][_EDGES[:, 0]], z[b][_EDGES[:, 1]]
            crossing = (za < near_z) != (zb < near_z)
            a, c = pts[_EDGES[crossing, 0]], pts[_EDGES[crossing, 1]]
            t = (near_z - za[crossing]) / (zb[crossing] - za[crossing])
            pts = np.concatenate([pts[z[b] >= near_z], a + t[:, None] * (c - a)])
        u = camera.fx * pts[:, 0] / pts[:, 2] + camera.cx
        v = camera.fy * pts[:, 1] / pts[:, 2] + camera.cy
        c0 = max(int(np.floor((u.min() - off) / step)), 0)
        c1 = min(int(np.ceil((u.max() - off) / step)) + 1, w)
        r0 = max(int(np.floor((v.min() - off) / step)), 0)
        r1 = min(int(np.ceil((v.max() - off) / step)) + 1, h)
        out.append(None if c0 >= c1 or r0 >= r1 else (slice(r0, r1), slice(c0, c1)))
    return out


def _along(columns: Sequence[FloatArray], index: Any, direction: FloatArray) -> FloatArray:
    """The coordinate along ``direction`` of the points ``columns[k][index]`` (x, y, z
    columns); only the columns the direction needs are indexed (one for an axis-aligned box)."""
    main = int(np.argmax(np.abs(direction)))
    if abs(direction[main]) > 1.0 - 1e-9:
        return np.asarray(columns[main][index] * np.sign(direction[main]), dtype=np.float64)
    out = np.zeros(columns[0][index].shape)
    for k in range(3):
        if direction[k] != 0.0:
            out += columns[k][index] * direction[k]
    return out


def _within(
    columns: Sequence[FloatArray], index: Any, direction: FloatArray, offset_m: float, half_m: float,
    allowed_m: float | FloatArray, noise: FloatArray | None, ray_columns: Sequence[FloatArray],
    min_cos: float,
) -> NDArray[np.bool_]:
    """Whether the points ``columns[k][index]`` lie within a slab: ``|p·direction - offset_m| -
    half_m <= allowed_m`` (a number or per point), plus, with ``noise`` (per point), the noise
    times the cosine of the viewing ray (``ray_columns``) with ``direction``, at least
    ``min_cos``. Computed in place on two arrays, not the eight temporaries of the formula
    (the same numbers: an axis direction only flips a sign)."""
    main = int(np.argmax(np.abs(direction)))
    axis = abs(direction[main]) > 1.0 - 1e-9
    if axis:  # |x·s - c| = |x - s·c| for s = ±1
        dist = np.subtract(columns[main][index], float(np.sign(direction[main])) * offset_m)
    else:
        dist = _along(columns, index, direction)
        np.subtract(dist, offset_m, out=dist)
    np.abs(dist, out=dist)
    np.subtract(dist, half_m, out=dist)
    if noise is None:
        inside: NDArray[np.bool_] = np.less_equal(dist, allowed_m)
        return inside
    cos = np.abs(ray_columns[main][index]) if axis else np.abs(_along(ray_columns, index, direction))
    np.maximum(cos, min_cos, out=cos)
    np.multiply(cos, noise[index], out=cos)
    np.add(cos, allowed_m, out=cos)
    within: NDArray[np.bool_] = np.less_equal(dist, cos)
    return within


def _filter_background(
    valid: NDArray[np.bool_],
    cols_map: Sequence[FloatArray],
    margin: FloatArray,
    boxes: Sequence[Box3D],
    camera: CameraIntrinsics,
    T_map_cam: FloatArray,
    step: int,
    config: BackgroundFilterConfig,
    noise: FloatArray | None = None,
    rays_map: Sequence[FloatArray] | None = None,
) -> NDArray[np.bool_]:
    """``valid`` without the grid points inside any box; each box only visits the part of the
    grid it projects to.

    ``cols_map``: the points' map-frame x, y and z, each a flat (h·w,) array (contiguous
    columns: a box axis along a map axis, the usual case of walls, floors and tables, then costs
    one gather and one subtraction per candidate point). ``margin`` (h, w) grows every box on
    every side. ``noise`` (h, w), when given, is the depth noise of each point: it grows a box
    face by that noise projected on the face's normal (depth noise moves a point along its
    viewing ray, so a floor seen at a grazing angle needs far less margin than a wall seen
    head-on), at least ``background_noise_min_cos`` of it; ``rays_map`` (required with
    ``noise``) are the unit viewing rays, map frame, columns as ``cols_map``.
    """
    h, w = valid.shape
    flat_valid = valid.ravel().copy()
    T_cam_map = np.asarray(np.linalg.inv(T_map_cam), dtype=np.float64)
    # One margin for every point (the usual case: the depth noise is in ``noise``) is added as a
    # number, not gathered per point.
    uniform = margin.size > 0 and float(margin.min()) == float(margin.max())
    max_margin = float(margin.max()) if margin.size else 0.0
    m_all = max_margin
    M = margin.ravel()
    N: FloatArray | None = None
    ray_cols: Sequence[FloatArray] = ()
    if noise is not None and noise.size:
        max_margin += float(noise.max())
        N = noise.ravel()
        if rays_map is None:
            raise ValueError("_filter_background: noise needs rays_map")
        ray_cols = rays_map

    grid_valid = flat_valid.reshape(h, w)  # a view: the boxes' removals show in it
    grids = [c.reshape(h, w) for c in cols_map]
    ray_grids = [c.reshape(h, w) for c in ray_cols]
    M_grid = M.reshape(h, w)
    N_grid = None if N is None else N.reshape(h, w)
    min_cos = BACKGROUND_NOISE_MIN_COS

    # Largest boxes first (floor, walls): they remove most points, the others test fewer.
    boxes = sorted(boxes, key=lambda b: -b.volume_m3)
    rois = _box_rois(boxes, max_margin, camera, T_cam_map, step, (h, w), config)
    for box, roi in zip(boxes, rois, strict=True):
        if roi is None:
            continue
        rows, cols = roi
        # Thinnest axis first (walls, floors): few points survive it, the others test fewer.
        # The first test runs on the box's image rectangle as is (no gather).
        axes = np.argsort(box.extent_m)
        direction = box.R[:, axes[0]]
        keep = _within(
            grids, (rows, cols), direction, float(box.center_m @ direction), box.extent_m[axes[0]] / 2.0,
            m_all if uniform else M_grid[rows, cols], N_grid, ray_grids, min_cos,
        )
        keep &= grid_valid[rows, cols]
        local_idx = np.flatnonzero(keep)
        if len(local_idx) == 0:
            continue
        width = cols.stop - cols.start
        cand = (local_idx // width + rows.start) * w + local_idx % width + cols.start
        for axis in axes[1:]:
            direction = box.R[:, axis]
            inside = _within(
                cols_map, cand, direction, float(box.center_m @ direction), box.extent_m[axis] / 2.0,
                m_all if uniform else M[cand], N, ray_cols, min_cos,
            )
            cand = cand[inside]
            if len(cand) == 0:
                break
        flat_valid[cand] = False
    return flat_valid.reshape(h, w)


def table_leg_boxes(top: Box3D, band_m: float, height_m: float = 1.2) -> list[Box3D]:
    """Where a table's legs stand: four boxes under the edges of its top (``band_m`` wide,
    reaching ``height_m`` down from the top's underside), in the frame of ``top``.

    The background layer knows a table as its top plane; its legs survive the background
    filter and join the chairs beside them into one cluster. Filtering this band under the
    top's perimeter removes the legs and keeps what stands beside (or under) the table.
    """
    if band_m <= 0:
        return []
    R = np.asarray(top.R, dtype=np.float64)
    normal = int(np.argmax(np.abs(R[2, :])))  # the top's axis closest to the vertical
    a, b = (k for k in range(3) if k != normal)
    underside_z = float(top.center_m[2]) - float(np.abs(R[2, normal]) * top.extent_m[normal]) / 2.0
    out = []
    for along, across in ((a, b), (b, a)):
        band = min(band_m, float(top.extent_m[along]) / 2.0)
        for sign in (-1.0, 1.0):
            extent = np.zeros(3)
            extent[normal], extent[along], extent[across] = height_m, band, top.extent_m[across]
            centre = top.center_m + sign * (top.extent_m[along] - band) / 2.0 * R[:, along]
            centre = np.array([centre[0], centre[1], underside_z - height_m / 2.0])
            out.append(Box3D(centre, extent, R))
    return out
