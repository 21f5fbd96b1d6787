"""Geometry-only objects: solid things the depth shows that no instance holds (a pallet, a box
stack, a bucket, a shelf), fused over views in a voxel map and kept as ``unknown`` instances.

A track of unnamed blobs becomes an instance only when the camera saw the whole object
(``whole.py``), which a stack longer than a metre, or one always cut by the image's border,
never is; nor does a track that detections named once or twice. This map asks instead
whether a surface is *there*. At keyframes (every ``KEYFRAME_S``, and whenever the camera
turned ``KEYFRAME_TURN_RAD`` or moved ``KEYFRAME_MOVE_M``) the points of the not flat blobs of
every class but the walkers', and of the clusters too long for one object (a rack seen along
its length), add their voxels (``VOXEL_M``), and every voxel kept so far is projected into the
depth image: measured at its depth, the surface is seen there again; measured well behind it,
the camera looked through it (expected, not seen). A voxel found there in ``MIN_SEEN_SHARE``
of the keyframes that could tell is evidence; a passing person, flying pixels at a depth edge
and a drifting fragment are seen through from the next viewpoint and are not.

At the end of the log the evidence voxels outside the background, and outside the columns
that reach the mapped ceiling (a wall or a pillar the background missed), are grouped into parts:
neighbours (voxels one above the other across a gap of ``STACK_GAP_M`` too: a rack's boards)
join unless the keyframes' blobs held them apart as often as together or more (a chair at a
desk, two stacks side by side). Where the depth is poor the blobs run touching things
together, and stray points at their depth edges bridge the gap between them: a voxel found
at fewer than ``FIRM_SEEN`` keyframes is weak evidence, which joins a part but never two. A
part whose firm voxels fall into bodies that touch through a neck of at most
``NECK_VOXELS``, stand side by side and are each an object by themselves is those bodies.
A part longer than ``MAX_EXTENT_M`` is several things run together (a row of shelves): it
is parted into compact pieces. A part is an
object when its voxels were found there at ``MIN_SEEN_PART`` keyframes (median), it is solid
(not one sheet of voxels), large enough, stands on the floor or a support over its footprint
(``BASE_REACH_M``), and no instance of the session (any class) covers it. Nothing stands inside
the floor: a part with ``SUNK_SHARE`` of its voxels deeper than ``SUNK_M`` under it is the
floor seen at range (depth noise spreads below the surface as above it); a part with fewer
is a thing with stray points under it, judged without them. Its box is the box
of its voxels.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.surface_samples import SAMPLE_POINTS
from hiper_cli.perceive.foreground.whole import thickness_m
from hiper_cli.types import Frame

__all__ = ["KEYFRAME_S", "SolidMap", "SolidPart", "is_solid", "overlap_share"]

FloatArray = NDArray[np.float64]
KEYFRAME_S = 0.5  # the static map is refined at least this often (s of log) ...
KEYFRAME_TURN_RAD = np.deg2rad(10.0)  # ... and whenever the camera turned this much since ...
KEYFRAME_MOVE_M = 0.3  # ... or moved this far
VOXEL_M = 0.1  # edge of a voxel of the map
MIN_SEEN_SHARE = 0.6  # of the keyframes that could tell, the share that found a voxel's surface
MIN_SEEN_PART = 2  # a part: its voxels found there at this many keyframes (median)
NOISE_M = 0.02  # depth noise at 1 m; a surface is "there" within VOXEL_M + NOISE_M · z² of it
FIRM_SEEN = 4  # a voxel found at fewer keyframes is weak evidence: it joins a part, never two
NECK_VOXELS = 4  # ... and the bodies they part it into touch through this many voxels each at most
ATTACH_STEPS = 4  # ... the part of a firm voxel at most this many steps away (else its own)
STACK_GAP_M = 0.4  # voxels one above the other across at most this gap are one part
MIN_VOXELS = 10  # a part with fewer is debris, not an object (0.01 m³ of surface at 0.1 m)
MIN_HEIGHT_M = 0.15  # ... or lower than this
MIN_THICKNESS_M = 0.05  # the spread of a part's voxels across their thinnest direction: a sheet
BASE_REACH_M = 0.25  # its lowest voxel this near the floor or a support top: it stands there
SUNK_M = 0.15  # ... and not further below it (depth noise): deeper, it is the floor seen at range
SUNK_SHARE = 0.1  # a part with this share of its voxels deeper than SUNK_M under the floor is the floor
CEILING_REACH_M = 0.3  # its top this near the ceiling: it is the building's, or joined to it
MAX_EXTENT_M = 4.5  # a longer part is several things run together: it is parted in pieces
MAX_PIECES = 8  # ... at most this many
MIN_PIECE_FILL = 0.5  # a piece covers this share of its box's footprint at least
FLAT_M = 0.01  # a blob whose points spread less than this (σ, plus FLAT_PER_M2 · depth²) across
FLAT_PER_M2 = 0.0015  # ... their thinnest direction is a piece of a surface: it adds no voxels
COVERED_SHARE = 0.3  # a part whose box an instance's box covers by this share of it is that one
_OFFSET = 1 << 20  # voxel indices are packed into one int64 key, 21 bits each
_BITS = 21


_Support = tuple[FloatArray, FloatArray, float]  # a support's footprint (lower, upper corner, m) and top


def is_solid(points_cam: FloatArray) -> bool:
    """Whether a blob's points (camera frame) spread across their thinnest direction by more
    than the depth noise: a body, not a piece of a wall or a furniture side."""
    if len(points_cam) < 4:
        return False
    depth_m = float(np.median(points_cam[:, 2]))
    return thickness_m(points_cam) >= FLAT_M + FLAT_PER_M2 * depth_m * depth_m


def _pack(ijk: NDArray[np.int64]) -> NDArray[np.int64]:
    shifted = ijk + _OFFSET
    return (shifted[:, 0] << (2 * _BITS)) | (shifted[:, 1] << _BITS) | shifted[:, 2]


def _centres(keys: NDArray[np.int64]) -> FloatArray:
    """The centres (N, 3; map frame, m) of the voxels ``keys``."""
    return np.asarray((_unpack(keys) + 0.5) * VOXEL_M, dtype=np.float64)


def _unpack(keys: NDArray[np.int64]) -> NDArray[np.int64]:
    mask = (1 << _BITS) - 1
    return np.stack([(keys >> (2 * _BITS)) & mask, (keys >> _BITS) & mask, keys & mask], axis=1) - _OFFSET


@dataclass(frozen=True)
class SolidPart:
    """One geometry-only object: its box (map frame), when it was first and last held, the
    observations of the blobs that held it, and the share of views that found it there."""

    box: Box3D
    first_seen_s: float
    last_seen_s: float
    observation_uuids: list[str]
    seen_share: float
    surface_m: list[list[float]]  # up to SAMPLE_POINTS of its voxel centres: a later session's sample


class SolidMap:
    """The voxel map of solid surfaces (see the module docstring)."""

    def __init__(self) -> None:
        self._keys = np.zeros(0, dtype=np.int64)  # sorted
        self._seen = np.zeros(0, dtype=np.int32)
        self._free = np.zeros(0, dtype=np.int32)
        self._first_s = np.zeros(0, dtype=np.float64)
        self._last_s = np.zeros(0, dtype=np.float64)
        # per blob added: its observation's uuid, its keyframe and its voxels' keys
        self._blobs: list[tuple[str, int, NDArray[np.int64]]] = []
        self._keyframes = 0
        self._last_keyframe_s: float | None = None
        self._last_pose: FloatArray | None = None  # T_map_cam of the last keyframe

    def due(self, stamp_s: float, T_map_cam: FloatArray | None = None) -> bool:
        """Whether a frame is a keyframe: ``KEYFRAME_S`` after the last one, or a new viewpoint
        (the camera turned by ``KEYFRAME_TURN_RAD`` or moved by ``KEYFRAME_MOVE_M`` since): a
        camera sweeping past a shelf sees each of its voxels in several keyframes."""
        if self._last_keyframe_s is None or stamp_s - self._last_keyframe_s >= KEYFRAME_S:
            return True
        if T_map_cam is None or self._last_pose is None:
            return False
        turn = np.clip((np.trace(self._last_pose[:3, :3].T @ T_map_cam[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)
        moved_m = float(np.linalg.norm(T_map_cam[:3, 3] - self._last_pose[:3, 3]))
        return float(np.arccos(turn)) >= KEYFRAME_TURN_RAD or moved_m >= KEYFRAME_MOVE_M

    def add(self, frame: Frame, blobs: Sequence[tuple[str, FloatArray]]) -> None:
        """One keyframe: ``blobs`` are (observation uuid, map points) of its solid blobs (walkers'
        left out: what walks is no part of the static map)."""
        self._last_keyframe_s = frame.stamp_s
        self._last_pose = np.asarray(frame.T_map_cam, dtype=np.float64)
        self._keyframes += 1
        self._look(frame)  # the voxels kept so far: there, or seen through
        held: list[NDArray[np.int64]] = []
        for uuid, points in blobs:
            if len(points) == 0:
                continue
            keys = np.unique(_pack(np.floor(points / VOXEL_M).astype(np.int64)))
            self._blobs.append((uuid, self._keyframes, keys))
            held.append(keys)
        if not held:
            return
        keys = np.unique(np.concatenate(held))
        new = np.setdiff1d(keys, self._keys, assume_unique=True)
        if len(new):
            self._insert(new, frame.stamp_s)
        self._last_s[np.searchsorted(self._keys, keys)] = frame.stamp_s

    def _insert(self, new: NDArray[np.int64], stamp_s: float) -> None:
        keys = np.concatenate([self._keys, new])
        order = np.argsort(keys, kind="stable")
        self._keys = keys[order]
        n = len(new)
        self._seen = np.concatenate([self._seen, np.ones(n, np.int32)])[order]  # the view that found it
        self._free = np.concatenate([self._free, np.zeros(n, np.int32)])[order]
        self._first_s = np.concatenate([self._first_s, np.full(n, stamp_s)])[order]
        self._last_s = np.concatenate([self._last_s, np.full(n, stamp_s)])[order]

    def _look(self, frame: Frame) -> None:
        """Count, per kept voxel in the camera's view, whether the depth image finds a surface
        at it (seen) or well behind it (free); nearer depth or no return tells nothing."""
        if not len(self._keys):
            return
        centres = _centres(self._keys)
        T_cam_map = np.linalg.inv(frame.T_map_cam)
        p = centres @ T_cam_map[:3, :3].T + T_cam_map[:3, 3]
        z = p[:, 2]
        cam = frame.camera
        ok = z > VOXEL_M
        safe_z = np.where(ok, z, 1.0)
        u = np.floor(cam.fx * p[:, 0] / safe_z + cam.cx).astype(np.int64)
        v = np.floor(cam.fy * p[:, 1] / safe_z + cam.cy).astype(np.int64)
        ok &= (u >= 0) & (u < cam.width) & (v >= 0) & (v < cam.height)
        idx = np.flatnonzero(ok)
        measured = frame.depth_m[v[idx], u[idx]].astype(np.float64)
        margin = VOXEL_M + NOISE_M * z[idx] ** 2
        there = (measured > 0) & (np.abs(measured - z[idx]) <= margin)
        through = measured > z[idx] + margin
        self._seen[idx[there]] += 1
        self._free[idx[through]] += 1

    def confirmed(self, box: Box3D) -> bool:
        """Whether what lies in ``box`` (map frame) may exist: False only when the map holds
        voxels there, no keyframe but the one that found each saw it again, and a later one
        looked through where it was (a passer-by's piece, a smear of stray points). Nothing
        there, or nothing seen since, tells nothing."""
        lo, hi = box.aabb()
        centres = _centres(self._keys)
        inside = np.all((centres >= lo - VOXEL_M / 2.0) & (centres <= hi + VOXEL_M / 2.0), axis=1)
        if not np.any(inside):
            return True
        return int(self._seen[inside].max()) >= 2 or int(self._free[inside].sum()) == 0

    def parts(self, floor_z_m: float, supports: Sequence[Box3D], taken: Sequence[Box3D],
              background: Sequence[Box3D], ceiling_z_m: float | None = None) -> list[SolidPart]:
        """The geometry-only objects: evidence voxels outside the ``background`` boxes, grouped
        into connected parts, kept when found there again, solid, standing and not ``taken`` by
        an instance (see the module docstring)."""
        told = self._seen + self._free
        evidence = self._seen >= MIN_SEEN_SHARE * np.maximum(told, 1)
        idx = np.flatnonzero(evidence)
        if len(idx):
            centres = _centres(self._keys[idx])
            inside = np.zeros(len(idx), dtype=bool)
            for box in background:  # in the box's own axes: a wall at an angle holds no room
                local = (centres - box.center_m) @ box.R
                inside |= np.all(np.abs(local) <= box.extent_m / 2.0, axis=1)
            idx = idx[~inside]
        if ceiling_z_m is not None and len(idx):
            idx = idx[~_building_columns(_unpack(self._keys[idx]), ceiling_z_m)]
        if not len(idx):
            return []
        labels = np.full(len(self._keys), -1, dtype=np.int64)
        bodies = np.full(len(self._keys), -1, dtype=np.int64)
        labels[idx], bodies[idx] = self._grouped(idx)
        held = self._held_by(labels)
        # what a part may stand on: the supports' tops over their footprints; the floor's height
        # anywhere while the background has mapped no support
        tops = [(b.aabb()[0][:2], b.aabb()[1][:2], float(b.aabb()[1][2])) for b in supports] or [
            (np.full(2, -np.inf), np.full(2, np.inf), floor_z_m)]
        out: list[SolidPart] = []
        for label in range(int(labels.max()) + 1):
            frames, uuids = held.get(label, (set(), []))
            if not frames:
                continue
            members = np.flatnonzero(labels == label)
            for piece in _pieces(members, _centres(self._keys[members])):
                if np.median(self._seen[piece]) < MIN_SEEN_PART:
                    continue
                below = _centres(self._keys[piece])[:, 2] < floor_z_m - SUNK_M
                if np.mean(below) >= SUNK_SHARE:
                    continue  # the floor seen at range: its noise spreads below it as above
                piece = piece[~below]  # a few stray points under the floor: no part of the thing
                out += self._bodies(piece, bodies[piece], (tops, ceiling_z_m), taken, uuids)
        return out

    def _bodies(self, piece: NDArray[np.int64], body: NDArray[np.int64],
                levels: tuple[Sequence[_Support], float | None], taken: Sequence[Box3D],
                uuids: list[str]) -> list[SolidPart]:
        """The objects of one piece (voxel indices): the bodies its firm voxels part it into
        (``body``: their labels; a body is firm for the most part) when each of them
        is an object by itself, standing where it is; else the piece as one object."""
        split = [piece[body == b] for b in np.unique(body)]
        split = [s for s in split if len(s) >= MIN_VOXELS and np.median(self._seen[s]) >= FIRM_SEEN]
        if len(split) >= 2 and _necked(self._keys, split):
            parts = [self._part(s, levels, taken, uuids) for s in split]
            kept = [p for p in parts if p is not None]
            if len(kept) == len(parts) and _side_by_side([p.box for p in kept]):
                return kept
        whole = self._part(piece, levels, taken, uuids)
        return [] if whole is None else [whole]

    def _grouped(self, idx: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Labels 0..k-1 of the parts of the voxels ``idx``: neighbours (26-connected, or one above
        the other across ``STACK_GAP_M``) are one part unless the keyframes' blobs held them apart
        as often as together or more (a chair at a desk, a box beside a bucket: the segmenter parts
        them wherever a view shows the gap between them). A voxel that two blobs of one view
        held, in most of its views, lies between two things: it joins a neighbour's part, but
        joins no parts together."""
        a, b = _neighbour_pairs(_unpack(self._keys[idx]))
        together, apart, between = self._votes(idx, a, b)
        keep = ((together > apart) | (together + apart == 0)) & ~between[a] & ~between[b]
        weak = self._seen[idx] < FIRM_SEEN
        labels = _labels(len(idx), a, b, keep)
        bodies = _attached(_labels(len(idx), a, b, keep & ~weak[a] & ~weak[b]), weak, a[keep], b[keep])
        for x, y in ((a, b), (b, a)):  # a voxel between two things takes a neighbour's part
            join = between[x] & ~between[y]
            labels[x[join]] = labels[y[join]]
            bodies[x[join]] = bodies[y[join]]
        return np.asarray(labels, dtype=np.int64), bodies

    def _votes(self, idx: NDArray[np.int64], a: NDArray[np.int64], b: NDArray[np.int64]
               ) -> tuple[NDArray[np.int32], NDArray[np.int32], NDArray[np.bool_]]:
        """Per pair (``a``, ``b``: indices into ``idx``), the keyframes whose blobs held both
        voxels in one blob and in two; per voxel, whether two blobs of one keyframe held it in
        most of the keyframes that held it."""
        together = np.zeros(len(a), dtype=np.int32)
        apart = np.zeros(len(a), dtype=np.int32)
        held = np.zeros(len(idx), dtype=np.int32)
        shared = np.zeros(len(idx), dtype=np.int32)
        where = np.full(len(self._keys), -1, dtype=np.int64)
        where[idx] = np.arange(len(idx))
        blob_of = np.full(len(idx), -1, dtype=np.int64)
        keyframe = None
        for n, (_, kf, keys) in enumerate([*self._blobs, ("", -1, np.zeros(0, np.int64))]):
            if kf != keyframe:  # one keyframe's blobs are all in: count its votes
                la, lb = blob_of[a], blob_of[b]
                both = (la >= 0) & (lb >= 0)
                together += both & (la == lb)
                apart += both & (la != lb)
                held += blob_of != -1
                shared += blob_of == -2
                keyframe = kf
                blob_of[:] = -1
            at = where[np.searchsorted(self._keys, keys)]
            at = at[at >= 0]
            blob_of[at] = np.where(blob_of[at] == -1, n, -2)  # -2: two blobs of one view held it
        return together, apart, 2 * shared > held

    def _held_by(self, labels: NDArray[np.int64]) -> dict[int, tuple[set[int], list[str]]]:
        """Per part label, the keyframes and observations of the blobs whose voxels lie in it
        for the most part."""
        held: dict[int, tuple[set[int], list[str]]] = {}
        for uuid, keyframe, keys in self._blobs:
            of = labels[np.searchsorted(self._keys, keys)]
            of = of[of >= 0]
            if not len(of):
                continue
            values, counts = np.unique(of, return_counts=True)
            best = int(np.argmax(counts))
            if counts[best] >= 0.5 * len(keys):
                frames, uuids = held.setdefault(int(values[best]), (set(), []))
                frames.add(keyframe)
                if uuid:  # a cluster too large for one object has no observation
                    uuids.append(uuid)
        return held

    def _part(
        self, members: NDArray[np.int64], levels: tuple[Sequence[_Support], float | None],
        taken: Sequence[Box3D], uuids: list[str],
    ) -> SolidPart | None:
        """The object of one connected part (``members``: voxel indices), or None when it is
        debris, a sheet, afloat, reaching the ceiling, too long or an instance's already;
        ``levels``: the tops of the floor and the supports, and the ceiling's height (None:
        none mapped)."""
        tops, ceiling_z_m = levels
        if len(members) < MIN_VOXELS:
            return None
        centres = _centres(self._keys[members])
        lo, hi = centres.min(axis=0) - VOXEL_M / 2.0, centres.max(axis=0) + VOXEL_M / 2.0
        extent = hi - lo
        if extent[2] < MIN_HEIGHT_M or max(float(extent[0]), float(extent[1])) > MAX_EXTENT_M:
            return None
        if not any(-SUNK_M <= float(lo[2]) - top <= BASE_REACH_M  # stands on a support, over its footprint
                   and np.all(lo[:2] < s_hi) and np.all(hi[:2] > s_lo) for s_lo, s_hi, top in tops):
            return None
        if ceiling_z_m is not None and float(hi[2]) >= ceiling_z_m - CEILING_REACH_M:
            return None  # from the floor to the ceiling: building structure, or run into it
        if _thinnest_spread_m(centres) < MIN_THICKNESS_M:
            return None
        box = Box3D((lo + hi) / 2.0, extent)
        if any(overlap_share(box, other) >= COVERED_SHARE for other in taken):
            return None
        told = self._seen[members] + self._free[members]
        sample = centres[np.linspace(0, len(centres) - 1, min(len(centres), SAMPLE_POINTS)).astype(np.int64)]
        return SolidPart(box, float(self._first_s[members].min()), float(self._last_s[members].max()),
                         uuids, float(self._seen[members].sum() / max(int(told.sum()), 1)),
                         np.round(sample, 3).tolist())


def _pieces(members: NDArray[np.int64], centres: FloatArray) -> list[NDArray[np.int64]]:
    """``members`` (voxel indices, their ``centres``) in pieces at most ``MAX_EXTENT_M`` long
    across the floor: a part longer than one object is several run together (a row of
    shelves, a desk with its chairs), parted where nothing tells where: into the fewest
    compact pieces (k-means over the footprint, seeded at voxels far apart)."""
    xy = centres[:, :2]
    if float(np.max(np.ptp(xy, axis=0))) <= MAX_EXTENT_M:
        return [members]
    for k in range(2, MAX_PIECES + 1):
        seeds = [0]
        for _ in range(k - 1):  # each next seed the voxel farthest from those chosen
            gap = np.min(np.linalg.norm(xy[:, None, :] - xy[seeds][None, :, :], axis=2), axis=1)
            seeds.append(int(np.argmax(gap)))
        means = xy[seeds]
        for _ in range(20):
            nearest = np.argmin(np.linalg.norm(xy[:, None, :] - means[None, :, :], axis=2), axis=1)
            means = np.array([xy[nearest == j].mean(axis=0) if np.any(nearest == j) else means[j]
                              for j in range(k)])
        groups = [np.flatnonzero(nearest == j) for j in range(k) if np.any(nearest == j)]
        if all(_compact(xy[g]) for g in groups) or k == MAX_PIECES:
            return [members[g] for g in groups]
    return [members]


def _compact(xy: FloatArray) -> bool:
    """Whether voxel centres ``xy`` (N, 2) are one piece: at most ``MAX_EXTENT_M`` long, and
    filling ``MIN_PIECE_FILL`` of their box's footprint (the corner of an L-shaped row is two)."""
    extent = np.ptp(xy, axis=0) + VOXEL_M
    if float(np.max(extent)) > MAX_EXTENT_M + VOXEL_M:
        return False
    cells = len(np.unique(np.round(xy / VOXEL_M).astype(np.int64), axis=0))
    return cells * VOXEL_M * VOXEL_M >= MIN_PIECE_FILL * float(np.prod(extent))


def _building_columns(ijk: NDArray[np.int64], ceiling_z_m: float) -> NDArray[np.bool_]:
    """Per voxel ``ijk``, whether its column (the voxels above and below it) reaches up to the
    ceiling: a wall or a pillar the background did not map, not the table or the shelf that
    stands against it."""
    columns = ijk[:, 0] * (1 << _BITS) + ijk[:, 1]
    order = np.argsort(columns)
    ordered = columns[order]
    starts = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]])
    top_k = np.maximum.reduceat(ijk[order, 2], starts)
    column_of = np.searchsorted(ordered[starts], columns)
    return np.asarray((top_k[column_of] + 1) * VOXEL_M >= ceiling_z_m - CEILING_REACH_M, dtype=bool)


def _necked(keys: NDArray[np.int64], bodies: Sequence[NDArray[np.int64]]) -> bool:
    """Whether the ``bodies`` (voxel indices into ``keys``) touch one another, if at all, through
    at most ``NECK_VOXELS`` voxels each: a bridge of stray points between two things, not the
    cross-section of one thing whose middle the views saw less."""
    members = np.concatenate(bodies)
    body = np.concatenate([np.full(len(b), n) for n, b in enumerate(bodies)])
    a, b = _neighbour_pairs(_unpack(keys[members]))
    cross = body[a] != body[b]
    for x in range(len(bodies)):
        for y in range(x + 1, len(bodies)):
            pair = cross & (((body[a] == x) & (body[b] == y)) | ((body[a] == y) & (body[b] == x)))
            if len(np.unique(np.r_[a[pair], b[pair]])) > 2 * NECK_VOXELS:
                return False
    return True


def _side_by_side(boxes: Sequence[Box3D]) -> bool:
    """Whether no two ``boxes`` share more than ``COVERED_SHARE`` of the smaller one's footprint:
    bodies that stand beside one another, not the storeys of one."""
    for n, a in enumerate(boxes):
        alo, ahi = a.aabb()
        for b in boxes[n + 1:]:
            blo, bhi = b.aabb()
            inter = np.clip(np.minimum(ahi[:2], bhi[:2]) - np.maximum(alo[:2], blo[:2]), 0.0, None)
            smaller = min(float(np.prod(ahi[:2] - alo[:2])), float(np.prod(bhi[:2] - blo[:2])))
            if float(np.prod(inter)) > COVERED_SHARE * smaller:
                return False
    return True


def _attached(labels: NDArray[np.int64], weak: NDArray[np.bool_], a: NDArray[np.int64],
              b: NDArray[np.int64]) -> NDArray[np.int64]:
    """``labels`` with each ``weak`` voxel in the part of the nearest firm voxel it is joined to
    through the pairs (``a``, ``b``); weak voxels joined to no firm one keep parts of their own."""
    out = np.where(weak, -1, labels)
    for _ in range(ATTACH_STEPS):
        for x, y in ((a, b), (b, a)):
            take = (out[x] >= 0) & (out[y] < 0)
            out[y[take]] = out[x[take]]
    left = out < 0
    if np.any(left):
        rest = _labels(len(out), a, b, left[a] & left[b])
        _, rest = np.unique(rest[left], return_inverse=True)
        out[left] = int(out.max()) + 1 + rest.ravel()
    _, out = np.unique(out, return_inverse=True)
    return np.asarray(out.ravel(), dtype=np.int64)


def _labels(n: int, a: NDArray[np.int64], b: NDArray[np.int64], keep: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Labels 0..k-1 of the connected parts of ``n`` voxels joined by the pairs (``a``, ``b``) kept."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(int(keep.sum())), (a[keep], b[keep])), shape=(n, n))
    return np.asarray(connected_components(graph, directed=False)[1], dtype=np.int64)


def _neighbour_pairs(ijk: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The pairs (indices into ``ijk``, each pair once) of voxels that touch (26-connected) or
    lie one above the other across at most ``STACK_GAP_M``."""
    keys = _pack(ijk)
    order = np.argsort(keys)
    ordered = keys[order]
    gap = round(STACK_GAP_M / VOXEL_M)
    offsets = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in range(0, gap + 2)
               if (k, j, i) > (0, 0, 0) and (k <= 1 or (i == 0 and j == 0))]
    a_all, b_all = [], []
    for offset in offsets:
        other = _pack(ijk + np.array(offset, dtype=np.int64))
        pos = np.clip(np.searchsorted(ordered, other), 0, len(ordered) - 1)
        hit = ordered[pos] == other
        a_all.append(np.flatnonzero(hit))
        b_all.append(order[pos[hit]])
    return np.concatenate(a_all), np.concatenate(b_all)


def _thinnest_spread_m(points: FloatArray) -> float:
    """The spread (σ, m) of ``points`` across their thinnest direction."""
    centred = points - points.mean(axis=0)
    cov = centred.T @ centred / len(points)
    return float(np.sqrt(max(float(np.linalg.eigvalsh(cov)[0]), 0.0)))


def overlap_share(a: Box3D, b: Box3D) -> float:
    """The volume the boxes share, as a share of ``a``'s."""
    alo, ahi = a.aabb()
    blo, bhi = b.aabb()
    inter = np.clip(np.minimum(ahi, bhi) - np.maximum(alo, blo), 0.0, None)
    volume = float(np.prod(ahi - alo))
    return float(np.prod(inter)) / volume if volume > 0 else 0.0
