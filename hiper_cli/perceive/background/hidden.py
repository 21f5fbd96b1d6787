"""Where a table top goes on behind what stands in front of it.

A desk seen past a chair's back, or with bottles standing across it, shows its top in pieces:
each view sees the part on one side of the occluder, and two pieces 0.1-0.25 m apart never
meet within Algorithm 2's contour margin. What lies between them is not free space: the camera
saw something nearer there, so the top may go on behind it. Two desks that stand apart show
the opposite: through the gap the camera sees past the plane (the floor, a desk's side).

``hidden_points`` returns, for one top seen in one image, the points of its plane within
``table_bridge_m`` of its seen edge where it may go on: samples around the segment that lie on
the plane but were left out of it (the strips between bottles), and samples nearer than the
plane on their viewing ray (what hid it), moved along the ray onto it. Merging takes them as
evidence of the plane when it tests whether a top continues a known one (``merge._matches``),
and fills with them the gap between the two pieces it joins (``merge.merge_into``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.planes import PlaneSegment, SampleGrid
from hiper_cli.types import CameraIntrinsics

__all__ = ["hidden_points"]

FloatArray = NDArray[np.float64]
MAX_POINTS = 160  # kept per observation, evenly spaced (they go into the knowledge base)
MAX_RADIUS_SAMPLES = 48  # the band around the segment, in grid samples, at most


def hidden_points(grid: SampleGrid, camera: CameraIntrinsics, seg: PlaneSegment,
                  cfg: BackgroundConfig) -> FloatArray:
    """(K, 3) camera-frame points on ``seg``'s plane, within ``cfg.table_bridge_m`` of its
    samples, where the top may go on in this image (K may be 0): samples on the plane that the
    segment left out (cut off by what stands on the top) and samples in front of it (what hid
    the top there, moved along their ray onto it), joined to the segment in the image through
    such samples. A sample seen past the plane (the floor through a gap) joins nothing."""
    import cv2
    from scipy.spatial import cKDTree

    reach_m = cfg.table_bridge_m
    mask = seg.mask
    if reach_m <= 0 or not mask.any():
        return np.zeros((0, 3))
    n, d = np.asarray(seg.plane_cam[:3], dtype=np.float64), float(seg.plane_cam[3])
    seen = grid.points_cam[mask]
    near_z = max(float(seen[:, 2].min()), cfg.min_depth_m)
    radius = min(int(np.ceil(camera.fx * reach_m / near_z / grid.stride)), MAX_RADIUS_SAMPLES)
    size = 2 * max(radius, 1) + 1
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))
    band = (cv2.dilate(mask.astype(np.uint8), disc) > 0) & ~mask & grid.valid
    p = grid.points_cam
    rays = p / np.where(grid.valid, p[..., 2], 1.0)[..., None]  # through each sample, z = 1
    denom = rays @ n
    ahead = denom < -1e-6  # the ray meets the plane ahead of the camera ...
    plane_z = np.where(ahead, -d / np.where(ahead, denom, -1.0), np.inf)
    ahead &= plane_z < cfg.max_depth_m  # ... within the depth range
    tol = 2.0 * cfg.inlier_m * np.maximum(p[..., 2], 1.0)
    on = band & ahead & (np.abs(p[..., 2] - plane_z) <= tol)
    front = band & ahead & (p[..., 2] < plane_z - tol)  # nearer than the plane on its ray
    _, labels = cv2.connectedComponents((mask | on | front).astype(np.uint8), connectivity=8)
    joined = np.isin(labels, np.unique(labels[mask])) & (on | front)
    if not joined.any():
        return np.zeros((0, 3))
    on_plane = rays[joined] * plane_z[joined][:, None]
    near = cKDTree(seen).query(on_plane, distance_upper_bound=reach_m)[0] <= reach_m
    out = on_plane[near]
    if len(out) > MAX_POINTS:
        out = out[np.linspace(0, len(out) - 1, MAX_POINTS).astype(int)]
    return np.asarray(out)
