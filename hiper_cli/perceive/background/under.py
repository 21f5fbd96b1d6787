"""Whether a horizontal plane at table height stands on legs or on a solid block.

A table top is a board on legs: right below its near edge in the image the camera sees
under it (the floor, chair seats, the wall behind: farther than the edge) after at most
a thin apron. The top of a box stack, a cabinet, a counter or a made bed goes down as a
solid front: below the edge the depth stays the edge's. ``solid_below`` probes
``wall_probe_gap_px`` .. ``wall_probe_reach_px`` below the plane's lowest mask sample in
every image column (the near edge of a top the camera looks down on) and calls the top
solid when most columns with evidence see no farther than the edge. Columns whose edge is
the image's bottom, or whose probes see only nearer things (an occluder) or no return,
give no evidence.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.planes import PlaneSegment, SampleGrid

__all__ = ["UnderEvidence", "solid_below", "under_evidence"]

UnderEvidence = Literal["solid", "legs", "unknown"]

# The depth of a vertical front seen from above grows as the probes go down it
# (optical axis pitched down): about 0.26 m per metre of drop at 15 degrees.
FRONT_SLOPE = 0.3


def solid_below(grid: SampleGrid, seg: PlaneSegment, cfg: BackgroundConfig) -> bool:
    """Whether the top ``seg`` (camera frame, on ``grid``) has a solid front under its near edge."""
    return under_evidence(grid, seg, cfg) == "solid"


def under_evidence(grid: SampleGrid, seg: PlaneSegment, cfg: BackgroundConfig) -> UnderEvidence:
    """What the camera sees under the near edge of the top ``seg`` (camera frame, on ``grid``):
    a ``solid`` front, under it on ``legs``, or too few columns with evidence (``unknown``)."""
    mask = seg.mask
    h, _ = mask.shape
    cols = np.flatnonzero(mask.any(axis=0))
    if len(cols) == 0:
        return "unknown"
    edge = h - 1 - np.argmax(mask[::-1, cols], axis=0)
    gap = max(round(cfg.wall_probe_gap_px / grid.stride), 1)
    reach = max(round(cfg.wall_probe_reach_px / grid.stride), gap)
    steps = np.arange(gap, reach + 1)
    at = edge[:, None] + steps[None, :]
    inside = at < h
    rows = np.where(inside, at, h - 1)
    z_edge = grid.points_cam[edge, cols, 2][:, None]
    z = grid.points_cam[rows, cols[:, None], 2]
    valid = grid.valid[rows, cols[:, None]] & inside
    drop = np.abs(grid.points_cam[rows, cols[:, None], 1] - grid.points_cam[edge, cols, 1][:, None])
    tol = cfg.wall_probe_tolerance_m + cfg.wall_probe_tolerance_frac * z_edge + FRONT_SLOPE * drop
    farther = valid & (z > z_edge + tol)
    level = valid & (np.abs(z - z_edge) <= tol)
    has_edge = edge < h - 1  # the image's bottom edge: no evidence
    is_open = has_edge & farther.any(axis=1)
    is_solid = has_edge & ~is_open & level.any(axis=1)
    n_open, n_solid = int(is_open.sum()), int(is_solid.sum())
    if n_open + n_solid < cfg.wall_probe_min_columns:
        return "unknown"
    return "solid" if n_solid > cfg.wall_open_share * (n_open + n_solid) else "legs"
