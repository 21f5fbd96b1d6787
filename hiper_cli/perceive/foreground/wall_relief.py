"""Objects hung on the walls (a picture, a screen, a board): a surface standing proud of a
mapped wall, seen so from several viewpoints, kept as one ``unknown`` instance.

The background filter takes what lies within its margin of a wall's box, and the map of solid
things (``solid_map.py``) keeps only bodies standing on the floor or a support: a picture 4 cm
deep is neither. At the map's keyframes the depth image's points near each mapped wall (within
``BAND_M`` of its face, ``EDGE_M`` inside its edges) are binned into cells of ``CELL_M`` on the
wall. A cell whose mean distance from the face exceeds the wall's median in that view by
``RELIEF_M``, and by three times the noise of that mean (``NOISE_PER_M2`` · depth², over the
square root of its points), stands proud in that view; within that of the median it is flush.
A cell proud in ``MIN_VIEWS`` views and in ``PROUD_SHARE`` of those that could tell is evidence:
one noisy view, or the pixels at a depth edge, do not repeat from the next viewpoint.

At the end of the log, touching evidence cells are parts. A part is an object hung on the wall
when it is at least ``MIN_SIDE_M`` both ways and ``MAX_SIDE_M`` at most, no more than
``MAX_ASPECT`` times longer than wide (a strip is an edge of the building: a corner the wall's
extent ran past, a door frame, a pillar's side), its lowest cell is
``HUNG_M`` above the floor (lower, it is the back of a thing standing there, which the map of
solid things keeps), and no instance's box lies beside it at its height (``BESIDE_M``: the
head board of a bed against the wall is the bed's).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.solid_map import SolidPart
from hiper_cli.perceive.foreground.surface_samples import SAMPLE_POINTS
from hiper_cli.types import Frame

__all__ = ["WallRelief"]

FloatArray = NDArray[np.float64]
CELL_M = 0.1  # the edge of a cell on the wall
STEP_PX = 4  # every STEP_PX-th pixel both ways is looked at
BAND_M = 0.15  # points at most this far in front of a wall's face (and 0.1 m behind it) are its
EDGE_M = 0.15  # ... and at least this far inside its edges (not the next wall, not a door frame)
MIN_POINTS = 4  # a cell with fewer points in a view tells nothing
MIN_CELLS_VIEW = 10  # a wall with fewer cells in a view gives no median
RELIEF_M = 0.02  # a cell this much in front of the wall's median stands proud ...
NOISE_PER_M2 = 0.0015  # ... and three times the depth noise of its mean (σ = this · depth², per point)
MIN_VIEWS = 2  # proud in this many views at least ...
PROUD_SHARE = 0.6  # ... and in this share of the views that told proud from flush
MIN_CELLS = 4  # a part of fewer cells is noise
MIN_SIDE_M = 0.2  # a part at least this wide and high ...
MAX_SIDE_M = 2.5  # ... and at most this: longer runs are the wall's own relief (a skirting, a beam)
MAX_ASPECT = 4.0  # ... and at most this many times longer than wide: an edge of the building
HUNG_M = 0.3  # its lowest cell this far above the floor: hung, not the back of a thing standing
BESIDE_M = 0.2  # an instance's box this near across the floor, at the part's height, owns it
FOLD_EVERY = 64  # views kept aside before they are folded into the counts per cell
_OFFSET = 1 << 20  # cell indices are packed into one int64 key, 21 bits each
_BITS = 21


class WallRelief:
    """Per cell on the walls ever told (packed keys of its map-frame position, sorted): the
    views that saw it proud, those that saw it flush, and when it was first and last proud
    (see the module docstring). Memory grows with the walls' area, not with the log's length."""

    def __init__(self) -> None:
        self._keys = np.zeros(0, dtype=np.int64)
        self._proud = np.zeros(0, dtype=np.int64)
        self._flush = np.zeros(0, dtype=np.int64)
        self._first_s = np.zeros(0, dtype=np.float64)
        self._last_s = np.zeros(0, dtype=np.float64)
        self._pending: list[tuple[NDArray[np.int64], NDArray[np.int64], float]] = []  # views not folded yet

    def add(self, frame: Frame, walls: Sequence[Box3D]) -> None:
        """One keyframe: its depth image against the walls mapped so far."""
        if not walls:
            return
        depth = frame.depth_m[::STEP_PX, ::STEP_PX].astype(np.float64)
        v, u = np.nonzero(depth > 0)
        z = depth[v, u]
        cam = frame.camera
        u_px, v_px = u * STEP_PX + 0.5, v * STEP_PX + 0.5
        points_cam = np.stack([(u_px - cam.cx) / cam.fx * z, (v_px - cam.cy) / cam.fy * z, z], axis=1)
        T = np.asarray(frame.T_map_cam, dtype=np.float64)
        points = points_cam @ T[:3, :3].T + T[:3, 3]
        for wall in walls:
            self._look(wall, points, z, T[:3, 3], frame.stamp_s)

    def _look(self, wall: Box3D, points: FloatArray, z: FloatArray, eye: FloatArray, stamp_s: float) -> None:
        """Count, per cell of ``wall`` in this view, whether it stood proud or flush."""
        thin = int(np.argmin(wall.extent_m))
        across = [k for k in range(3) if k != thin]
        normal = wall.R[:, thin] * (1.0 if (eye - wall.center_m) @ wall.R[:, thin] >= 0 else -1.0)
        off = points @ normal - (float(wall.center_m @ normal) + wall.extent_m[thin] / 2.0)
        near = np.flatnonzero((off > -CELL_M) & (off < BAND_M))  # the plane's band first: cheap
        if len(near) < MIN_POINTS * MIN_CELLS_VIEW:
            return
        local = (points[near] - wall.center_m) @ wall.R[:, across]
        inside = np.all(np.abs(local) <= wall.extent_m[across] / 2.0 - EDGE_M, axis=1)
        on = near[inside]
        if len(on) < MIN_POINTS * MIN_CELLS_VIEW:
            return
        on_wall = points[on] - np.outer(off[on], normal)  # onto the face: the cell is where on the wall
        keys, inverse, counts = np.unique(_pack(np.floor(on_wall / CELL_M).astype(np.int64)),
                                          return_inverse=True, return_counts=True)
        inverse = inverse.ravel()
        mean_m = np.bincount(inverse, off[on]) / counts
        depth_m = np.bincount(inverse, z[on]) / counts
        enough = counts >= MIN_POINTS
        if np.count_nonzero(enough) < MIN_CELLS_VIEW:
            return
        relief = mean_m - np.median(mean_m[enough])
        margin = np.maximum(RELIEF_M, 3.0 * NOISE_PER_M2 * depth_m**2 / np.sqrt(counts))
        keys, relief, margin = keys[enough], relief[enough], margin[enough]
        self._count(keys[relief >= margin], keys[np.abs(relief) < margin], stamp_s)

    def _count(self, proud: NDArray[np.int64], flush: NDArray[np.int64], stamp_s: float) -> None:
        """One view's cells (unique keys) that stood ``proud`` and ``flush``: kept aside, and
        folded into the counts every ``FOLD_EVERY`` views (``_fold``)."""
        self._pending.append((proud, flush, stamp_s))
        if len(self._pending) >= FOLD_EVERY:
            self._fold()

    def _fold(self) -> None:
        """Fold the views kept aside into the counts per cell."""
        if not self._pending:
            return
        proud = np.concatenate([p for p, _, _ in self._pending])
        flush = np.concatenate([f for _, f, _ in self._pending])
        stamps = np.concatenate([np.full(len(p), t) for p, _, t in self._pending])
        self._pending = []
        keys, inverse = np.unique(np.concatenate([self._keys, proud, flush]), return_inverse=True)
        old, at_proud = inverse[: len(self._keys)], inverse[len(self._keys): len(self._keys) + len(proud)]
        at_flush = inverse[len(self._keys) + len(proud):]
        counts = np.zeros((2, len(keys)), dtype=np.int64)
        first_s, last_s = np.full(len(keys), np.inf), np.full(len(keys), -np.inf)
        counts[0, old], counts[1, old], first_s[old], last_s[old] = (self._proud, self._flush, self._first_s,
                                                                    self._last_s)
        np.add.at(counts[0], at_proud, 1)
        np.add.at(counts[1], at_flush, 1)
        np.minimum.at(first_s, at_proud, stamps)
        np.maximum.at(last_s, at_proud, stamps)
        self._keys, self._proud, self._flush = keys, counts[0], counts[1]
        self._first_s, self._last_s = first_s, last_s

    def parts(self, floor_z_m: float, instances: Sequence[Box3D]) -> list[SolidPart]:
        """The objects hung on the walls (see the module docstring)."""
        self._fold()
        evidence = np.flatnonzero((self._proud >= MIN_VIEWS)
                                   & (self._proud >= PROUD_SHARE * (self._proud + self._flush)))
        cells = dict(zip(map(tuple, _unpack(self._keys[evidence]).tolist()), evidence.tolist(), strict=True))
        out: list[SolidPart] = []
        for group in _connected(set(cells)):
            if len(group) < MIN_CELLS:
                continue
            ijk = np.array(group, dtype=np.float64)
            lo, hi = ijk.min(axis=0) * CELL_M, (ijk.max(axis=0) + 1.0) * CELL_M
            short, long = np.sort(hi - lo)[1:]  # the two largest: across the wall's face
            shaped = short >= MIN_SIDE_M - 1e-9 and long <= min(MAX_SIDE_M + 1e-9, MAX_ASPECT * short)
            if not shaped or lo[2] < floor_z_m + HUNG_M:
                continue
            if any(_beside(box, lo, hi) for box in instances):
                continue
            at = np.array([cells[key] for key in group], dtype=np.int64)
            proud = int(self._proud[at].sum())
            told = proud + int(self._flush[at].sum())
            centres = (ijk + 0.5) * CELL_M
            out.append(SolidPart(Box3D((lo + hi) / 2.0, hi - lo), float(self._first_s[at].min()),
                                 float(self._last_s[at].max()), [], proud / max(told, 1),
                                 np.round(centres[:SAMPLE_POINTS], 3).tolist()))
        return out


def _beside(box: Box3D, lo: FloatArray, hi: FloatArray) -> bool:
    """Whether ``box`` lies within ``BESIDE_M`` of ``lo``-``hi`` across the floor, overlapping it
    in height."""
    b_lo, b_hi = box.aabb()
    return bool(np.all(b_lo[:2] <= hi[:2] + BESIDE_M) and np.all(b_hi[:2] >= lo[:2] - BESIDE_M)
                and b_lo[2] <= hi[2] and b_hi[2] >= lo[2])


def _pack(ijk: NDArray[np.int64]) -> NDArray[np.int64]:
    shifted = ijk + _OFFSET
    packed = (shifted[:, 0] << (2 * _BITS)) | (shifted[:, 1] << _BITS) | shifted[:, 2]
    return np.asarray(packed, dtype=np.int64)


def _unpack(keys: NDArray[np.int64]) -> NDArray[np.int64]:
    mask = (1 << _BITS) - 1
    return np.stack([(keys >> (2 * _BITS)) & mask, (keys >> _BITS) & mask, keys & mask], axis=1) - _OFFSET


def _connected(cells: set[tuple[int, int, int]]) -> list[list[tuple[int, int, int]]]:
    """The groups of ``cells`` that touch (26-connected)."""
    groups: list[list[tuple[int, int, int]]] = []
    seen: set[tuple[int, int, int]] = set()
    steps = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) != (0, 0, 0)]
    for start in cells:
        if start in seen:
            continue
        seen.add(start)
        group, todo = [], [start]
        while todo:
            cell = todo.pop()
            group.append(cell)
            for di, dj, dk in steps:
                nxt = (cell[0] + di, cell[1] + dj, cell[2] + dk)
                if nxt in cells and nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        groups.append(group)
    return groups
