"""Objects seen in part behind something nearer, named by the detection box that holds them.

A detector boxes a whole object, the part something nearer hides included (the back of a chair
across a table shows above the table's top; its box reaches the floor). The depth camera sees
the visible part only: a blob that is a small part of the box, so the IoU of Algorithm 4
(``match.py``) stays far below its threshold and the object is never named. A detection that
named no blob by IoU names the blob that is its visible part:

- **inside**: at least ``min_inside`` of the blob's pixels lie in the box;
- **the box's main segment**: of the blobs the box holds (``min_inside`` of their pixels in
  it; a blob only partly in it is another object crossing it, an occluder or a neighbour), the
  one with the most pixels in the box, with none that has most of its pixels in the box
  behind it (``HIDDEN_DEPTH_GAP_M`` deeper): a cup in front of a chair, or on the table in
  front of it, is not the chair;
- **hidden**: at least ``HIDDEN_SHARE`` of the box's depth samples outside the blob are nearer
  than the blob by ``HIDDEN_DEPTH_GAP_M``: something in front hides the rest of the box. An
  object in plain view whose box its blob does not fill is no occluded object (a part of
  something larger, or a small thing in a box of something else);
- **the box fits the class at the blob's depth**: the box's size in metres at the blob's
  median depth is at most the class's largest size (``plausible.max_longest_m``: a thing far
  behind a near bottle's box would make a bottle metres tall), and the object stands at that
  depth: the box's bottom edge placed at the blob's depth lies no lower than the mapped floor
  (``FLOOR_SLACK_M``); a patch of floor seen past a bed, in the bed's box, would put the bed's
  base under the floor;
- **its top, across the box**: the blob reaches the box's top (``TOP_BAND``) and spans a
  third of its width (``ACROSS_SHARE``). What hides an object stands in front of it on the same
  floor and hides its lower part: its top shows, across the box. A patch of floor behind a
  person's legs, or a strip of wall beside a bed, is no such part.

Each detection names one blob; a blob held by several boxes takes the class of the one its
image box overlaps most (IoU).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.match import Match, iou_matrix
from hiper_cli.perceive.foreground.plausible import CLASS_SIZE_TOLERANCE, max_longest_m
from hiper_cli.perceive.foreground.segment import JOIN_CONTAINMENT, pixels_in_boxes
from hiper_cli.types import CameraIntrinsics, Detections, Frame

__all__ = ["HIDDEN_DEPTH_GAP_M", "HIDDEN_PARTS", "HIDDEN_SHARE", "name_hidden"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
HIDDEN_PARTS: bool = True
"""Name the visible part of an object hidden in part by its detection box (this module)."""
HIDDEN_DEPTH_GAP_M: float = 0.15
"""A depth sample this much nearer than a blob hides it; a blob this much deeper lies behind."""
HIDDEN_SHARE: float = 0.5
"""At least this share of a box's depth samples outside its blob lie in front of the blob."""
TOP_BAND: float = 0.15
"""The visible part's top lies within this share of the box's height from the box's top ..."""
ACROSS_SHARE: float = 1.0 / 3.0
"""... and it spans at least this share of the box's width."""
FLOOR_SLACK_M: float = 0.25
"""The box's bottom, placed at the blob's depth, lies at most this below the mapped floor."""
BEHIND_SHARE: float = 0.5
"""A blob with this share of its pixels in the box, behind the candidate, is the box's object."""

FloatArray = NDArray[np.float64]


def name_hidden(
    matches: Sequence[Match],
    pixels_uv: Sequence[NDArray[np.int32]],
    depths_m: Sequence[FloatArray],
    detections: Detections,
    frame: Frame,
    step: int,
    *,
    min_score: float,
    floor_z_m: float | None = None,
    min_inside: float = JOIN_CONTAINMENT,
) -> list[Match]:
    """``matches`` (one per blob; ``pixels_uv`` (N, 2) full-resolution pixels and ``depths_m``
    (N,) camera depths of each blob's points) with the unnamed blobs that a detection holds as
    the visible part of a hidden object named by it (see the module docstring). ``frame``: the
    depth image, camera and pose; ``step``: the segmentation's pixel step; ``floor_z_m``: the
    mapped floor's height (None: no floor mapped, no test of the base)."""
    out = list(matches)
    if len(detections) == 0 or not out:
        return out
    named = {m.detection_index for m in out if m.detection_index is not None}
    medians = [float(np.median(d)) if len(d) else np.inf for d in depths_m]
    found: list[tuple[float, int, int]] = []  # (IoU, detection, blob)
    for k, box in enumerate(detections.xyxy):
        if k in named or detections.scores[k] < min_score:
            continue
        i = _visible_part(out, pixels_uv, medians, box, min_inside)
        if (
            i is not None
            and _top_across(box, pixels_uv[i])
            and _fits(box, medians[i], detections.class_names[k], frame.camera)
            and (floor_z_m is None or _base_z_m(box, medians[i], frame) >= floor_z_m - FLOOR_SLACK_M)
            and _hidden_share(box, pixels_uv[i], medians[i], (frame.depth_m, frame.camera, step))
            >= HIDDEN_SHARE
        ):
            lo, hi = pixels_uv[i].min(axis=0), pixels_uv[i].max(axis=0)
            blob_box = np.array([lo[0], lo[1], hi[0] + 1, hi[1] + 1], dtype=np.float64)
            found.append((float(iou_matrix(blob_box, box)[0, 0]), k, i))
    for iou, k, i in sorted(found, key=lambda f: -f[0]):  # the box a blob fills most names it
        if out[i].detection_index is None:
            out[i] = Match(detections.class_names[k], float(detections.scores[k]), k, iou)
    return out


def _top_across(box: FloatArray, uv: NDArray[np.int32]) -> bool:
    """Whether the blob's pixels reach the box's top (within ``TOP_BAND``) and span
    ``ACROSS_SHARE`` of its width: what stands in front of an object on the same floor hides
    its lower part, and its top shows across the box."""
    height, width = box[3] - box[1], box[2] - box[0]
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    return bool(lo[1] <= box[1] + TOP_BAND * height and hi[0] - lo[0] >= ACROSS_SHARE * width)


def _visible_part(
    matches: Sequence[Match], pixels_uv: Sequence[NDArray[np.int32]], medians: Sequence[float],
    box: FloatArray, min_inside: float,
) -> int | None:
    """The unnamed blob that is the box's main segment with ``min_inside`` of its pixels in it
    and no blob mostly inside it behind it; None when there is none."""
    box = box.reshape(1, 4)
    counts = np.array([int(pixels_in_boxes(uv, box)[:, 0].sum()) for uv in pixels_uv])
    shares = counts / np.maximum([len(uv) for uv in pixels_uv], 1)
    held = np.flatnonzero(shares >= min_inside)  # the blobs the box holds; others cross it
    if len(held) == 0:
        return None
    i = int(held[np.argmax(counts[held])])
    if matches[i].detection_index is not None:
        return None
    behind = (shares >= BEHIND_SHARE) & (np.asarray(medians) > medians[i] + HIDDEN_DEPTH_GAP_M)
    return None if behind.any() else i


def _fits(box: FloatArray, depth_m: float, class_name: str, camera: CameraIntrinsics) -> bool:
    """Whether the box, at ``depth_m``, is no larger than the class's largest object."""
    width_m = (box[2] - box[0]) * depth_m / camera.fx
    height_m = (box[3] - box[1]) * depth_m / camera.fy
    return bool(max(width_m, height_m) <= max_longest_m(class_name, CLASS_SIZE_TOLERANCE))


def _base_z_m(box: FloatArray, depth_m: float, frame: Frame) -> float:
    """The map height of the box's bottom edge (its middle) placed at ``depth_m``: where the
    object stands if it lies at the blob's depth."""
    camera = frame.camera
    u, v = 0.5 * (box[0] + box[2]), box[3]
    point = np.array([(u - camera.cx) / camera.fx * depth_m, (v - camera.cy) / camera.fy * depth_m, depth_m])
    return float((frame.T_map_cam[:3, :3] @ point + frame.T_map_cam[:3, 3])[2])


def _hidden_share(
    box: FloatArray, uv: NDArray[np.int32], depth_m: float,
    view: tuple[NDArray[np.float32], CameraIntrinsics, int],
) -> float:
    """The share of the box's depth samples (the segmentation's grid) outside the blob's pixels
    that lie ``HIDDEN_DEPTH_GAP_M`` or more in front of ``depth_m``."""
    image, camera, step = view
    off = step // 2
    cols = np.arange(off, camera.width, step)
    rows = np.arange(off, camera.height, step)
    cols = cols[(cols + 0.5 >= box[0]) & (cols + 0.5 <= box[2])]
    rows = rows[(rows + 0.5 >= box[1]) & (rows + 0.5 <= box[3])]
    if len(cols) == 0 or len(rows) == 0:
        return 0.0
    z = np.asarray(image[np.ix_(rows, cols)], dtype=np.float64)
    mine = np.zeros(z.shape, dtype=bool)
    r = np.searchsorted(rows, uv[:, 1])
    c = np.searchsorted(cols, uv[:, 0])
    ok = (r < len(rows)) & (c < len(cols))
    ok[ok] &= (rows[r[ok]] == uv[ok, 1]) & (cols[c[ok]] == uv[ok, 0])
    mine[r[ok], c[ok]] = True
    rest = z[~mine]
    rest = rest[np.isfinite(rest) & (rest > 0)]
    if len(rest) == 0:
        return 0.0
    return float(np.mean(rest < depth_m - HIDDEN_DEPTH_GAP_M))
