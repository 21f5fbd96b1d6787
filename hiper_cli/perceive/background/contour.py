"""Plane geometry: transforms, in-plane bases, contours as polygons in the plane (shapely).

A contour is stored as a (K, 3) ring of points on its plane (first point not repeated). For
merging, rings are projected into a 2D basis of a plane and handled as shapely polygons.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.types import CameraIntrinsics

__all__ = [
    "PlaneFrame",
    "contour_from_mask",
    "plane_frame",
    "polygon_area_m2",
    "sample_ring",
    "to_polygon",
    "to_ring",
    "transform_plane",
    "transform_points",
]

FloatArray = NDArray[np.float64]


def transform_plane(plane_a: FloatArray, T_b_a: FloatArray) -> FloatArray:
    """The plane [n, d] given in frame a, expressed in frame b."""
    n_b = T_b_a[:3, :3] @ np.asarray(plane_a[:3], dtype=np.float64)
    return np.append(n_b, float(plane_a[3]) - float(n_b @ T_b_a[:3, 3]))


def transform_points(points_a: FloatArray, T_b_a: FloatArray) -> FloatArray:
    pts = np.asarray(points_a, dtype=np.float64).reshape(-1, 3)
    return np.asarray(pts @ T_b_a[:3, :3].T + T_b_a[:3, 3])


class PlaneFrame:
    """An orthonormal frame on a plane: ``origin`` on it, in-plane axes ``u``, ``v``, ``normal``.

    For a near-horizontal plane ``u`` follows the x axis; otherwise ``u`` is horizontal
    (z × n) and ``v`` points up as much as it can, so wall polygons are (along, height).
    """

    def __init__(self, plane: FloatArray) -> None:
        n = np.asarray(plane[:3], dtype=np.float64)
        n = n / np.linalg.norm(n)
        self.normal = n
        self.d = float(plane[3]) / float(np.linalg.norm(plane[:3]))
        self.origin = -self.d * n
        if abs(n[2]) > 0.9:
            u = np.array([1.0, 0.0, 0.0]) - n[0] * n
        else:
            u = np.cross(np.array([0.0, 0.0, 1.0]), n)
        self.u = u / np.linalg.norm(u)
        self.v = np.cross(n, self.u)

    @property
    def R(self) -> FloatArray:
        """Columns u, v, normal."""
        return np.stack([self.u, self.v, self.normal], axis=1)

    def to_2d(self, points: FloatArray) -> FloatArray:
        rel = np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.origin
        return np.stack([rel @ self.u, rel @ self.v], axis=1)

    def to_3d(self, uv: FloatArray) -> FloatArray:
        uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        return np.asarray(self.origin + uv[:, :1] * self.u + uv[:, 1:2] * self.v)


def plane_frame(plane: FloatArray) -> PlaneFrame:
    return PlaneFrame(plane)


def to_polygon(ring: FloatArray, frame: PlaneFrame) -> Any:
    """The shapely polygon of a (K, 3) ring projected into ``frame`` (valid, maybe empty)."""
    from shapely.geometry import Polygon

    pts = frame.to_2d(ring)
    if len(pts) < 3:
        return Polygon()
    poly = Polygon(pts)
    if not poly.is_valid:
        poly = poly.buffer(0)
    return poly


def to_ring(polygon: Any, frame: PlaneFrame) -> FloatArray:
    """The (K, 3) exterior ring of a polygon (the largest part of a multi-polygon)."""
    if polygon.is_empty:
        return np.zeros((0, 3))
    if polygon.geom_type != "Polygon":
        parts = list(getattr(polygon, "geoms", []))
        polys = [p for p in parts if p.geom_type == "Polygon"]
        if not polys:
            return np.zeros((0, 3))
        polygon = max(polys, key=lambda p: p.area)
    xy = np.asarray(polygon.exterior.coords)[:-1]
    return frame.to_3d(xy)


def polygon_area_m2(ring: FloatArray, frame: PlaneFrame) -> float:
    return float(to_polygon(ring, frame).area)


def sample_ring(ring: FloatArray, spacing_m: float) -> FloatArray:
    """Points every ``spacing_m`` along a closed (K, 3) ring."""
    ring = np.asarray(ring, dtype=np.float64).reshape(-1, 3)
    if len(ring) < 2:
        return ring
    out = []
    for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True):
        steps = max(int(np.ceil(np.linalg.norm(b - a) / spacing_m)), 1)
        t = np.arange(steps)[:, None] / steps
        out.append(a + t * (b - a))
    return np.concatenate(out)


def contour_from_mask(mask: NDArray[np.bool_], stride: int, camera: CameraIntrinsics,
                      plane_cam: FloatArray, epsilon_px: float,
                      points_cam: FloatArray | None = None) -> FloatArray:
    """The outer contour (K, 3) of the largest blob of a sample mask, on ``plane_cam``.

    The blob outline is traced in the image (OpenCV) and simplified by ``epsilon_px`` samples.
    A vertex on an inlier sample is that sample projected onto the plane (``points_cam``,
    (h, w, 3)); any other vertex is where its viewing ray meets the plane.
    """
    import cv2

    m = cv2.morphologyEx(mask.astype(np.uint8), cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    contours, _ = cv2.findContours(m, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return np.zeros((0, 3))
    largest = max(contours, key=cv2.contourArea)
    largest = cv2.approxPolyDP(largest, epsilon_px, True)
    ij = largest.reshape(-1, 2)
    px = ij.astype(np.float64) * stride
    rays = np.stack(
        [(px[:, 0] - camera.cx) / camera.fx, (px[:, 1] - camera.cy) / camera.fy, np.ones(len(px))], axis=1
    )
    n = np.asarray(plane_cam[:3], dtype=np.float64)
    denom = rays @ n
    ok = np.abs(denom) > 1e-6
    t = -float(plane_cam[3]) / np.where(ok, denom, 1.0)
    ok &= t > 0
    out = rays * t[:, None]
    if points_cam is not None:
        on = mask[ij[:, 1], ij[:, 0]]
        p = points_cam[ij[:, 1], ij[:, 0]]
        projected = p - ((p @ n) + float(plane_cam[3]))[:, None] * n
        out = np.where(on[:, None], projected, out)
        ok |= on
    return np.asarray(out[ok])
