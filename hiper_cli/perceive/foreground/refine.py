"""Blobs refined with the 2D detections of the same frame: split what touches, join what an
occluder cut apart.

Euclidean clustering cannot tell two objects apart that touch (a bottle on a chair seat,
chairs pushed under a table) and cuts one object in two when something nearer hides its
middle. The detector sees those cases from the image; this step uses its boxes before the
IoU matching of Algorithm 4:

0. **Trim**: a blob whose image box overlaps a detection box with IoU at least ``trim_iou``
   loses the points outside that box (grown by one sample step), when they are at most
   ``trim_max_share`` of it: a table leg or a wall corner that the clustering attached to a
   chair. Points within ``trim_margin_frac`` of the box's size outside it stay when their
   depth is within ``trim_depth_m`` of the median depth of the points inside: a box jittered
   smaller cut the head of a person or the top of a chair's back.
1. **Split**: a blob whose pixels fall into two or more detection boxes (each holding at least
   ``min_cluster_points`` of them) is divided (``detection_split``; without it, only a blob that
   holds two or more boxes of one class side by side, ``split_twins``: each box at least
   ``join_containment`` inside the blob's image box, none half inside another unless their
   own points lie ``twin_depth_gap_m`` apart in depth: one chair behind the other). Every point
   goes to the smallest box it lies in (the specific object in front of a larger one); a
   point inside several boxes then goes to the box whose points' median depth is nearest its
   own (a chair seen through the bottle's box keeps the chair's depth). Points outside every
   box join the group of their nearest labelled point when it is within ``split_attach_m``;
   the rest form a group of their own. Groups smaller than ``min_cluster_points`` join the
   group of their nearest point. A small thing's box inside a blob too big for its class cuts
   the thing out (``carve.py``: a bottle on an unmapped side table).
2. **Join**: blobs that lie inside the same detection box (a share ``join_containment`` of
   their pixels, the box grown by ``detection_margin_frac`` of its size for detector jitter;
   the smallest such box owns them), whose median depths differ by at most ``join_depth_m``
   and whose nearest points are at most ``join_gap_m`` apart become one blob (a person
   behind a table: the torso above it, the legs below it), unless the joined image box fits
   the detection box worse than before (IoU lower by more than ``join_max_iou_loss``: a piece
   of an unmapped table beside a chair).

No detection, no change: with a low-recall detector the step costs almost nothing.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.carve import CARVE_CLASSES, carve_small
from hiper_cli.perceive.foreground.config import RefineConfig
from hiper_cli.perceive.foreground.match import iou_matrix
from hiper_cli.perceive.foreground.segment import (
    JOIN_CONTAINMENT,
    Blob,
    boxes_within,
    concat_blobs,
    pixels_in_boxes,
    sub_blob,
    support_below,
)

__all__ = ["refine_blobs"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
TRIM_IOU: float = 0.3
"""A blob overlapping a detection box with at least this IoU loses its points outside the
(grown) box, when they are at most ``trim_max_share`` of it (1: off) ..."""
TRIM_MAX_SHARE: float = 0.4
TRIM_MARGIN_FRAC: float = 0.1
"""The trimming box is the detection box grown by this share of its size on every side:
a jittered box (the ``truth`` detector's corners move by 5 % of the size, σ) otherwise cuts
the head of a person or the top of a chair back. Only points at the depth of the blob's
part inside the box (within ``trim_depth_m`` of its median) are kept there: a table leg or a
wall behind is not."""
TRIM_DEPTH_M: float = 0.2
SPLIT_ATTACH_M: float = 0.15
"""A split blob's point outside every box joins the nearest labelled point within this."""
SPLIT_TWINS: bool = True
"""Even with ``detection_split`` off, split a blob that holds two or more detection boxes of
one class side by side (each at least ``join_containment`` inside the blob's image box,
none half inside another): bottles, cups or chairs in a row that the clustering joined (its
tolerance grows with the depth: 0.26 m at 4 m). Boxes of one class side by side are two
objects whatever the jitter; a person beside a chair keeps to the rule above."""
TWIN_DEPTH_GAP_M: float = 0.5
"""Two boxes of one class that overlap by half or more are still twins when the points only
one holds lie this much farther than the other's in median depth (two chairs one behind the
other at a table's far end); nearer, they are duplicate boxes of one object (a chair's back
is 0.2-0.45 m behind its seat's front; 0: never)."""
DETECTION_MARGIN_FRAC: float = 0.1
"""... the box grown by this share of its size on every side (detector jitter: without it a
chair's seat cut off by its own back at the image's lower edge stays apart) ..."""
JOIN_DEPTH_M: float = 0.25
"""... their median depths at most this far apart ..."""
JOIN_GAP_M: float = 0.3
"""... and their nearest points at most this far apart."""
JOIN_MAX_IOU_LOSS: float = 0.05
"""... unless the joined image box's IoU with the detection box is lower than before by
more than this (a piece of an unmapped table top beside a chair's box)."""

FloatArray = NDArray[np.float64]
SMALL = "\0small"  # ``_twins``: the one kind of every class in ``carve_classes``


def _nearest_label(
    query: FloatArray, points: FloatArray, labels: NDArray[np.int64]
) -> tuple[NDArray[np.int64], FloatArray]:
    from scipy.spatial import cKDTree

    dist, idx = cKDTree(points).query(query)
    return labels[np.asarray(idx, dtype=np.int64)], np.asarray(dist, dtype=np.float64)


def _split(
    blob: Blob, boxes: FloatArray, areas: FloatArray, config: RefineConfig
) -> list[NDArray[np.int64]] | None:
    """Index groups of the points of ``blob``, or None when it stays whole."""
    inside = pixels_in_boxes(blob.pixels_uv, boxes)
    counts = inside.sum(axis=0)
    cand = np.flatnonzero(counts >= config.min_cluster_points)
    if len(cand) < 2:
        return None
    inside = inside[:, cand]
    n = len(blob.points_cam)
    # 1. the smallest box holding the point
    order = np.argsort(areas[cand])  # candidate columns, smallest box first
    labels = np.full(n, -1, dtype=np.int64)
    for col in order[::-1]:  # the smallest box writes last
        labels[inside[:, col]] = col
    # 2. points in several boxes: the box whose points' median depth is nearest
    z = blob.points_cam[:, 2]
    multi = np.flatnonzero(inside.sum(axis=1) >= 2)
    if len(multi):
        medians = np.array(
            [np.median(z[labels == c]) if np.any(labels == c) else np.inf for c in range(len(cand))]
        )
        cost = np.where(inside[multi], np.abs(z[multi, None] - medians[None, :]), np.inf)
        labels[multi] = np.argmin(cost, axis=1)
    # 3. points outside every box: the nearest labelled point's group, when close
    free = np.flatnonzero(labels < 0)
    own = np.flatnonzero(labels >= 0)
    if len(free) and len(own):
        near, dist = _nearest_label(blob.points_cam[free], blob.points_cam[own], labels[own])
        labels[free] = np.where(dist <= SPLIT_ATTACH_M, near, len(cand))
    # 4. groups too small join the group of their nearest point
    sizes = np.bincount(labels, minlength=len(cand) + 1)
    small = np.flatnonzero((sizes > 0) & (sizes < config.min_cluster_points))
    if len(small):
        is_small = np.isin(labels, small)
        keep = np.flatnonzero(~is_small)
        if len(keep) == 0:
            return None
        near, _ = _nearest_label(blob.points_cam[is_small], blob.points_cam[keep], labels[keep])
        labels[is_small] = near
    groups = [np.flatnonzero(labels == g) for g in np.unique(labels)]
    return groups if len(groups) >= 2 else None


def _apart_in_depth(blob: Blob, a: FloatArray, b: FloatArray, config: RefineConfig) -> bool:
    """Whether the points of ``blob`` that only box ``a`` holds and those that only ``b`` holds
    (or, for a box inside the other, those the inner one holds) lie more than
    ``twin_depth_gap_m`` apart in median depth: one object behind the other, not one object's
    duplicate boxes. False when either side has fewer than ``min_cluster_points``."""
    if TWIN_DEPTH_GAP_M <= 0:
        return False
    inside = pixels_in_boxes(blob.pixels_uv, np.stack([a, b]))
    only_a, only_b = inside[:, 0] & ~inside[:, 1], inside[:, 1] & ~inside[:, 0]
    both = inside[:, 0] & inside[:, 1]
    if np.count_nonzero(only_a) < config.min_cluster_points:
        only_a = both
    elif np.count_nonzero(only_b) < config.min_cluster_points:
        only_b = both
    if min(np.count_nonzero(only_a), np.count_nonzero(only_b)) < config.min_cluster_points:
        return False
    z = blob.points_cam[:, 2]
    return bool(abs(float(np.median(z[only_a])) - float(np.median(z[only_b]))) > TWIN_DEPTH_GAP_M)


def _twins(
    blob: Blob, boxes: FloatArray, classes: Sequence[str], config: RefineConfig
) -> NDArray[np.int64]:
    """The detection boxes of the class (every small thing, ``carve_classes``, one class here:
    a cup beside a bottle) with most boxes side by side in the blob's image box
    (each at least ``join_containment`` inside it, none half inside another unless the two lie
    at different depths, ``_apart_in_depth``: duplicate boxes of one object, a chair and its
    back, are no twins; two chairs one behind the other are); empty when fewer than two."""
    inside = boxes_within(blob.image_box_xyxy, boxes, JOIN_CONTAINMENT)
    area = np.maximum(np.prod(boxes[:, 2:] - boxes[:, :2], axis=1), 1e-9)
    best = np.zeros(0, dtype=np.int64)
    kinds = np.array([SMALL if c in CARVE_CLASSES else c for c in classes], dtype=object)
    for name in sorted({c for c, ok in zip(kinds, inside, strict=True) if ok}):
        idx = np.flatnonzero(inside & (kinds == name))
        if len(idx) < 2:
            continue
        b = boxes[idx]
        p_lo = np.maximum(b[:, None, :2], b[None, :, :2])
        p_hi = np.minimum(b[:, None, 2:], b[None, :, 2:])
        common = np.prod(np.clip(p_hi - p_lo, 0.0, None), axis=2)
        smaller = np.minimum(area[idx][:, None], area[idx][None, :])
        np.fill_diagonal(common, 0.0)
        overlapping = np.argwhere(np.triu(common >= 0.5 * smaller, k=1))
        if all(_apart_in_depth(blob, b[i], b[j], config) for i, j in overlapping) and len(idx) > len(best):
            best = idx
    return best


def _trim(
    blob: Blob, iou: FloatArray, boxes: FloatArray, grown: FloatArray, step_pad: FloatArray,
    config: RefineConfig,
) -> NDArray[np.int64] | None:
    """The points of ``blob`` inside the (grown) box of the detection it overlaps best (``iou``
    (K,) of its image box with ``boxes``), when that IoU reaches ``trim_iou`` and the points
    outside are at most ``trim_max_share``."""
    k = int(np.argmax(iou))
    if iou[k] < TRIM_IOU:
        return None
    inside = pixels_in_boxes(blob.pixels_uv, boxes[k : k + 1] + step_pad)[:, 0]
    near = pixels_in_boxes(blob.pixels_uv, grown[k : k + 1])[:, 0] & ~inside
    if near.any() and inside.any():
        # Just outside the box at the depth of what is inside: the box was jittered smaller.
        z = blob.points_cam[:, 2]
        inside |= near & (np.abs(z - float(np.median(z[inside]))) <= TRIM_DEPTH_M)
    n_out = int((~inside).sum())
    if n_out == 0 or n_out > TRIM_MAX_SHARE * len(inside):
        return None
    keep = np.flatnonzero(inside)
    return keep if len(keep) >= config.min_cluster_points else None


def _owner(blob: Blob, boxes: FloatArray, areas: FloatArray, config: RefineConfig) -> int | None:
    """The smallest (jitter-grown) detection box holding ``join_containment`` of the blob."""
    share = np.count_nonzero(pixels_in_boxes(blob.pixels_uv, boxes), axis=0) / len(blob.pixels_uv)
    ok = np.flatnonzero(share >= JOIN_CONTAINMENT)
    if len(ok) == 0:
        return None
    return int(ok[np.argmin(areas[ok])])


def _close(a: Blob, b: Blob, config: RefineConfig) -> bool:
    from scipy.spatial import cKDTree

    # Boxes farther apart than the gap hold no points within it (distances are the same in the
    # map frame, where the blobs' bounds are known already).
    (a_min, a_max), (b_min, b_max) = a.bounds_map, b.bounds_map
    if np.linalg.norm(np.maximum(np.maximum(a_min - b_max, b_min - a_max), 0.0)) > JOIN_GAP_M:
        return False
    # Depth ranges (10th to 90th percentile), not medians: a chair's back legs lie 0.4 m
    # behind the middle of its front.
    za, zb = a.points_cam[:, 2], b.points_cam[:, 2]
    a_lo, a_hi = np.percentile(za, [10, 90])
    b_lo, b_hi = np.percentile(zb, [10, 90])
    if max(a_lo - b_hi, b_lo - a_hi) > JOIN_DEPTH_M:
        return False
    small, large = (a, b) if len(a.points_cam) <= len(b.points_cam) else (b, a)
    dist, _ = cKDTree(large.points_cam).query(small.points_cam, distance_upper_bound=JOIN_GAP_M)
    return bool(np.isfinite(dist).any())


def _fits_better(group: Sequence[Blob], blob: Blob, box_xyxy: FloatArray, config: RefineConfig) -> bool:
    """Whether adding ``blob`` to ``group`` keeps the group's image box at least as close to the
    detection box (IoU, up to ``join_max_iou_loss``): the torso and legs of a person cut by a
    table fill the person's box together, a piece of a table beside a chair's box does not."""
    before = np.array([b.image_box_xyxy for b in group])
    union = np.r_[before[:, :2].min(axis=0), before[:, 2:].max(axis=0)]
    box = blob.image_box_xyxy
    joined = np.r_[np.minimum(union[:2], box[:2]), np.maximum(union[2:], box[2:])]
    iou = iou_matrix(np.stack([union, joined]), box_xyxy.reshape(1, 4))[:, 0]
    return bool(iou[1] >= iou[0] - JOIN_MAX_IOU_LOSS)


def refine_blobs(
    blobs: Sequence[Blob],
    detection_boxes_xyxy: FloatArray,
    config: RefineConfig,
    width: int,
    height: int,
    support_boxes_map: Sequence[Box3D] = (),
    classes: Sequence[str] = (),
    size_tolerance: float | None = None,
) -> list[Blob]:
    """Split and join ``blobs`` with this frame's detection boxes (see the module docstring).

    Fragments (``Blob.fragment``, fewer than ``min_cluster_points`` points) may join an object
    in their detection box; those that do not are dropped.

    ``detection_boxes_xyxy`` (K, 4) pixels: the detections the matching will use; ``classes``
    their class names (``split_twins``, ``carve_classes``; empty: neither). ``size_tolerance``:
    ``class_size_tolerance`` when class sizes are on (None: no carving). Blobs that are neither
    split nor joined are returned as they are.
    """
    boxes = np.asarray(detection_boxes_xyxy, dtype=np.float64).reshape(-1, 4)
    if len(boxes) == 0 or not blobs:
        return [b for b in blobs if not b.fragment]
    image = (width, height)
    out, changed = _split_all(blobs, boxes, classes, config, image)
    if size_tolerance is not None:
        out, changed = carve_small(out, changed, boxes, classes, config, size_tolerance, width, height)
    if TRIM_IOU < 1.0:
        _trim_all(out, changed, boxes, config, image)
    if config.detection_join and len(out) >= 2:
        out, changed = _join_all(out, changed, boxes, config, image)
    whole_blobs = [i for i, b in enumerate(out) if not b.fragment]
    out, changed = [out[i] for i in whole_blobs], [changed[i] for i in whole_blobs]
    if config.background_filter and support_boxes_map:
        for blob, was_changed in zip(out, changed, strict=True):
            if was_changed:
                blob.support_z_m = support_below(blob, support_boxes_map, config, height)
    return out


def _split_all(
    blobs: Sequence[Blob], boxes: FloatArray, classes: Sequence[str], config: RefineConfig,
    image: tuple[int, int],
) -> tuple[list[Blob], list[bool]]:
    """The blobs split by the detection boxes (``detection_split``; else only twins of a class,
    ``split_twins``), and per blob out whether it is new."""
    areas = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    twins_on = SPLIT_TWINS and len(classes) == len(boxes)

    def groups_of(blob: Blob) -> list[NDArray[np.int64]] | None:
        if blob.fragment:
            return None
        if config.detection_split:
            return _split(blob, boxes, areas, config)
        if twins_on:
            twins = _twins(blob, boxes, classes, config)
            return _split(blob, boxes[twins], areas[twins], config) if len(twins) >= 2 else None
        return None

    out: list[Blob] = []
    changed: list[bool] = []
    for blob in blobs:
        groups = groups_of(blob)
        if groups is None:
            out.append(blob)
            changed.append(False)
        else:
            out.extend(sub_blob(blob, g, config.pixel_step, *image) for g in groups)
            changed.extend([True] * len(groups))
    return out, changed


def _trim_all(
    out: list[Blob], changed: list[bool], boxes: FloatArray, config: RefineConfig, image: tuple[int, int]
) -> None:
    """Trim each blob to the detection box it mostly lies in (``_trim``), in place."""
    step = config.pixel_step
    size = np.stack([boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1]], axis=1)
    sign = np.array([-1.0, -1.0, 1.0, 1.0])
    trim_pad = np.tile(size * TRIM_MARGIN_FRAC + step, 2) * sign
    step_pad = step * sign
    ious = iou_matrix(np.array([blob.image_box_xyxy for blob in out]).reshape(-1, 4), boxes)
    for i, blob in enumerate(out):
        if blob.fragment:
            continue
        keep = _trim(blob, ious[i], boxes, boxes + trim_pad, step_pad, config)
        if keep is not None:
            out[i] = sub_blob(blob, keep, step, *image)
            changed[i] = True


def _join_all(
    out: list[Blob], changed: list[bool], boxes: FloatArray, config: RefineConfig, image: tuple[int, int]
) -> tuple[list[Blob], list[bool]]:
    """Blobs (fragments too) that one detection box owns (``_owner``) joined where close and the
    union fits the box better (``_close``, ``_fits_better``; greedy, largest first)."""
    step = config.pixel_step
    areas = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    size = np.stack([boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1]], axis=1)
    grown = boxes + np.tile(size * DETECTION_MARGIN_FRAC + step, 2) * np.array([-1.0, -1.0, 1.0, 1.0])
    by_owner: dict[int, list[int]] = {}
    for i, blob in enumerate(out):
        k = _owner(blob, grown, areas, config)
        if k is not None:
            by_owner.setdefault(k, []).append(i)
    drop: set[int] = set()
    extra: list[Blob] = []
    for k, members in by_owner.items():
        if len(members) < 2:
            continue
        largest_first = sorted(members, key=lambda i: -len(out[i].points_cam))
        for group in _close_groups(out, largest_first, boxes[k], config):
            if len(group) > 1:
                drop.update(group)
                whole = concat_blobs([out[j] for j in group], step, *image)
                whole.fragment = len(whole.points_cam) < config.min_cluster_points
                extra.append(whole)
    if not drop:
        return out, changed
    return ([b for i, b in enumerate(out) if i not in drop] + extra,
            [c for i, c in enumerate(changed) if i not in drop] + [True] * len(extra))


def _close_groups(
    out: list[Blob], members: list[int], box: FloatArray, config: RefineConfig
) -> list[list[int]]:
    """``members`` (indices into ``out``) in groups: each joins the first group with a close
    member whose union fits ``box`` better, else starts its own."""
    merged: list[list[int]] = []
    for i in members:
        for group in merged:
            if any(_close(out[i], out[j], config) for j in group) and _fits_better(
                [out[j] for j in group], out[i], box, config
            ):
                group.append(i)
                break
        else:
            merged.append([i])
    return merged
