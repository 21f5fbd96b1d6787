"""Tables the foreground finds before the background layer has mapped them.

In the first seconds of a log the background stage may not know a table yet (its top is seen
at a grazing angle, a band of pixels too thin for its plane cells); the Euclidean clustering
then joins the chairs around it, the table and what stands on it into one blob, whose centre
is 0.1-0.5 m off each chair's. ``drop_unseen_tables`` finds such a table in a blob that a
detection names (not furniture with tops of its own: ``unseen_table_skip_classes``): a
horizontal slab at table height, of columns that end there (a person or a chair's back beside
the table rises above it), whose footprint spans ``unseen_table_min_side_m`` along its minor
axis (a chair's back or a shelf board is narrow), on legs (``on_legs``: the top of a cabinet,
a counter or a book cube stands on a solid front and is no table). The slab and the legs under it
(``legs.leg_points``) leave the blob, and what remains is clustered again as the segmentation
does; parts smaller than ``min_cluster_points`` are dropped. A detection of a class with no top
at table height (``unseen_table_lookalikes``: a bench's seat is lower) whose blob holds a table
top named the table, not what remains of the blob. Once the background layer maps the
table, its filter removes the top and ``legs.py`` the legs before this step.

Each frame decides anew: a table remembered once and removed from every blob that reaches it
later would cut the chair backs that cross the top's height (twice the identity switches on the
tuning logs).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.config import RefineConfig, SegmentConfig
from hiper_cli.perceive.foreground.legs import (
    TABLE_LEG_ABOVE_M,
    TABLE_LEG_CELL_M,
    TABLE_LEG_REACH_M,
    leg_points,
    standing_on,
)
from hiper_cli.perceive.foreground.match import iou_matrix
from hiper_cli.perceive.foreground.refine import TRIM_IOU
from hiper_cli.perceive.foreground.segment import Blob, cell_inverse, grid_components, sub_blob

__all__ = [
    "drop_unseen_tables", "on_legs", "one_board", "split_unseen_tables", "table_points", "unseen_table_top",
]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
UNSEEN_TABLE_MIN_SIDE_M: float = 0.3
"""A table the background layer has not mapped yet (its top seen at a grazing angle in the
first seconds) merges the chairs around it into one blob. When such a blob overlaps a
detection (IoU >= ``trim_iou``) and holds a horizontal slab between
``unseen_table_min_height_m`` and ``unseen_table_max_height_m`` whose footprint spans this
much along both map axes, the slab and its legs leave the blob and the rest is clustered
again (``legs.py``, ``refine.py``; 0: off) ..."""
UNSEEN_TABLE_MIN_HEIGHT_M: float = 0.6
UNSEEN_TABLE_MAX_HEIGHT_M: float = 1.2
UNSEEN_TABLE_SKIP_CLASSES: tuple[str, ...] = ("couch", "bed", "dining table", "toilet")
"""... except in blobs matched to these detector classes: furniture with tops of its own (a
couch's arms and back are such a slab) ..."""
UNSEEN_TABLE_LOOKALIKES: tuple[str, ...] = ("bench",)
"""... A detection of these classes (no top at table height: a bench's seat lies below it)
whose blob holds a table top named the table, and names nothing else in that frame
(YOLOX-Nano names a table with things on it ``bench``) ..."""
UNSEEN_TABLE_HOLDING: float = 0.8
"""... and also in a blob that no detection names but that holds a detected object: a
detection box (not of those classes) lies at least this share inside the blob's image box
(a bottle or a cup standing on a table the background has not mapped, a bedside table seen
only from a doorway, joins the table's blob, and no detection names that blob; 0: off)."""

FloatArray = NDArray[np.float64]
SLAB_BIN_M = 0.02  # height bins of the search for a table top
TOP_THICKNESS_M = 0.04


def _column_tops(points_map: FloatArray, cell_m: float) -> FloatArray:
    """For each point (N, 3), the highest point of its horizontal cell (``cell_m`` wide)."""
    inverse = cell_inverse(points_map[:, :2], cell_m)
    tops = np.full(int(inverse.max()) + 1, -np.inf)
    np.maximum.at(tops, inverse, points_map[:, 2])
    return np.asarray(tops[inverse])


def unseen_table_top(points_map: FloatArray, config: SegmentConfig) -> Box3D | None:
    """The top of a table the background layer has not mapped yet, if the points (N, 3) of a
    blob hold one: the most populated horizontal slab between ``unseen_table_min_height_m``
    and ``unseen_table_max_height_m``, of the columns (``table_leg_cell_m`` cells) that end
    there (a person or a chair's back beside the table rises above it), whose footprint spans
    ``unseen_table_min_side_m`` along its minor axis. Its box, 4 cm thick, top at the slab's
    middle."""
    if len(points_map) < config.min_cluster_points:
        return None
    z = points_map[:, 2]
    at_height = (z >= UNSEEN_TABLE_MIN_HEIGHT_M) & (z <= UNSEEN_TABLE_MAX_HEIGHT_M)
    if np.count_nonzero(at_height) < config.min_cluster_points:
        return None  # too few points at table height, whichever columns end there
    reach = 2 * SLAB_BIN_M + TABLE_LEG_ABOVE_M
    ending = _column_tops(points_map, TABLE_LEG_CELL_M) <= z + reach
    sel = np.flatnonzero(at_height & ending)
    if len(sel) < config.min_cluster_points:
        return None
    bins = np.floor(z[sel] / SLAB_BIN_M).astype(np.int64)
    mode = (int(np.argmax(np.bincount(bins - bins.min()))) + int(bins.min()) + 0.5) * SLAB_BIN_M
    slab = sel[np.abs(z[sel] - mode) <= SLAB_BIN_M]
    if len(slab) < config.min_cluster_points:
        return None
    if _minor_extent_m(points_map[slab, :2]) < UNSEEN_TABLE_MIN_SIDE_M:
        return None
    lo, hi = np.percentile(points_map[slab, :2], [5, 95], axis=0)
    top = float(np.median(z[slab]))
    return Box3D(
        np.array([(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, top - TOP_THICKNESS_M / 2.0]),
        np.array([hi[0] - lo[0], hi[1] - lo[1], TOP_THICKNESS_M]),
    )


def _minor_extent_m(points_xy: FloatArray) -> float:
    """The width (5th to 95th percentile) of horizontal points along their minor principal
    axis: a table top is wide both ways, a chair's back or a shelf board is not."""
    centred = points_xy - points_xy.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    along = centred @ vectors[:, 0]  # eigh sorts ascending: the minor axis first
    p5, p95 = np.percentile(along, [5, 95])
    return float(p95 - p5)


def _top_points(points_map: FloatArray, top: Box3D, config: SegmentConfig) -> NDArray[np.bool_]:
    """Which points (N, 3) are the table's top: within its footprint grown by
    ``table_leg_reach_m``, two slab bins of its top height, in columns that end there."""
    lo, hi = top.aabb()
    reach = 2 * SLAB_BIN_M + TABLE_LEG_ABOVE_M
    ending = _column_tops(points_map, TABLE_LEG_CELL_M) <= hi[2] + reach
    return np.asarray(
        np.all(points_map[:, :2] >= lo[:2] - TABLE_LEG_REACH_M, axis=1)
        & np.all(points_map[:, :2] <= hi[:2] + TABLE_LEG_REACH_M, axis=1)
        & (np.abs(points_map[:, 2] - hi[2]) <= 2 * SLAB_BIN_M) & ending
    )


def table_points(points_map: FloatArray, top: Box3D, config: SegmentConfig) -> NDArray[np.bool_]:
    """Which points (N, 3) are the table's top (``_top_points``) or its legs (``leg_points``)."""
    return np.asarray(_top_points(points_map, top, config) | leg_points(points_map, [top], config))


def one_board(blob: Blob, top: Box3D, config: SegmentConfig) -> bool:
    """Whether the top found in ``blob`` is one board: the largest connected part of its points
    (linked as the segmentation links points, on the image grid) still spans
    ``unseen_table_min_side_m`` along its minor axis. The top of a chair's back and the bottles
    on a desk behind it end at one height, and the depth noise at 4 m spreads the back's 4 cm
    into a band as deep as a table: their slab is wide, but in pieces."""
    on_top = np.flatnonzero(_top_points(blob.points_map, top, config))
    parts = grid_components(blob, on_top, config.pixel_step, config)
    if not parts:
        return False
    largest = on_top[max(parts, key=len)]
    if len(largest) < config.min_cluster_points:
        return False
    return _minor_extent_m(blob.points_map[largest, :2]) >= UNSEEN_TABLE_MIN_SIDE_M


def on_legs(blob: Blob, top: Box3D, config: SegmentConfig) -> bool:
    """Whether what holds the top found in ``blob`` up is legs, not a solid front: the points
    of the blob's columns that rise from low down to the top (``legs.leg_points``) stand, seen
    from the camera, in runs across the view narrower than ``unseen_table_min_side_m`` or than
    half the top's width across the view. A table's legs are a few centimetres thick each,
    with free space between them; the front of a cabinet, a counter or a shelf with things on
    its top is such a column in every cell along its edge (runs of 0.54-1.5 times the top's
    width on the degraded bookstore's counters and book cube; 0.26-0.33, at most 0.3 m, under
    office 62's tables seen from 4 m). Across the view (the camera's x), not in the map: depth
    noise spreads a leg at 4 m some 0.2 m along the ray, but moves its side little. No leg
    seen (chairs before it, its top seen from below) is no evidence against a table."""
    legs = leg_points(blob.points_map, [top], config)
    if not legs.any():
        return True
    cells = np.unique(np.floor(blob.points_cam[legs, 0] / TABLE_LEG_CELL_M).astype(np.int64))
    breaks = np.flatnonzero(np.diff(cells) != 1)
    starts, ends = np.r_[0, breaks + 1], np.r_[breaks, len(cells) - 1]
    widest_m = float(np.max(cells[ends] - cells[starts] + 1)) * TABLE_LEG_CELL_M
    across = blob.points_cam[_top_points(blob.points_map, top, config), 0]
    top_m = float(np.ptp(np.percentile(across, [3, 97]))) if len(across) else 0.0
    return widest_m < max(UNSEEN_TABLE_MIN_SIDE_M, top_m / 2.0)


def drop_unseen_tables(
    blobs: list[Blob], boxes_xyxy: FloatArray, classes: Sequence[str], config: RefineConfig,
    width: int, height: int,
) -> list[Blob]:
    """``blobs`` without the tops and legs of tables found in them (see the module docstring);
    ``boxes_xyxy`` (K, 4) and ``classes`` are this frame's detections."""
    return split_unseen_tables(blobs, boxes_xyxy, classes, config, width, height)[0]


def split_unseen_tables(
    blobs: list[Blob], boxes_xyxy: FloatArray, classes: Sequence[str], config: RefineConfig,
    width: int, height: int,
) -> tuple[list[Blob], list[Blob], list[int]]:
    """(``blobs`` without the tops and legs of tables found in them, one blob per table found:
    its top and legs, the indices of the detections of an ``unseen_table_lookalikes`` class that
    name a blob holding a table: they named the table); ``boxes_xyxy`` (K, 4) and ``classes``
    are this frame's detections. A top found on a solid front (not ``on_legs``: a cabinet, a
    counter) leaves its blob with its front as a table's does, so what stands on it is apart,
    but is no table: it is dropped, as the background filter drops a mapped top."""
    tables: list[Blob] = []
    lookalikes: list[int] = []
    if UNSEEN_TABLE_MIN_SIDE_M <= 0 or not blobs:
        return blobs, tables, lookalikes
    boxes = np.asarray(boxes_xyxy, dtype=np.float64).reshape(-1, 4)
    if len(boxes) == 0:
        return blobs, tables, lookalikes
    out: list[Blob] = []
    blob_boxes = np.array([blob.image_box_xyxy for blob in blobs])
    ious = iou_matrix(blob_boxes, boxes)
    held = _held(blob_boxes, boxes, classes, config)
    for blob, iou, holds in zip(blobs, ious, held, strict=True):
        top = None
        if not blob.fragment:
            k = int(np.argmax(iou))
            named = iou[k] >= TRIM_IOU
            if (named and classes[k] not in UNSEEN_TABLE_SKIP_CLASSES) or (not named and holds):
                top = unseen_table_top(blob.points_map, config)
                if top is not None and not one_board(blob, top, config):
                    top = None
        if top is None:
            out.append(blob)
            continue
        legs = on_legs(blob, top, config)
        if legs:
            lookalikes.extend(j for j in np.flatnonzero(iou >= TRIM_IOU).tolist()
                              if classes[j] in UNSEEN_TABLE_LOOKALIKES)
        on_table = table_points(blob.points_map, top, config)
        if legs and np.count_nonzero(on_table) >= config.min_cluster_points:
            tables.append(sub_blob(blob, np.flatnonzero(on_table), config.pixel_step, width, height))
        rest = np.flatnonzero(~on_table)
        for part in grid_components(blob, rest, config.pixel_step, config):
            if len(part) >= config.min_cluster_points:
                out.append(_part(blob, rest[part], top, config, width, height))
    return out, tables, lookalikes


def _held(
    blob_boxes: FloatArray, boxes: FloatArray, classes: Sequence[str], config: RefineConfig
) -> NDArray[np.bool_]:
    """Per blob, whether a detection box (not of ``unseen_table_skip_classes``) lies at least
    ``unseen_table_holding`` inside its image box: an object in or on it (0: never)."""
    if UNSEEN_TABLE_HOLDING <= 0:
        return np.zeros(len(blob_boxes), dtype=bool)
    usable = np.array([c not in UNSEEN_TABLE_SKIP_CLASSES for c in classes], dtype=bool)
    lo = np.maximum(blob_boxes[:, None, :2], boxes[None, :, :2])
    hi = np.minimum(blob_boxes[:, None, 2:], boxes[None, :, 2:])
    inter = np.prod(np.clip(hi - lo, 0.0, None), axis=2)
    area = np.prod(np.clip(boxes[:, 2:] - boxes[:, :2], 0.0, None), axis=1)
    inside = inter >= UNSEEN_TABLE_HOLDING * np.maximum(area, 1e-9)[None, :]
    return np.asarray((inside & usable[None, :]).any(axis=1))


def _part(
    blob: Blob, sel: NDArray[np.int64], top: Box3D,
    config: SegmentConfig, width: int, height: int,
) -> Blob:
    """A part of ``blob`` as a blob of its own, standing on the table top, on the floor below the
    blob (as the segmentation found it), or on nothing known."""
    part = sub_blob(blob, sel, config.pixel_step, width, height)
    part.support_z_m = standing_on(part, [float(top.aabb()[1][2]), blob.support_z_m], config)
    return part
