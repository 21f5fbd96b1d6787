"""Whether a blob shows a whole, solid object (evidence for an ``unknown`` instance).

An unmatched blob is a lasting object only if the camera saw all of it: a blob touching the
image's edge is cut there (a shelf, a wall or a floor remnant seen through the border), one
longer than ``unknown_max_extent_m`` is structure or several things, and a flat one (its
points within a centimetre or two of one plane, beyond the depth noise) is a piece of a
surface the background did not claim: a wall, a floor, a furniture side.

A blob inside the image may still be cut by something nearer: a bed seen through a doorway, a
couch behind a chair (``occluded``). Its outline then borders nearer surfaces; an object seen
whole borders only farther ones, or what it stands on. A blob whose top borders a nearer
surface (a chair's seat under a desk's top) does not show how tall its object is
(``top_hidden``); one whose bottom borders a nearer surface (the back of a chair behind a table,
above the table's top) does not show where its object stands (``bottom_hidden``). For the
evidence of an ``unknown`` object, ``base_occluded`` tells that apart from the floor or table top
it stands on, which at a grazing angle is also nearer than its base.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.background_filter import BACKGROUND_MARGIN_PER_M2
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.types import CameraIntrinsics

__all__ = [
    "base_occluded",
    "bottom_hidden",
    "in_full_view",
    "inside_image",
    "occluded",
    "seen_whole",
    "thickness_m",
    "top_hidden",
]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
UNKNOWN_MAX_EXTENT_M: float = 1.0
"""An unmatched blob is seen *whole* (``whole.py``: evidence for an ``unknown`` instance)
only when inside the image (not within one ``pixel_step`` of its edge: a shelf, a wall or a
floor remnant cut by the border is a piece of something larger), no longer than this ..."""
UNKNOWN_MIN_THICKNESS_M: float = 0.01
"""... and not flat: the thinnest spread σ of its points at least this plus
``background_margin_per_m2`` · depth² (a flat blob is a piece of a wall, a floor or a
furniture side the background did not claim)."""
FULL_VIEW_MIN_PX2: float = 1024.0
"""... where a full view's image box covers at least this many pixels (32 x 32; smaller, a
detector may miss what it names up close) ..."""
FULL_VIEW_COVER: float = 0.5
"""... and a full view counts for every class of a detection lying (this share of its box's
area) inside the blob's image box, named for the blob or not (``match.named_within``): a
bottle joined with the cup beside it in one blob was still named a bottle."""

OCCLUDER_MARGIN_M = 0.15  # a surface this much nearer than the blob beside it stands in front
OCCLUDER_RING_CELLS = 2  # ... within this many samples of the blob's outline
OCCLUDED_SHARE = 0.1  # a blob whose outline borders occluders for this share of it is cut
TOP_HIDDEN_SHARE = 0.5  # a blob whose top borders occluders in this share of its columns


def thickness_m(points: np.ndarray) -> float:
    """The spread (σ, m) of ``points`` (N, 3) along their thinnest direction."""
    if len(points) < 4:
        return 0.0
    centred = points - points.mean(axis=0)
    cov = centred.T @ centred / len(points)
    return float(np.sqrt(max(float(np.linalg.eigvalsh(cov)[0]), 0.0)))


def inside_image(blob: Blob, pixel_step: int, camera: CameraIntrinsics) -> bool:
    """Whether ``blob``'s image box keeps more than one ``pixel_step`` from the image's edges:
    a blob reaching the border is cut there and shows only a part of its object."""
    x0, y0, x1, y1 = (float(v) for v in blob.image_box_xyxy)
    edge = pixel_step
    return not (x0 <= edge or y0 <= edge or x1 >= camera.width - edge or y1 >= camera.height - edge)


def seen_whole(
    blob: Blob, config: ForegroundConfig, camera: CameraIntrinsics,
    view: tuple[NDArray[np.float32], NDArray[np.float64]] | None = None,
) -> bool | None:
    """Whether ``blob`` lies inside the image, is compact and is not flat. Given the frame's
    ``view`` (depth image, camera pose), None when the camera did not see where it stands
    (``base_occluded``): the view tells neither way (the top of a box stack seen over a nearer
    one may be a whole thing or a part; a plant seen behind a chair is whole elsewhere)."""
    if not inside_image(blob, config.pixel_step, camera):
        return False
    if float(np.max(blob.extent_map_m)) > UNKNOWN_MAX_EXTENT_M:
        return False
    depth = float(np.median(blob.points_cam[:, 2]))
    flat_m = UNKNOWN_MIN_THICKNESS_M + BACKGROUND_MARGIN_PER_M2 * depth * depth
    if thickness_m(blob.points_cam) < flat_m:
        return False
    if view is not None and base_occluded(blob, view[0], camera, view[1], config.pixel_step):
        return None
    return True


def occluded(
    blob: Blob, depth_m: NDArray[np.float32], camera: CameraIntrinsics, T_map_cam: NDArray[np.float64],
    pixel_step: int,
) -> bool:
    """Whether something nearer hides a part of ``blob``: of the samples around its outline
    (within ``OCCLUDER_RING_CELLS`` samples), at least ``OCCLUDED_SHARE`` are more than
    ``OCCLUDER_MARGIN_M`` nearer than the blob beside them and lie above the blob's base (what
    an object stands on lies below it and in front of it, and hides nothing)."""
    from scipy.ndimage import binary_dilation, minimum_filter

    step, off = pixel_step, pixel_step // 2
    grid = blob.pixels_uv // step
    reach = OCCLUDER_RING_CELLS
    lo = np.maximum(grid.min(axis=0) - reach, 0)
    n_u, n_v = (camera.width - off + step - 1) // step, (camera.height - off + step - 1) // step
    hi = np.minimum(grid.max(axis=0) + reach + 1, [n_u, n_v])
    shape = (int(hi[1] - lo[1]), int(hi[0] - lo[0]))
    mask = np.zeros(shape, dtype=bool)
    mask[grid[:, 1] - lo[1], grid[:, 0] - lo[0]] = True
    vs = off + step * np.arange(lo[1], hi[1])
    us = off + step * np.arange(lo[0], hi[0])
    z = depth_m[np.ix_(vs, us)].astype(np.float64)
    ring = binary_dilation(mask, iterations=reach) & ~mask
    if not ring.any():
        return False
    beside = minimum_filter(np.where(mask, z, np.inf), size=2 * reach + 1)
    nearer = ring & (z > 0) & (z < beside - OCCLUDER_MARGIN_M)
    if nearer.any():
        rows, cols = np.nonzero(nearer)
        zz = z[rows, cols]
        x = (us[cols] - camera.cx) / camera.fx * zz
        y = (vs[rows] - camera.cy) / camera.fy * zz
        height = T_map_cam[2, :3] @ np.stack([x, y, zz]) + T_map_cam[2, 3]
        base = float(blob.bounds_map[0][2])
        nearer[rows, cols] = height > base + OCCLUDER_MARGIN_M
    return bool(nearer.sum() >= OCCLUDED_SHARE * ring.sum())


def in_full_view(
    blob: Blob, depth_m: NDArray[np.float32], camera: CameraIntrinsics, T_map_cam: NDArray[np.float64],
    pixel_step: int, min_area_px2: float,
) -> bool:
    """Whether ``blob`` showed its whole object, large enough for a detector to name it: inside
    the image, its image box at least ``min_area_px2`` in area, not hidden in part by something
    nearer around it (``occluded``), above it or below it (``top_hidden``, ``bottom_hidden``: the
    back of a chair over the table's top in front is a part). A view a detector declines to
    name then counts against a class it gave the object elsewhere (``class_vote``)."""
    x0, y0, x1, y1 = (float(v) for v in blob.image_box_xyxy)
    if (x1 - x0) * (y1 - y0) < min_area_px2 or not inside_image(blob, pixel_step, camera):
        return False
    return not (
        top_hidden(blob, depth_m, pixel_step)
        or bottom_hidden(blob, depth_m, pixel_step)
        or occluded(blob, depth_m, camera, T_map_cam, pixel_step)  # the costliest last
    )


def top_hidden(blob: Blob, depth_m: NDArray[np.float32], pixel_step: int) -> bool:
    """Whether the camera did not see how high ``blob``'s object reaches: the blob reaches the
    image's top edge, or the image rows just above its box (``OCCLUDER_RING_CELLS`` samples)
    show, in ``TOP_HIDDEN_SHARE`` of its columns, something more than ``OCCLUDER_MARGIN_M``
    nearer than the blob (a desk's top over the seat of the chair behind it)."""
    step = pixel_step
    x0, y0, x1, _ = (int(v) for v in blob.image_box_xyxy)
    if y0 <= step:
        return True
    rows = depth_m[max(y0 - step * OCCLUDER_RING_CELLS, 0):y0, x0:max(x1, x0 + 1):step].astype(np.float64)
    if rows.size == 0:
        return False
    return _nearer_across(rows, float(np.median(blob.points_cam[:, 2])) - OCCLUDER_MARGIN_M)


def bottom_hidden(blob: Blob, depth_m: NDArray[np.float32], pixel_step: int) -> bool:
    """Whether the camera did not see where ``blob``'s object stands: the blob reaches the image's
    bottom edge, or the image rows just below its box (``OCCLUDER_RING_CELLS`` samples) show, in
    ``TOP_HIDDEN_SHARE`` of its columns, something more than ``OCCLUDER_MARGIN_M`` nearer than the
    blob's lowest samples (a table's top in front of the back of the chair behind it). What
    an object stands on meets its base at the base's depth, and hides nothing."""
    below = _below(blob, depth_m, pixel_step)
    if below is None:
        return True
    _, _, z, base_m = below
    return z.size > 0 and _nearer_across(z, base_m - OCCLUDER_MARGIN_M)


def _below(
    blob: Blob, depth_m: NDArray[np.float32], pixel_step: int,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], float] | None:
    """The image rows just below ``blob``'s box (``OCCLUDER_RING_CELLS`` samples) at every
    ``pixel_step``-th column of it: their row and column indices, their depth (m; 0: no return),
    and the depth of the blob's lowest samples; None when the box reaches the image's bottom."""
    step, reach = pixel_step, pixel_step * OCCLUDER_RING_CELLS
    x0, _, x1, y1 = (int(v) for v in blob.image_box_xyxy)
    height = depth_m.shape[0]
    if y1 >= height - step:
        return None
    vs = np.arange(y1, min(y1 + reach, height))
    us = np.arange(x0, max(x1, x0 + 1), step)
    v = blob.pixels_uv[:, 1]
    base_m = float(np.median(blob.points_cam[v >= v.max() - reach, 2]))
    return vs, us, depth_m[np.ix_(vs, us)].astype(np.float64), base_m


def base_occluded(
    blob: Blob, depth_m: NDArray[np.float32], camera: CameraIntrinsics, T_map_cam: NDArray[np.float64],
    pixel_step: int,
) -> bool:
    """Whether something nearer stands in front of ``blob``'s base: in ``TOP_HIDDEN_SHARE`` of
    the columns just below its box, a return more than ``OCCLUDER_MARGIN_M`` nearer than its
    lowest samples that is no surface it could stand on: higher than its base, or seen from
    below (above the camera). Unlike ``bottom_hidden``, the floor or a table top in front of
    an object, nearer by more than the margin at a grazing angle, hides nothing."""
    below = _below(blob, depth_m, pixel_step)
    if below is None:
        return True
    vs, us, z, base_m = below
    nearer = (z > 0) & (z < base_m - OCCLUDER_MARGIN_M)
    if not nearer.any():
        return False
    rows, cols = np.nonzero(nearer)
    zz = z[rows, cols]
    rays = np.stack([(us[cols] - camera.cx) / camera.fx * zz, (vs[rows] - camera.cy) / camera.fy * zz, zz])
    up_m = T_map_cam[2, :3] @ rays + T_map_cam[2, 3]
    base_up_m = float(blob.bounds_map[0][2])
    nearer[rows, cols] = (up_m > base_up_m + OCCLUDER_MARGIN_M) | (up_m > T_map_cam[2, 3])
    return bool(nearer.any(axis=0).mean() >= TOP_HIDDEN_SHARE)


def _nearer_across(rows: NDArray[np.float64], limit_m: float) -> bool:
    """Whether image ``rows`` (depth, m; 0: no return) show a return nearer than ``limit_m`` in
    ``TOP_HIDDEN_SHARE`` of their columns."""
    nearer = ((rows > 0) & (rows < limit_m)).any(axis=0)
    return bool(nearer.mean() >= TOP_HIDDEN_SHARE)
