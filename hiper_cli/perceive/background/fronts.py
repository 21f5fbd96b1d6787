"""Whether a vertical plane is a furniture front: something a furniture depth stands behind it.

A wardrobe, a fridge or a row of bookshelves stands against a wall: past the side edge of
its front the camera sees the wall behind it, parallel to the front and a furniture depth
(0.3-0.8 m) back (``front_sides``). Standing free in a room, seen from beside its front, it
shows its own side face running that depth back from the front's edge and ending there
(``deep_sides``). A wall ends at a corner (the next wall is nearer, or turns away and goes
on), at a doorway (the wall's thickness, then the room beyond, at any depth) or at a door
recessed into it (parallel, but only the wall's thickness back): a wall seen whole between
two doorways is open at both its sides, and still a wall.

``front_sides`` probes past the left and right edges of a plane (``bounds.edge_probes``)
and names the sides where the samples seen beyond the plane (those on no plane of the
image, or on one parallel to it) lie, at their median, between ``wall_front_min_m`` and
``wall_front_max_m`` behind it, and in most image lines with evidence most of them lie
within the inlier distance (``inlier_m`` times their depth) of that median: on a surface
parallel to the plane. Past a wall's end the room beyond, its floor or a wall turning away
spread over many depths along a line. A wardrobe in a room's corner shows this at one side
only; the other is the corner.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.background.bounds import OPEN, UNKNOWN, edge_probes, line_verdicts
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.planes import PlaneSegment, SampleGrid
from hiper_cli.types import CameraIntrinsics

__all__ = ["deep_sides", "front_sides", "segment_labels"]


def segment_labels(shape: tuple[int, int], segments: Sequence[PlaneSegment]) -> NDArray[np.int64]:
    """Per grid sample, the index of the plane in ``segments`` it belongs to, or -1."""
    labels = np.full(shape, -1, dtype=np.int64)
    for k, seg in enumerate(segments):
        labels[seg.mask] = k
    return labels


def front_sides(grid: SampleGrid, camera: CameraIntrinsics, seg: PlaneSegment,
                segments: Sequence[PlaneSegment], labels: NDArray[np.int64],
                cfg: BackgroundConfig) -> list[str]:
    """The side edges (``left``, ``right``) of ``seg`` (camera frame, on ``grid``) past which
    a surface parallel to it stands a furniture depth behind it. ``segments`` are the image's
    planes, ``labels`` their samples (``segment_labels``): a sample on a plane that is not
    parallel to ``seg`` (the floor, the ceiling, a wall across) is no sample of that surface."""
    normal, offset = seg.plane_cam[:3], float(seg.plane_cam[3])
    planes = np.array([s.plane_cam for s in segments]).reshape(-1, 4)
    parallel = np.append(planes[:, :3] @ normal >= np.cos(np.radians(cfg.merge_angle_deg)), True)
    out: list[str] = []
    for side in ("left", "right"):
        probes = edge_probes(grid, camera, seg, cfg, side)
        if probes is None:
            continue
        n_evidence = int(np.sum(line_verdicts(probes) != UNKNOWN))
        beyond = probes.inside & (probes.cat == OPEN) & grid.valid[probes.rows, probes.cols]
        beyond &= parallel[labels[probes.rows, probes.cols]]  # -1: on no plane, kept
        if not beyond.any():
            continue
        points = grid.points_cam[probes.rows[beyond], probes.cols[beyond]]
        behind_m = -(points @ normal + offset)  # the normal faces the camera
        back_m = float(np.median(behind_m))
        if not cfg.wall_front_min_m <= back_m <= cfg.wall_front_max_m:
            continue
        near = np.abs(behind_m - back_m) <= cfg.inlier_m * points[:, 2]
        on_back = np.zeros(probes.cat.shape, dtype=bool)
        on_back[beyond] = near
        if not _parallel(on_back, behind_m[near], points[near, 2], grid.stride / camera.fx):
            continue  # a surface turning away from the plane (a wall across it, seen face on)
        n_beyond = beyond.sum(axis=1)
        n_front = int(np.sum((n_beyond > 0) & (on_back.sum(axis=1) >= cfg.wall_open_share * n_beyond)))
        if n_front >= max(cfg.wall_probe_min_columns, cfg.wall_open_share * n_evidence):
            out.append(side)
    return out


def _parallel(on_back: NDArray[np.bool_], behind_m: NDArray[np.float64], depth_m: NDArray[np.float64],
              step_rad: float) -> bool:
    """Whether the samples ``on_back`` (lines × probe steps; ``behind_m`` and ``depth_m`` of
    its true entries in order) lie on a surface parallel to the plane rather than across it:
    along each image line their depth behind the plane changes by less than the sideways
    distance between them (``step_rad`` × depth per step), pooled over the lines (a least
    squares slope below 1, 45 degrees). Depth noise spreads a narrow strip of wall behind a
    shelf at 4 m as much in depth as across, but does not tilt it; a wall turning away, seen
    face on, lies at one place across and at many depths."""
    lines, steps = np.nonzero(on_back)
    across_m = steps * step_rad * depth_m
    n = np.bincount(lines, minlength=on_back.shape[0]).astype(np.float64)
    if np.sum(n >= 2) < 2:
        return False
    safe = np.maximum(n, 1.0)
    u = across_m - (np.bincount(lines, across_m, on_back.shape[0]) / safe)[lines]
    d = behind_m - (np.bincount(lines, behind_m, on_back.shape[0]) / safe)[lines]
    return bool(abs(float(u @ d)) < float(u @ u))


def deep_sides(grid: SampleGrid, seg: PlaneSegment, height_m: NDArray[np.float64],
               cfg: BackgroundConfig) -> list[str]:
    """The side edges (``left``, ``right``) of ``seg`` (camera frame, on ``grid``) past which
    the camera sees a side face a furniture depth long: along the image line out from the
    edge the surface goes on without a depth jump, away from the plane, above the floor
    (``height_m``: every sample's height in the map), and ends, with a jump to farther,
    between ``wall_front_min_m`` and ``wall_front_max_m`` behind the plane, in most of the
    edge's lines. A wall's end at a doorway is its thickness deep; round a room's outer
    corner the next wall goes on (at a grazing angle near the range's end it breaks up: a few
    lines only)."""
    normal, offset = seg.plane_cam[:3], float(seg.plane_cam[3])
    w = seg.mask.shape[1]
    reach = max(round(2.0 * cfg.wall_probe_reach_px / grid.stride), 2)
    out: list[str] = []
    rows = np.flatnonzero(seg.mask.any(axis=1))
    if len(rows) == 0:
        return out
    for side, step in (("left", -1), ("right", 1)):
        if step < 0:
            edge = np.argmax(seg.mask[rows], axis=1)
        else:
            edge = w - 1 - np.argmax(seg.mask[rows, ::-1], axis=1)
        cols = edge[:, None] + step * np.arange(reach + 1)[None, :]
        inside = (cols >= 0) & (cols < w)
        cols = np.clip(cols, 0, w - 1)
        r = np.broadcast_to(rows[:, None], cols.shape)
        z = grid.points_cam[r, cols, 2]
        valid = inside & grid.valid[r, cols]
        usable = valid & (height_m[r, cols] > cfg.floor_max_height_m)
        behind = -(grid.points_cam[r, cols] @ normal + offset)
        dz = np.diff(z, axis=1)
        smooth = np.abs(dz) <= cfg.join_jump_frac * z[:, :-1]
        # beyond the side face: a furniture depth farther (a wall turning away at a grazing
        # angle breaks into smaller steps), or no return where the face ended well within
        # range (nothing there; at the range's end a wall turning away fades out instead)
        no_return = inside[:, 1:] & ~valid[:, 1:] & (z[:, :-1] < cfg.wall_probe_max_depth_m)
        farther = (valid[:, 1:] & (np.diff(behind, axis=1) >= cfg.wall_front_min_m)) | no_return
        # the run: samples 0 .. end - 1 of a line, joined without a jump
        joined = smooth & usable[:, 1:] & usable[:, :-1]
        end = np.argmin(np.concatenate([joined, np.zeros((len(rows), 1), dtype=bool)], axis=1), axis=1) + 1
        in_run = np.arange(reach + 1)[None, :] < end[:, None]
        depth_m = np.where(in_run, behind, -np.inf).max(axis=1)
        seen = end >= 2  # a side face seen past the edge
        goes_on = seen & (depth_m > cfg.wall_front_max_m)  # round a room's corner, the next wall
        ends = seen & ~goes_on & (end <= reach)
        ends &= farther[np.arange(len(rows)), np.minimum(end, reach) - 1]  # with a jump back
        n_deep = int(np.sum(ends & (depth_m >= cfg.wall_front_min_m)))
        thin = ends & (depth_m < cfg.wall_front_min_m)  # a wall's thickness
        n_other = int(np.sum(goes_on)) + int(np.sum(thin))
        if n_deep >= max(cfg.wall_probe_min_columns, cfg.wall_open_share * len(rows)) and n_deep > n_other:
            out.append(side)
    return out
