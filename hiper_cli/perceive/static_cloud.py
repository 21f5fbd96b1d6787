"""The place's cloud keeps what stands still: of the depth returns a session adds to it, only
the voxels it did not see through more often than it saw them.

The place's background cloud (``session_align.MapCloudGrower``, stored by
``graph/mapcloud.py``) is what a later session is aligned to and what tells it where the
earlier sessions saw free space (``graph.history.FreeBefore``: an object found where the
cloud holds nothing inside its box is an addition). Every depth return going in would put
into it the people who walked through and the flying pixels of a real depth camera (returns
between a near edge and the wall behind it, in mid-air): one stray point inside a box makes a
later addition look like an object that stood there all along.

So a session's new voxel goes in unless its views saw through it at least as often as they
saw it (hit it, or measured a return at its depth). A view sees through a voxel when the depth
its pixel block measured lies beyond it by more than ``THROUGH_M`` plus three times the depth
noise at that range (``NOISE_PER_M2`` · z², structured-light noise growing with the square of
the range): a flying pixel in mid-air is seen through from the next view, a person once the
robot looks there again after they left. Each view's depth is kept as the nearest return of
each ``PIXEL_STRIDE`` block, so a voxel is seen through only when the whole block lies beyond
it: an edge, where a block mixes a near surface and the wall behind it, does not carve the
near surface away. Voxels the earlier sessions stored keep their centroid (the map frame is
the first session's); one goes only when this session saw through it in at least
``EARLIER_THROUGH`` views and more often than it saw it: a chair moved or taken away leaves
the place's cloud, so the next session finds its space free as it was last seen
(``FreeBefore``), not as the first session saw it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.align import MAX_DEPTH_M, PIXEL_STRIDE, VOXEL_M, _unique_rows
from hiper_cli.types import CameraIntrinsics, Frame

__all__ = ["EARLIER_THROUGH", "NOISE_PER_M2", "THROUGH_M", "StaticCloud"]

FloatArray = NDArray[np.float64]

THROUGH_M = 0.15  # a block's nearest return this far beyond a voxel (plus the noise) saw through it
NOISE_PER_M2 = 0.0017  # depth noise (1 sigma) per squared metre of range
MIN_DEPTH_M = 0.2
MAX_VIEWS = 1200  # views kept for the carving; beyond, every other one is let go
EARLIER_THROUGH = 2  # an earlier session's voxel goes when seen through in this many views or more


class _View:
    """One view kept for the carving: the nearest return per pixel block, its pose, its camera."""

    def __init__(self, nearest_m: NDArray[np.float32], T_map_cam: FloatArray,
                 camera: CameraIntrinsics) -> None:
        self.nearest_m, self.T_cam_map, self.camera = nearest_m, np.linalg.inv(T_map_cam), camera

    def measure(self, points_map: FloatArray) -> tuple[NDArray[np.bool_], FloatArray, FloatArray]:
        """(in view with a return, depth of the points along the optical axis, the nearest
        return of their pixel block)."""
        T = self.T_cam_map
        p = points_map @ T[:3, :3].T + T[:3, 3]
        z = p[:, 2]
        cam = self.camera
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.floor((cam.fx * p[:, 0] / z + cam.cx) / PIXEL_STRIDE)
            v = np.floor((cam.fy * p[:, 1] / z + cam.cy) / PIXEL_STRIDE)
        rows, cols = self.nearest_m.shape
        ok = (z > MIN_DEPTH_M) & (u >= 0) & (u < cols) & (v >= 0) & (v < rows)
        measured = np.zeros(len(p))
        measured[ok] = self.nearest_m[v[ok].astype(int), u[ok].astype(int)]
        ok &= measured > 0
        return ok, z, measured


def _nearest_blocks(depth_m: NDArray[np.float32]) -> NDArray[np.float32]:
    """The nearest valid return of each ``PIXEL_STRIDE`` × ``PIXEL_STRIDE`` block (0: none)."""
    s = PIXEL_STRIDE
    h, w = (depth_m.shape[0] // s) * s, (depth_m.shape[1] // s) * s
    d = np.where(depth_m[:h, :w] > MIN_DEPTH_M, depth_m[:h, :w], np.inf).astype(np.float32)
    nearest = d.reshape(h // s, s, w // s, s).min(axis=(1, 3))
    return np.where(np.isfinite(nearest), nearest, 0.0).astype(np.float32)


class StaticCloud:
    """A voxel cloud (centroids, map frame, ``voxel_m`` voxels) of the earlier sessions' points
    plus this session's views, of which ``points`` keeps the voxels that stand still (see the
    module docstring)."""

    def __init__(self, earlier_m: FloatArray | None = None, voxel_m: float = VOXEL_M) -> None:
        self.voxel_m = voxel_m
        self._sum: dict[tuple[int, int, int], list[float]] = {}  # x, y, z sums of the voxel's points
        self._n: dict[tuple[int, int, int], int] = {}
        self._views_hit: dict[tuple[int, int, int], int] = {}  # this session's views that hit it
        self._earlier: set[tuple[int, int, int]] = set()
        self._views: list[_View] = []
        if earlier_m is not None and len(earlier_m):
            self._earlier = self._add(np.asarray(earlier_m, dtype=np.float64), count_view=False)

    def _add(self, points: FloatArray, *, count_view: bool) -> set[tuple[int, int, int]]:
        keys = np.floor(points / self.voxel_m).astype(np.int64)
        uniq, inverse = _unique_rows(keys)
        # per voxel, the sums of its points in input order (as ``np.add.at``), one pass per axis
        sums = np.stack([np.bincount(inverse, weights=points[:, k], minlength=len(uniq)) for k in range(3)],
                        axis=1)
        counts = np.bincount(inverse, minlength=len(uniq))
        out = set()
        for key, s, n in zip(map(tuple, uniq.tolist()), sums.tolist(), counts.tolist(), strict=True):
            out.add(key)
            if count_view:
                self._views_hit[key] = self._views_hit.get(key, 0) + 1
                if key in self._earlier:
                    # the map frame is the first session's: a later session, aligned with its
                    # own error and drifting its own way, adds new space but does not pull the map
                    continue
            old = self._sum.get(key)
            self._sum[key] = s if old is None else [old[0] + s[0], old[1] + s[1], old[2] + s[2]]
            self._n[key] = self._n.get(key, 0) + n
        return out

    def add_frame(self, frame: Frame) -> None:
        """The frame's depth returns (every ``PIXEL_STRIDE``-th pixel, up to ``MAX_DEPTH_M``,
        map frame) and the view, for the carving."""
        s = PIXEL_STRIDE
        depth = frame.depth_m[::s, ::s].astype(np.float64)
        cam = frame.camera
        v, u = np.mgrid[0:frame.depth_m.shape[0]:s, 0:frame.depth_m.shape[1]:s]
        ok = (depth > MIN_DEPTH_M) & (depth < MAX_DEPTH_M)
        z = depth[ok]
        pts = np.stack([(u[ok] - cam.cx) / cam.fx * z, (v[ok] - cam.cy) / cam.fy * z, z], axis=1)
        T = np.asarray(frame.T_map_cam, dtype=np.float64)
        if len(pts):
            self._add(pts @ T[:3, :3].T + T[:3, 3], count_view=True)
        if len(self._views) >= MAX_VIEWS:
            self._views = self._views[::2]
        self._views.append(_View(_nearest_blocks(frame.depth_m), T, cam))

    def __len__(self) -> int:
        return len(self._sum)

    def points(self) -> FloatArray:
        """The earlier sessions' voxels this session did not see gone, and this session's that
        stand still (centroids)."""
        if not self._sum:
            return np.zeros((0, 3))
        keys = list(self._sum)
        centroids = np.array([self._sum[k] for k in keys]) / np.array([self._n[k] for k in keys])[:, None]
        new = np.array([k not in self._earlier for k in keys])
        hits = np.array([self._views_hit.get(k, 0) for k in keys])
        through = np.zeros(len(keys), dtype=np.int64)
        seen = np.zeros(len(keys), dtype=np.int64)
        for view in self._views:
            ok, z, measured = view.measure(centroids)
            margin = THROUGH_M + 3.0 * NOISE_PER_M2 * z * z
            through += ok & (measured > z + margin)
            seen += ok & (np.abs(measured - z) <= margin)
        saw = np.maximum(seen, hits)
        keep = np.where(new, through < saw, (through < EARLIER_THROUGH) | (through <= saw))
        kept: FloatArray = centroids[keep]
        return kept
