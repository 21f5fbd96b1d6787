"""Plane extraction from one organized depth image (Algorithm 1, ``DetectPlanes``).

Two extractors return the same ``PlaneSegment`` list, planes in the camera optical frame:

- ``fast`` (default): the depth image is sampled on a grid (``stride_px``), grouped into cells
  of ``cell_px`` × ``cell_px`` samples, a least-squares plane is fitted to every cell from its
  moments, planar cells whose neighbours carry a similar plane are joined (connected components
  over the cell grid, as in PEAC, Feng et al. 2014, and CAPE, Proença and Gao 2018), each region
  is refitted, extended to the inlier samples around it and refitted again.
- ``ransac``: the paper's method: open3d's ``segment_plane`` run repeatedly on the samples,
  each plane's inliers split into image-connected parts and refitted by least squares.

A plane is ``[a, b, c, d]`` with ``a x + b y + c z + d = 0``, unit normal facing the camera.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.types import CameraIntrinsics

__all__ = ["PlaneSegment", "SampleGrid", "extract_planes", "sample_grid"]

FloatArray = NDArray[np.float64]
MAX_GROW_ANGLE_DEG = 35.0  # noisy cells never join across a real edge (walls meet at 90 degrees)
GROW_NOISE_FACTOR = 1.0  # the tilt one cell's residual explains


@dataclass(frozen=True)
class SampleGrid:
    """Depth samples every ``stride`` pixels: ``points_cam`` (h, w, 3), ``valid`` (h, w)."""

    stride: int
    points_cam: FloatArray
    valid: NDArray[np.bool_]

    @property
    def shape(self) -> tuple[int, int]:
        return int(self.valid.shape[0]), int(self.valid.shape[1])


@dataclass(frozen=True)
class PlaneSegment:
    """One plane seen in one image: ``plane_cam`` (4,), its sample ``mask`` (h, w) on ``grid``."""

    plane_cam: FloatArray
    mask: NDArray[np.bool_]
    rms_m: float
    n_points: int


def sample_grid(depth_m: NDArray[np.float32], camera: CameraIntrinsics, stride: int,
                min_depth_m: float, max_depth_m: float) -> SampleGrid:
    """Deproject every ``stride``-th pixel of ``depth_m`` into the camera frame."""
    z = depth_m[::stride, ::stride].astype(np.float64)
    valid = np.isfinite(z) & (z > min_depth_m) & (z < max_depth_m)
    z = np.where(valid, z, 0.0)
    u = np.arange(0, depth_m.shape[1], stride, dtype=np.float64)
    v = np.arange(0, depth_m.shape[0], stride, dtype=np.float64)
    x = (u[None, :] - camera.cx) / camera.fx * z
    y = (v[:, None] - camera.cy) / camera.fy * z
    return SampleGrid(stride, np.stack([x, y, z], axis=-1), valid)


def _fit_from_moments(n: FloatArray, s1: FloatArray,
                      s2: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Batched plane fit from point count (...), sums (..., 3) and outer-product sums (..., 3, 3).

    Returns unit normals (..., 3) facing the origin (the camera), offsets d (...) and the
    smallest two eigenvalues (..., 2) of the covariance (m²).
    """
    safe_n = np.maximum(n, 1.0)
    mean = s1 / safe_n[..., None]
    cov = s2 / safe_n[..., None, None] - mean[..., :, None] * mean[..., None, :]
    evals, evecs = np.linalg.eigh(cov)
    normal = evecs[..., :, 0]
    d = -np.einsum("...i,...i->...", normal, mean)
    flip = d < 0  # make n·0 + d > 0: the camera is on the normal's side
    normal = np.where(flip[..., None], -normal, normal)
    d = np.where(flip, -d, d)
    return normal, d, np.maximum(evals[..., :2], 0.0)


def _moments(points: FloatArray, weights: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Sums over the second-to-last axis of weighted points (..., k, 3)."""
    n = weights.sum(axis=-1)
    wp = points * weights[..., None]
    s1 = wp.sum(axis=-2)
    s2 = np.einsum("...ki,...kj->...ij", wp, points)
    return n, s1, s2


def _jumps(grid: SampleGrid, limit_inv_m: float) -> NDArray[np.bool_]:
    """Samples at a depth discontinuity: where the second difference of inverse depth along a
    row or a column exceeds ``limit_inv_m`` (on any plane 1/z is linear in the image)."""
    inv = np.where(grid.valid, 1.0 / np.where(grid.valid, grid.points_cam[..., 2], 1.0), np.nan)
    out = np.zeros(inv.shape, bool)
    with np.errstate(invalid="ignore"):
        dh = np.abs(inv[:, 2:] - 2.0 * inv[:, 1:-1] + inv[:, :-2]) > limit_inv_m
        dv = np.abs(inv[2:] - 2.0 * inv[1:-1] + inv[:-2]) > limit_inv_m
    out[:, 1:-1] |= dh
    out[1:-1] |= dv
    return out


def _extract_fast(grid: SampleGrid, cfg: BackgroundConfig) -> list[PlaneSegment]:
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    c = cfg.cell_px
    h, w = grid.shape
    gh, gw = h // c, w // c
    if gh < 1 or gw < 1:
        return []
    pts = grid.points_cam[: gh * c, : gw * c].reshape(gh, c, gw, c, 3).transpose(0, 2, 1, 3, 4)
    pts = pts.reshape(gh, gw, c * c, 3)
    valid = grid.valid[: gh * c, : gw * c].reshape(gh, c, gw, c).transpose(0, 2, 1, 3)
    wts: FloatArray = valid.reshape(gh, gw, c * c).astype(np.float64)
    n, s1, s2 = _moments(pts, wts)
    normal, d, evals = _fit_from_moments(n, s1, s2)
    z_mean = s1[..., 2] / np.maximum(n, 1.0)
    noise = cfg.cell_noise_m * np.maximum(z_mean, 1.0) ** 2
    planar = (n >= cfg.cell_min_valid * c * c) & (np.sqrt(evals[..., 0]) < noise)
    planar &= ~_jumps(grid, cfg.jump_inv_m)[: gh * c, : gw * c].reshape(gh, c, gw, c).any(axis=(1, 3))
    mean = s1 / np.maximum(n, 1.0)[..., None]

    cos_grow = np.cos(_grow_angle(evals, cfg))
    offset = cfg.grow_offset_m * np.maximum(z_mean, 1.0)
    idx = np.arange(gh * gw).reshape(gh, gw)
    rows: list[NDArray[np.int64]] = []
    cols: list[NDArray[np.int64]] = []
    for sa, sb in (
        ((slice(None), slice(0, gw - 1)), (slice(None), slice(1, gw))),
        ((slice(0, gh - 1), slice(None)), (slice(1, gh), slice(None))),
    ):
        na, nb = normal[sa], normal[sb]
        cos_ab = np.maximum(cos_grow[sa], cos_grow[sb])  # the stricter of the two cells
        ok = planar[sa] & planar[sb] & (np.einsum("...i,...i->...", na, nb) > cos_ab)
        off_ab = np.abs(np.einsum("...i,...i->...", na, mean[sb]) + d[sa])
        off_ba = np.abs(np.einsum("...i,...i->...", nb, mean[sa]) + d[sb])
        ok &= (off_ab < offset[sa]) & (off_ba < offset[sb])
        rows.append(idx[sa][ok])
        cols.append(idx[sb][ok])
    r = np.concatenate(rows)
    cc = np.concatenate(cols)
    graph = coo_matrix((np.ones(len(r)), (r, cc)), shape=(gh * gw, gh * gw))
    _, labels = connected_components(graph, directed=False)
    labels = np.where(planar.reshape(-1), labels, -1)
    counts = np.bincount(labels[labels >= 0], minlength=1) if np.any(labels >= 0) else np.zeros(1)
    regions = [int(k) for k in np.flatnonzero(counts >= cfg.min_plane_cells)]
    if not regions:
        return []
    # region planes from summed cell moments
    flat_n, flat_s1, flat_s2 = n.reshape(-1), s1.reshape(-1, 3), s2.reshape(-1, 3, 3)
    cells = [(labels == k).reshape(gh, gw) for k in regions]
    cells = _join_regions(cells, flat_n, flat_s1, flat_s2, cfg)
    planes = []
    for sel in cells:
        flat = sel.reshape(-1)
        rn, rs1, rs2 = flat_n[flat].sum(), flat_s1[flat].sum(axis=0), flat_s2[flat].sum(axis=0)
        nk, dk, _ = _fit_from_moments(np.array(rn), rs1, rs2)
        planes.append(np.append(nk, dk))
    return _refine(grid, np.array(planes), cells, cfg, cell=c)


def _grow_angle(evals: FloatArray, cfg: BackgroundConfig) -> FloatArray:
    """Per cell, the normal angle (radians) it may differ from a neighbour by: at least
    ``grow_angle_deg``, more where the cell's own residual (``evals[..., 0]``, the depth
    noise it holds) tilts its fit. A step of disparity quantisation or noise of RMS ``r``
    across a cell of half-width ``w`` tilts its normal by about atan(r / w), two cells
    differ by about that. At 4.8 m a cell is 0.18 m wide and a stereo sensor's depth
    steps 7 cm: the cells of one wall differ by 20-33 degrees (bookstore log), and with a
    fixed 12 degrees no wall beyond 4 m grew (``grow_noise_angle=False`` restores that).
    Noise-free cells keep ``grow_angle_deg``."""
    floor = np.radians(cfg.grow_angle_deg)
    if not cfg.grow_noise_angle:
        return np.full(evals.shape[:-1], floor)
    rms = np.sqrt(evals[..., 0])
    half_width = np.sqrt(3.0 * np.maximum(evals[..., 1], 1e-12))  # a uniform spread's half-width
    return np.clip(np.arctan(GROW_NOISE_FACTOR * rms / half_width), floor, np.radians(MAX_GROW_ANGLE_DEG))


def _join_regions(cells: list[NDArray[np.bool_]], n: FloatArray, s1: FloatArray, s2: FloatArray,
                  cfg: BackgroundConfig) -> list[NDArray[np.bool_]]:
    """Join regions that touch (within two cells) and whose region-wide planes agree.

    Cell normals are noisy far from the camera, so one surface may grow into several
    regions; their region planes, fitted from many more samples, are accurate enough to
    tell whether they are the same surface.
    """
    import cv2

    def region(sel: NDArray[np.bool_]) -> tuple[FloatArray, FloatArray, FloatArray, NDArray[np.bool_]]:
        """The region's plane (normal, d), mean point and its cells grown by two."""
        flat = sel.reshape(-1)
        rn = n[flat].sum()
        normal, d, _ = _fit_from_moments(np.array(rn), s1[flat].sum(axis=0), s2[flat].sum(axis=0))
        grown = cv2.dilate(sel.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool)
        return normal, d, s1[flat].sum(axis=0) / rn, grown

    cos_join = np.cos(np.radians(cfg.grow_angle_deg))
    # Computed once per region: a join replaces two regions by their union, the rest stay.
    regions = [region(sel) for sel in cells]
    while True:
        stats = [r[:3] for r in regions]
        grown = [r[3] for r in regions]
        pair = None
        for a in range(len(cells)):
            for b in range(a + 1, len(cells)):
                na, da, ma = stats[a]
                nb, db, mb = stats[b]
                if float(na @ nb) < cos_join or not np.any(grown[a] & cells[b]):
                    continue
                z = max(float(ma[2]), float(mb[2]), 1.0)
                if abs(float(na @ mb) + da) < cfg.grow_offset_m * z and abs(float(nb @ ma) + db) < (
                    cfg.grow_offset_m * z
                ):
                    pair = (a, b)
                    break
            if pair:
                break
        if pair is None:
            return cells
        a, b = pair
        cells = [c for k, c in enumerate(cells) if k not in pair] + [cells[a] | cells[b]]
        regions = [r for k, r in enumerate(regions) if k not in pair] + [region(cells[-1])]


def _smooth_neighbours(grid: SampleGrid, jump_frac: float) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Whether each sample and its right / lower neighbour lie on one surface: both valid and
    their depths within ``jump_frac`` of the nearer one. Shapes (h, w - 1) and (h - 1, w)."""
    z = grid.points_cam[..., 2]
    v = grid.valid
    a, b = z[:, :-1], z[:, 1:]
    right = v[:, :-1] & v[:, 1:] & (np.abs(b - a) <= jump_frac * np.minimum(a, b))
    a, b = z[:-1], z[1:]
    down = v[:-1] & v[1:] & (np.abs(b - a) <= jump_frac * np.minimum(a, b))
    return right, down


def _reachable(
    label: NDArray[np.int64], core: NDArray[np.bool_], joined: tuple[NDArray[np.bool_], NDArray[np.bool_]],
    shape: tuple[int, int],
) -> NDArray[np.int64]:
    """``label`` without the samples a plane cannot reach from its own cells through image
    neighbours of the same label and no depth jump: a chair back behind a table, seen just
    above the table's far edge at the table's height, is within the inlier distance of the
    top's plane but 0.45 m behind it."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    h, w = shape
    lab = label.reshape(h, w)
    right, down = joined
    has = np.flatnonzero(label >= 0)
    node = np.full((h, w), -1, dtype=np.int64)  # graph nodes: the labelled samples only
    node.ravel()[has] = np.arange(len(has))
    same_r = right & (lab[:, :-1] == lab[:, 1:]) & (lab[:, :-1] >= 0)
    same_d = down & (lab[:-1] == lab[1:]) & (lab[:-1] >= 0)
    r = np.concatenate([node[:, :-1][same_r], node[:-1][same_d]])
    c = np.concatenate([node[:, 1:][same_r], node[1:][same_d]])
    graph = coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)), shape=(len(has), len(has)))
    n_comp, comp = connected_components(graph, directed=False)
    # components never mix labels: keep those holding a core sample of their own plane
    keep = np.zeros(n_comp, dtype=bool)
    keep[comp[core[label[has], has]]] = True
    out = label.copy()
    out[has[~keep[comp]]] = -1
    return out


def _refine(grid: SampleGrid, planes: FloatArray, region_cells: list[NDArray[np.bool_]],
            cfg: BackgroundConfig, cell: int) -> list[PlaneSegment]:
    """Give every sample near a region to its closest plane, then refit each plane."""
    import cv2

    h, w = grid.shape
    pts = grid.points_cam.reshape(-1, 3)
    valid = grid.valid.reshape(-1)
    threshold = cfg.inlier_m * np.maximum(pts[:, 2], 1.0)
    # where each plane may take samples: its cells and their neighbours
    near = np.zeros((len(planes), h * w), bool)
    core = np.zeros((len(planes), h * w), bool)  # the samples of its own cells
    kernel = np.ones((3, 3), np.uint8)
    for k, cells in enumerate(region_cells):
        for grid_k, cells_k in ((near, cv2.dilate(cells.astype(np.uint8), kernel)), (core, cells)):
            up = np.zeros((h, w), np.uint8)
            big = np.repeat(np.repeat(np.asarray(cells_k, np.uint8), cell, axis=0), cell, axis=1)
            up[: big.shape[0], : big.shape[1]] = big[:h, :w]
            grid_k[k] = up.reshape(-1).astype(bool) & valid
    joined = _smooth_neighbours(grid, cfg.join_jump_frac) if cfg.join_jump_frac > 0 else None
    rms = np.full(len(planes), np.inf)
    out: list[PlaneSegment] = []
    passes = max(cfg.refine_passes, 1)
    for pass_k in range(passes):
        dist = np.abs(pts @ planes[:, :3].T + planes[:, 3]).T  # (K, h*w)
        # after the first pass each plane accepts samples within 2.5 of its own spreads
        limit = np.minimum(threshold[None], np.maximum(2.5 * rms, 0.01)[:, None])
        dist = np.where(near & (dist < limit), dist, np.inf)
        best = np.argmin(dist, axis=0)
        label = np.where(np.isfinite(dist.min(axis=0)), best, -1)
        if joined is not None and pass_k == passes - 1:  # the final masks (a strip moves no fit)
            label = _reachable(label, core, joined, (h, w))
        out = []
        for k in range(len(planes)):
            sel = np.flatnonzero(label == k)
            count = len(sel)
            if count < 3:
                continue
            p = pts[sel]
            normal, d, evals = _fit_from_moments(np.array(float(count)), p.sum(axis=0), p.T @ p)
            planes[k] = np.append(normal, d)
            rms[k] = float(np.sqrt(evals[0]))
            out.append(PlaneSegment(planes[k].copy(), (label == k).reshape(h, w), rms[k], count))
    return out


def _extract_ransac(grid: SampleGrid, cfg: BackgroundConfig) -> list[PlaneSegment]:
    import cv2
    import open3d as o3d

    h, w = grid.shape
    flat_valid = np.flatnonzero(grid.valid.reshape(-1))
    pts = grid.points_cam.reshape(-1, 3)
    remaining = flat_valid
    out: list[PlaneSegment] = []
    rng_seed = 0
    o3d.utility.random.seed(rng_seed)
    for _ in range(cfg.ransac_max_planes):
        if len(remaining) < cfg.ransac_min_points:
            break
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts[remaining]))
        mean_z = float(pts[remaining, 2].mean())
        _, inliers = cloud.segment_plane(
            distance_threshold=cfg.inlier_m * max(mean_z, 1.0) / 2.0,
            ransac_n=3,
            num_iterations=cfg.ransac_iterations,
        )
        inl = np.asarray(inliers, dtype=np.int64)
        if len(inl) < cfg.ransac_min_points:
            break
        mask = np.zeros(h * w, bool)
        mask[remaining[inl]] = True
        remaining = np.delete(remaining, inl)
        # one plane model may cover several surfaces: split its inliers by image connectivity
        ncomp, comp = cv2.connectedComponents(mask.reshape(h, w).astype(np.uint8), connectivity=8)
        for k in range(1, ncomp):
            part = comp == k
            count = int(part.sum())
            if count < cfg.ransac_min_points // 3:
                continue
            p = grid.points_cam[part]
            normal, d, evals = _fit_from_moments(np.array(float(count)), p.sum(axis=0), p.T @ p)
            out.append(PlaneSegment(np.append(normal, d), part, float(np.sqrt(evals[0])), count))
    return out


def extract_planes(depth_m: NDArray[np.float32], camera: CameraIntrinsics,
                   cfg: BackgroundConfig) -> tuple[SampleGrid, list[PlaneSegment]]:
    """The planes of one depth image by ``cfg.method``, with the sample grid they refer to."""
    if cfg.method == "ransac":
        grid = sample_grid(depth_m, camera, cfg.ransac_stride_px, cfg.min_depth_m, cfg.max_depth_m)
        return grid, _extract_ransac(grid, cfg)
    grid = sample_grid(depth_m, camera, cfg.stride_px, cfg.min_depth_m, cfg.max_depth_m)
    return grid, _extract_fast(grid, cfg)
