"""A couch or a bed: told apart by where their tall part stands.

A detector trained on photos confuses the two (YOLOX-Nano names a simulated office's couch
``bed`` in 26 views of 27): both are long, soft and about half a metre high where one sits or
lies. Their tall parts differ. A couch's back runs along one long side of its footprint; a
bed's headboard, when it has one, stands across one short end. A blob named either whose points
higher than ``TALL_M`` above the floor lie along one long side, spanning most of it, is a couch;
across one short end, spanning most of it, a bed. Otherwise (no tall part, tall parts at both
ends or all over, a view too short to show a whole side) the detector's name stands.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["BED", "COUCH", "couch_or_bed"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
COUCH_OR_BED: bool = True
"""A blob a detection names ``couch`` or ``bed`` takes the other name when its tall part
says so (``couch_or_bed.py``): a back along a long side is a couch's, a headboard across a
short end a bed's (issue 17: YOLOX-Nano named a couch ``bed`` in 26 views of 27)."""

COUCH, BED = "couch", "bed"
TALL_M = 0.7  # above a seat (0.45), a mattress (0.5-0.6) and a couch's arms (0.6-0.65)
MIN_TALL_SHARE = 0.05  # of the blob's points: a back or a headboard in view
MAX_TALL_SHARE = 0.8  # ... but not all of it: a couch seen from behind shows only its back
MIN_LENGTH_M = 1.2  # the footprint's long side: the shortest couches and beds, seen whole
OFF_MIDDLE = 0.25  # the tall points' mean lies this share of the footprint off its middle ...
SPAN = 0.6  # ... and they span this share of the side they stand along
EDGE_QUANTILE = 0.02  # the footprint's extent: between these quantiles of the points


def couch_or_bed(points_map: NDArray[np.float64], floor_z_m: float) -> str | None:
    """``COUCH``, ``BED`` or None (cannot tell) for a blob's points (N, 3, map frame, z up)."""
    if len(points_map) < 20:
        return None
    tall = points_map[:, 2] - floor_z_m > TALL_M
    share = float(tall.mean())
    if not MIN_TALL_SHARE <= share <= MAX_TALL_SHARE:
        return None
    xy = points_map[:, :2] - points_map[:, :2].mean(axis=0)
    _, axes = np.linalg.eigh(np.cov(xy.T))
    along, across = xy @ axes[:, 1], xy @ axes[:, 0]  # the footprint's long and short axes
    a_lo, a_hi = np.quantile(along, [EDGE_QUANTILE, 1.0 - EDGE_QUANTILE])
    b_lo, b_hi = np.quantile(across, [EDGE_QUANTILE, 1.0 - EDGE_QUANTILE])
    length, width = a_hi - a_lo, b_hi - b_lo
    if length < MIN_LENGTH_M or width <= 0.0:
        return None
    ta, tb = along[tall], across[tall]
    side = (float(np.mean(tb)) - (b_lo + b_hi) / 2.0) / width
    end = (float(np.mean(ta)) - (a_lo + a_hi) / 2.0) / length
    span_along = float(np.quantile(ta, 0.9) - np.quantile(ta, 0.1)) / length
    span_across = float(np.quantile(tb, 0.9) - np.quantile(tb, 0.1)) / width
    if abs(side) >= OFF_MIDDLE and span_along >= SPAN and abs(end) < OFF_MIDDLE:
        return COUCH
    if abs(end) >= OFF_MIDDLE and span_across >= SPAN and abs(side) < OFF_MIDDLE:
        return BED
    return None
