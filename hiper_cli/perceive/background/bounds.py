"""Whether a vertical plane seen in one depth image bounds the free space like a wall.

A wall reaches from the floor to the ceiling: in the image, right above its top edge the
camera sees the ceiling (or the wall going on), right below its bottom edge the floor at
the wall's foot, both at about the plane's own depth, unless the edge is the image's edge.
A furniture front (a shelf, a wardrobe, a stack of boxes) ends in the room: above or below
it the camera sees farther, or nothing within range. ``edge_evidence`` probes a few samples
beyond the plane's top and bottom edge in every image column it covers and says, for each
edge, whether the plane is ``open`` there (most probes see farther than the plane),
``closed`` (the surface goes on, or the edge is the image's edge) or ``unknown`` (an
occluder in front, too few probes); ``fronts.py`` adds ``front`` at a side edge past which
a parallel surface stands a furniture depth behind.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.planes import PlaneSegment, SampleGrid
from hiper_cli.types import CameraIntrinsics

__all__ = [
    "OPEN",
    "SIDES",
    "UNKNOWN",
    "EdgeEvidence",
    "EdgeProbes",
    "edge_evidence",
    "edge_probes",
    "is_open",
    "line_verdicts",
    "view_bounded",
]

EdgeEvidence = Literal["open", "closed", "unknown", "front"]
_OPEN, _CLOSED, _UNKNOWN, _MISSING = 1, 0, -1, 2
OPEN, UNKNOWN = _OPEN, _UNKNOWN  # a probe or line that sees beyond the plane; no evidence


def _probe(grid: SampleGrid, camera: CameraIntrinsics, plane_cam: NDArray[np.float64],
           rows: NDArray[np.int64], cols: NDArray[np.int64], cfg: BackgroundConfig) -> NDArray[np.int64]:
    """Per probe sample (``rows``, ``cols`` on the grid): open, closed or unknown."""
    stride = grid.stride
    ray = np.stack([
        (cols * stride - camera.cx) / camera.fx,
        (rows * stride - camera.cy) / camera.fy,
        np.ones(len(rows)),
    ], axis=1)
    facing = ray @ plane_cam[:3]
    with np.errstate(divide="ignore", invalid="ignore"):
        z_plane = np.where(facing < -1e-6, -plane_cam[3] / facing, np.inf)
    z = grid.points_cam[rows, cols, 2]
    valid = grid.valid[rows, cols]
    # no deeper than a furniture front's least depth less the depth noise there (``planes.py``'s
    # model, sigma = cell_noise_m z^2): past 3.6 m, 5 % of the depth would take a shelf's book
    # rows, 0.2-0.25 m behind its frame, for the plane going on
    sigma_m = cfg.cell_noise_m * np.clip(z_plane, 1.0, cfg.max_depth_m) ** 2
    tol = np.minimum(cfg.wall_probe_tolerance_m + cfg.wall_probe_tolerance_frac * z_plane,
                     cfg.wall_front_min_m - sigma_m)
    out = np.full(len(rows), _UNKNOWN, dtype=np.int64)
    seen = valid & np.isfinite(z_plane)
    out[seen & (z > z_plane + tol)] = _OPEN
    out[seen & (np.abs(z - z_plane) <= tol)] = _CLOSED
    # no return where the plane would still be well within range: nothing there, or a dropout
    # (``line_verdicts`` weighs it)
    out[~valid & (z_plane < cfg.wall_probe_max_depth_m)] = _MISSING
    return out


@dataclass(frozen=True)
class EdgeProbes:
    """The probes beyond one edge of a plane's mask, one row per image line across the edge
    and one column per step out from it: ``cat`` open / closed / unknown / missing (the
    image's edge is closed), ``rows`` and ``cols`` their samples on the grid, ``inside``
    whether the sample is in the image, ``returned`` whether it has a depth."""

    cat: NDArray[np.int64]
    rows: NDArray[np.int64]
    cols: NDArray[np.int64]
    inside: NDArray[np.bool_]
    returned: NDArray[np.bool_]


def edge_probes(grid: SampleGrid, camera: CameraIntrinsics, seg: PlaneSegment, cfg: BackgroundConfig,
                side: str) -> EdgeProbes | None:
    """The probes beyond one edge of the plane's mask: ``side`` top, bottom, left or right.

    In each image line across the edge the probes lie from ``wall_probe_gap_px`` to
    ``wall_probe_reach_px`` past it. None when the mask is empty."""
    mask = seg.mask if side in ("top", "bottom") else seg.mask.T
    n_along, _ = mask.shape  # probes move along axis 0 of ``mask``
    lines = np.flatnonzero(mask.any(axis=0))
    if len(lines) == 0:
        return None
    gap = max(round(cfg.wall_probe_gap_px / grid.stride), 1)
    reach = max(round(cfg.wall_probe_reach_px / grid.stride), gap)
    steps = np.arange(gap, reach + 1)
    if side in ("top", "left"):
        edge = np.argmax(mask[:, lines], axis=0)
        at = edge[:, None] - steps[None, :]
    else:
        edge = n_along - 1 - np.argmax(mask[::-1, lines], axis=0)
        at = edge[:, None] + steps[None, :]
    line_idx = np.broadcast_to(lines[:, None], at.shape)
    inside = (at >= 0) & (at < n_along)
    cat = np.full(at.shape, _CLOSED, dtype=np.int64)  # the image's edge
    along = np.clip(at, 0, n_along - 1)
    rows, cols = (along, line_idx) if side in ("top", "bottom") else (line_idx, along)
    rows, cols = np.ascontiguousarray(rows), np.ascontiguousarray(cols)
    cat[inside] = _probe(grid, camera, seg.plane_cam, rows[inside], cols[inside], cfg)
    return EdgeProbes(cat, rows, cols, inside, inside & grid.valid[rows, cols])


def line_verdicts(probes: EdgeProbes) -> NDArray[np.int64]:
    """Per image line: open when one of its probes sees beyond the plane (past a furniture
    front's convex corner the side bends away; past a room's concave corner the next wall is
    nearer, an occluder), or when none of its probes has a return where the plane would be
    within range (nothing there); else closed when one lies on the plane or outside the
    image, else unknown. A real sensor loses returns on dark or glossy patches, in the
    projector's shadow and at grazing incidence (docs/sensors.md): missing samples in a line
    that sees the surface go on, or nearer things, are such dropouts, not the room beyond
    (with any missing probe opening its line, a wall 1.9 m away on the degraded bookstore was
    open at its foot in 73 of 148 lines)."""
    cat = probes.cat
    seen = probes.returned.any(axis=1)  # a return in the image past the edge
    open_ = (cat == _OPEN).any(axis=1) | ((cat == _MISSING).any(axis=1) & ~seen)
    return np.where(open_, _OPEN, np.where((cat == _CLOSED).any(axis=1), _CLOSED, _UNKNOWN))


def _edge(grid: SampleGrid, camera: CameraIntrinsics, seg: PlaneSegment, cfg: BackgroundConfig,
          side: str) -> EdgeEvidence:
    """The evidence beyond one edge of the plane's mask (``edge_probes``, ``line_verdicts``)."""
    probes = edge_probes(grid, camera, seg, cfg, side)
    if probes is None:
        return "unknown"
    verdict = line_verdicts(probes)
    n_open = int(np.sum(verdict == _OPEN))
    n_closed = int(np.sum(verdict == _CLOSED))
    if n_open + n_closed < cfg.wall_probe_min_columns:
        return "unknown"
    return "open" if n_open >= cfg.wall_open_share * (n_open + n_closed) else "closed"


SIDES: tuple[str, ...] = ("top", "bottom", "left", "right")


def edge_evidence(grid: SampleGrid, camera: CameraIntrinsics, seg: PlaneSegment,
                  cfg: BackgroundConfig) -> dict[str, EdgeEvidence]:
    """The evidence beyond each edge (``SIDES``) of the plane ``seg`` (camera frame) on ``grid``."""
    return {side: _edge(grid, camera, seg, cfg, side) for side in SIDES}


def is_open(edges: dict[str, EdgeEvidence]) -> bool:
    """Whether a wall candidate ends in the room: open above or below (it does not reach the
    ceiling or the floor), or a ``front`` at one side (``fronts.py``: a parallel surface, or
    its own side face, a furniture depth behind). Open at both sides alone is no end: a wall
    between two doorways is, seen whole."""
    sides = (edges.get("left"), edges.get("right"))
    return edges.get("top") == "open" or edges.get("bottom") == "open" or "front" in sides


def view_bounded(grid: SampleGrid, camera: CameraIntrinsics, seg: PlaneSegment,
                 cfg: BackgroundConfig) -> bool:
    """Whether a vertical plane is seen as tall as the view allows: its mask reaches the
    image's top row in most of its columns and below it the camera does not see past it
    (the bottom edge not ``open``: something in front or against it). Beyond 4 m a camera
    1.2 m high, pitched 15° down, sees a wall up to about 2 m; over bookshelves 1.06 m tall
    standing at it, 0.95 m of it shows."""
    cols = np.flatnonzero(seg.mask.any(axis=0))
    if len(cols) == 0:
        return False
    top = np.argmax(seg.mask[:, cols], axis=0)
    if np.mean(top <= 1) < cfg.wall_open_share:
        return False
    return _edge(grid, camera, seg, cfg, "bottom") != "open"
