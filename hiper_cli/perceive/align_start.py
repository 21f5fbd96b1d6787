"""Refining a session's alignment where drift is smallest: the log's first metres.

A pose source drifts with motion (a visual odometry front end: some 0.5 % of the distance and
0.1°/m), in every session, the map's own included. Registering a whole log to the map averages
the drift of both and is off by a decimetre and a degree at the log's start; its first metres
have barely drifted, and a robot that starts a session where it started the last (a dock) sees
there the map's least drifted part too. So the whole-log transform is refined by point-to-plane
ICP of the first metres' cloud against the map, with a Cauchy kernel (people, moved objects).

A start that shows little (a floor and one wall) leaves some directions unconstrained, and ICP
slides along them. The Gauss-Newton normal matrix (rotation about the cloud's centre, scaled
by its radius, so its eigenvalues compare with the translations') says which directions the
start constrains: each step moves only along those whose eigenvalue, a share of the weighted
points, is at least ``MIN_CONSTRAINT``; along the others the whole-log transform stays. A floor
fixes height, roll and pitch, a wall yaw and its normal's offset.

Each gate iterates until a step moves the fit less than ``CONVERGED``: from a whole-log fit a
decimetre and half a degree off, the fine gate creeps for some 40 iterations (nearest voxel
centroids change as it goes), and a fit stopped early keeps part of the whole log's error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.logs.trajectory import rotation_about

__all__ = ["MIN_CONSTRAINT", "MapSurface", "StartFit", "refine", "refine_at_start"]

FloatArray = NDArray[np.float64]

MIN_CONSTRAINT = 0.03  # eigenvalue share of the weighted points under which a direction is left alone
KERNEL_M = 0.03  # Cauchy scale of the point-to-plane residuals
DISTANCES_M = (0.2, 0.1, 0.05)  # correspondence gates, coarse to fine
ITERATIONS = 100  # per gate at most; a gate ends when a step moves less than ``CONVERGED``
CONVERGED = 1e-4  # metres, radians: a step this small moves no point of a room by a millimetre
NORMAL_NEIGHBOURS = 12
MAX_CURVATURE = 0.1  # map points whose neighbourhood is not planar give no normal


@dataclass(frozen=True)
class StartFit:
    """The refined ``T_map_log``; ``constrained``: how many of the 6 directions the start fixed
    (the rest kept the whole-log value); ``inliers``: share of the start's points within the
    last gate; ``rmse_m``: their weighted point-to-plane residual."""

    T_map_log: FloatArray
    constrained: int
    inliers: float
    rmse_m: float


def _normals(points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per point: the unit normal of its neighbourhood and how far from planar it is."""
    from scipy.spatial import cKDTree

    k = min(NORMAL_NEIGHBOURS, len(points))
    _, nn = cKDTree(points).query(points, k)
    nb = points[nn] - points[nn].mean(axis=1, keepdims=True)
    eigval, eigvec = np.linalg.eigh(np.einsum("nki,nkj->nij", nb, nb))
    return eigvec[:, :, 0], eigval[:, 0] / np.maximum(eigval.sum(axis=1), 1e-12)


def _step(p: FloatArray, q: FloatArray, n: FloatArray) -> tuple[FloatArray, int, float]:
    """One Gauss-Newton step (4x4, applied on the left) in the constrained directions."""
    centre = p.mean(axis=0)
    radius = max(float(np.sqrt(((p - centre) ** 2).sum(axis=1).mean())), 1e-6)
    r = ((p - q) * n).sum(axis=1)
    w = 1.0 / (1.0 + (r / KERNEL_M) ** 2)
    J = np.hstack([np.cross(p - centre, n) / radius, n])
    H = (J * w[:, None]).T @ J / w.sum()
    g = (J * w[:, None]).T @ r / w.sum()
    eigval, eigvec = np.linalg.eigh(H)
    keep = eigval >= MIN_CONSTRAINT
    x = -(eigvec[:, keep] @ ((eigvec[:, keep].T @ g) / eigval[keep]))
    R = rotation_about(x[:3] / radius)
    D = np.eye(4)
    D[:3, :3] = R
    D[:3, 3] = centre - R @ centre + x[3:]
    return D, int(keep.sum()), float(np.sqrt((w * r * r).sum() / w.sum()))


class MapSurface:
    """The map's points with their normals, planarity and a search tree: built once, for the
    start's fit and for every segment of a path (``perceive.align_path``)."""

    def __init__(self, map_points: FloatArray) -> None:
        from scipy.spatial import cKDTree

        self.points = np.asarray(map_points, dtype=np.float64)
        self.normals, self.curvature = _normals(self.points)
        self.tree = cKDTree(self.points)


def refine(points: FloatArray, surface: MapSurface, T0: FloatArray) -> StartFit:
    """``T0`` refined on ``points`` (log frame) against the map's surface, in the directions
    they constrain (see the module docstring)."""
    T = np.asarray(T0, dtype=np.float64).copy()
    constrained, inliers, rmse = 0, 0.0, float("inf")
    for gate in DISTANCES_M:
        for _ in range(ITERATIONS):
            p = points @ T[:3, :3].T + T[:3, 3]
            d, j = surface.tree.query(p, distance_upper_bound=gate)
            ok = np.isfinite(d)
            ok[ok] = surface.curvature[j[ok]] < MAX_CURVATURE
            inliers = float(ok.mean()) if len(ok) else 0.0
            if ok.sum() < 20:
                return StartFit(np.asarray(T0, dtype=np.float64), 0, inliers, rmse)
            D, constrained, rmse = _step(p[ok], surface.points[j[ok]], surface.normals[j[ok]])
            T = D @ T
            if np.abs(D - np.eye(4)).max() < CONVERGED:
                break
    return StartFit(T, constrained, inliers, rmse)


def refine_at_start(start_points: FloatArray, map_points: FloatArray, T0: FloatArray) -> StartFit:
    """``T0`` (the whole log's registration) refined on the start's cloud (log frame) against
    the map (see the module docstring)."""
    return refine(start_points, MapSurface(map_points), T0)
