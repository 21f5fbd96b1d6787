"""What a detection can name: a walker, a solid body and the nearest thing in its box;
anything else, the blob that fits its box best.

Two kinds of blobs became people, and their tracks then lived on after the person left (a
"person last seen" seconds or minutes late, and a second person instance):

- **flat** ones: a picture, a poster or a screen that shows people (a detector names them
  ``person``; the simulator's truth detector does so 30 % of the time, as the paper's
  false-positive trap), and wall pieces the background has not claimed, which a lost person
  track took while it searched. A person is a solid body at least a hand deep, whose surface
  seen from any side spreads along the viewing ray; a flat blob half a metre across or more,
  whose points lie within the depth noise of one plane (``whole.thickness_m``, the same test
  that keeps flat pieces from being ``unknown`` objects), is not one (``is_flat``; a smaller
  flat patch may be a piece of a chest seen from 0.4 m). A blob named a walker class that is
  flat stays ``unknown``, and a walker's track does not take a flat blob
  (``Measurement.solid``).
- blobs **behind** the one the detection saw: a detection box of a person in front of a wall
  also names the wall's blob when that blob's image box fits the person's box (the
  refinement trims a blob to the box it overlaps). Inside the box the nearer object hides the
  farther one, so the detector saw the nearer; of the blobs one detection names, those whose
  depths lie more than ``join_depth_m`` (the refinement's "same object" depth gap) beyond the
  nearest one's are not what it saw and stay ``unknown`` (``detected_blobs``). Two parts of one
  person split by a table lie at the same depth and both keep the name. For the other
  classes the blob that fits the box best is what the detection saw, and blobs in front of it
  are not either: the end of a desk before a chair fills part of the chair's box, and the
  nearest rule would give the desk the chair's name.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.background_filter import BACKGROUND_MARGIN_PER_M2
from hiper_cli.perceive.foreground.class_vote import UNKNOWN
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.match import Match
from hiper_cli.perceive.foreground.refine import JOIN_DEPTH_M
from hiper_cli.perceive.foreground.whole import UNKNOWN_MIN_THICKNESS_M, thickness_m

__all__ = ["detected_blobs", "is_flat"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
WALKER_SOLID: bool = True
"""A walker is a solid body (``solid.py``): a flat blob (as ``unknown_min_thickness_m``
says: a picture or a screen showing people, a wall piece) named a walker class stays
``unknown``, and a walker's track does not take a flat blob."""
DETECTION_NEAREST: bool = True
"""A detection names one of the blobs it matches and those at its depth
(``solid.detected_blobs``): for a walker class the nearest (a wall behind a person stays
``unknown``), for other classes the one that fits its box best (a desk's end in front of
a chair stays ``unknown``); blobs more than ``join_depth_m`` behind or in front of it do not
keep the name."""

DEPTH_RANGE_PERCENTILES = (5.0, 95.0)  # a blob's depth range, robust to a few stray points
PANEL_MIN_SPAN_M = 0.5  # a flat blob this large would show a body's relief (a torso's width)
PANEL_MIN_DEPTH_M = 1.0  # nearer, a patch of one body fills the view (0.5 m across at 0.4 m)
BODY_RELIEF_M = 0.03  # a body's surface spreads at least this much along the view (thinnest σ)


def is_flat(points_cam: NDArray[np.float64], config: ForegroundConfig) -> bool:
    """Whether the points (N, 3, camera frame) of a blob are a flat panel: at least
    ``PANEL_MIN_SPAN_M`` across and on one plane within the depth noise (their thinnest spread
    below ``unknown_min_thickness_m`` plus ``background_margin_per_m2`` · depth², depth: their
    median distance). A smaller patch is no evidence: a person 0.4 m from the camera shows a
    piece of the chest, as flat as a wall. Nor is a flat reading where the depth noise reaches a
    body's relief (``BODY_RELIEF_M``, beyond about 3.6 m): a walker's upper body at 5 m reads as
    flat as a wall there; nor nearer than ``PANEL_MIN_DEPTH_M``, where a person's chest fills
    the whole image, 0.5 m across and flat."""
    if len(points_cam) < 4:
        return False
    if float(np.max(np.ptp(points_cam, axis=0))) < PANEL_MIN_SPAN_M:
        return False
    depth = float(np.median(points_cam[:, 2]))
    flat_m = UNKNOWN_MIN_THICKNESS_M + BACKGROUND_MARGIN_PER_M2 * depth * depth
    if depth < PANEL_MIN_DEPTH_M or flat_m >= BODY_RELIEF_M:
        return False
    return thickness_m(points_cam) < flat_m


def detected_blobs(
    matches: Sequence[Match], depths_m: Sequence[NDArray[np.float64]], config: ForegroundConfig
) -> list[Match]:
    """``matches`` with the blobs a detection names that are not what it saw made
    ``unknown``. Per detection, what it saw is, for a walker class, the blob with the nearest
    median depth (a wall behind a person, trimmed to the person's box, fits that box as well),
    and for any other class the blob that fits its box best (highest IoU; a desk's end in
    front of a chair fills only part of the chair's box). A blob whose depth range
    (``DEPTH_RANGE_PERCENTILES``) lies more than ``join_depth_m`` beyond that blob's, or in
    front of it, is not. ``depths_m``: each blob's point depths (camera z, m)."""
    out = list(matches)
    by_detection: dict[int, list[int]] = {}
    for i, m in enumerate(matches):
        if m.detection_index is not None:
            by_detection.setdefault(m.detection_index, []).append(i)
    lo_q, hi_q = DEPTH_RANGE_PERCENTILES
    for named in by_detection.values():
        if len(named) < 2:
            continue
        ranges = {i: np.percentile(depths_m[i], [lo_q, 50.0, hi_q]) for i in named}
        if matches[named[0]].class_name in config.walker_classes:
            seen = min(named, key=lambda i: float(ranges[i][1]))
        else:
            seen = max(named, key=lambda i: (matches[i].iou, -float(ranges[i][1])))
        near_end, far_end = float(ranges[seen][0]), float(ranges[seen][2])
        for i in named:
            if float(ranges[i][0]) > far_end + JOIN_DEPTH_M or (
                float(ranges[i][2]) < near_end - JOIN_DEPTH_M
            ):
                out[i] = Match(UNKNOWN, 0.0, None, matches[i].iou)
    return out
