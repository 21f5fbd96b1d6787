"""The background's supports as the foreground stage reads them: the floors and table tops
objects stand on (their tops at the fitted plane), and the floor's height, map frame; and the
tables those tops belong to, as objects (``table_bodies``)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground.solid_map import COVERED_SHARE, overlap_share

SUPPORT_CLASSES = ("floor", "table")
HORIZONTAL_PLANE_MIN_NZ = 0.9  # a support plane this close to horizontal (|n_z|) gives the top
SUPPORT_TOP_BELOW_BOX_M = 0.05  # ... when the plane's height lies this far below its box at most
TOUCH_M = 0.1  # an unnamed piece reaching a table's top this near its footprint ... (``table_bodies``)
ALONG_SHARE = 0.5  # ... and along this share of its side at least holds it: it is the table's other part
UNDER_TOP_SHARE = 0.5  # a piece that is the table itself has this share of its footprint under the top
TOP_GRID = 5  # a table's stored surface: TOP_GRID × TOP_GRID points on its top ...
TOP_INSET = 0.1  # ... this share of its sides inside its edges (the background's extent is an estimate)

FloatArray = NDArray[np.float64]


def support_boxes(background: Iterable[Instance]) -> list[Box3D]:
    """The floors and table tops objects stand on, map frame: axis-aligned, their top at the
    fitted plane's height (``data["plane_map"]``) where there is one. The box of a plane
    instance is thicker than the plane by the depth noise of its points; an object's base
    rests on the plane itself."""
    out: list[Box3D] = []
    for inst in background:
        if inst.class_name not in SUPPORT_CLASSES:
            continue
        lo, hi = inst.box.aabb()
        plane = inst.data.get("plane_map")
        if plane is not None and len(plane) == 4 and abs(float(plane[2])) > HORIZONTAL_PLANE_MIN_NZ:
            a, b, c, d = (float(v) for v in plane)
            cx, cy = (lo[:2] + hi[:2]) / 2.0
            top = -(a * cx + b * cy + d) / c
            if lo[2] - SUPPORT_TOP_BELOW_BOX_M <= top <= hi[2]:
                hi = hi.copy()
                hi[2] = top
                lo = lo.copy()
                lo[2] = min(lo[2], top)
        out.append(Box3D((lo + hi) / 2.0, hi - lo))
    return out


def floor_height_m(background: Iterable[Instance]) -> float:
    """The height of the floor, map frame: the lowest top of the floor instances (their box's
    top; 0, the map's origin, before the background found one)."""
    tops = [float(inst.box.aabb()[1][2]) for inst in background if inst.class_name == "floor"]
    return min(tops) if tops else 0.0


def table_bodies(background: Iterable[Instance], floor_z_m: float, taken: Sequence[Box3D],
                 pieces: Sequence[Box3D]) -> list[tuple[Instance, Box3D, FloatArray]]:
    """The objects the mapped table tops belong to: per table of ``background`` no instance
    holds yet, (the table, the box from the floor up to its top over the top's footprint, a grid
    of points on its top, the surface the views saw, and its four feet at the floor, where it
    stands: a later session's empty-place test aims at the top, not at the air under it, and
    leaves the feet out). The top is the background's support;
    the thing standing there, top and legs, is still an object, which the foreground filter
    (its points are the background's) and the map of solid things (its voxels lie in the
    background's box) never see. An instance holds it when its box (``taken``) covers
    ``COVERED_SHARE`` of the table's, or when a piece of an unnamed or table instance (``pieces``)
    continues the top (``_touches``): the table's other part."""
    held, near = list(taken), list(pieces)
    out: list[tuple[Instance, Box3D, FloatArray]] = []
    for inst, box in mapped_tables(background, floor_z_m):
        lo, hi = box.aabb()
        if any(overlap_share(box, other) >= COVERED_SHARE for other in held) or any(
                _touches(piece, lo, hi) for piece in near):
            continue
        top_z = float(hi[2])
        inner = (hi[:2] - lo[:2]) * TOP_INSET
        u, v = np.meshgrid(np.linspace(lo[0] + inner[0], hi[0] - inner[0], TOP_GRID),
                           np.linspace(lo[1] + inner[1], hi[1] - inner[1], TOP_GRID))
        top_points = np.column_stack([u.ravel(), v.ravel(), np.full(u.size, top_z)])
        feet = np.array([[x, y, floor_z_m] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
        out.append((inst, box, np.concatenate([top_points, feet])))
        held.append(box)
        near.append(box)
    return out


def mapped_tables(background: Iterable[Instance], floor_z_m: float) -> list[tuple[Instance, Box3D]]:
    """The background's tables, largest top first, each with its body's box: from the floor up
    to its top, over the top's footprint (none for a top at or below the floor)."""
    tables = [inst for inst in background if inst.class_name == "table"]
    tables.sort(key=lambda inst: -float(np.prod(inst.box.extent_m[:2])))
    out: list[tuple[Instance, Box3D]] = []
    for inst in tables:
        lo, hi = support_boxes([inst])[0].aabb()
        if float(hi[2]) <= floor_z_m:
            continue
        lo = np.array([lo[0], lo[1], floor_z_m])
        out.append((inst, Box3D((lo + hi) / 2.0, hi - lo)))
    return out


def holds(piece: Box3D, body: Box3D) -> float:
    """How much ``piece`` is the table whose body is ``body``: the share of the body's volume it
    covers when that reaches ``COVERED_SHARE``, or when it continues the top (``_touches``),
    and it lies mostly under the top (``UNDER_TOP_SHARE`` of its footprint within ``TOUCH_M``
    of the top's: chairs in a row beside the table reach its side but stand beside it); else 0."""
    lo, hi = body.aabb()
    p_lo, p_hi = piece.aabb()
    inside = np.clip(np.minimum(p_hi[:2], hi[:2] + TOUCH_M) - np.maximum(p_lo[:2], lo[:2] - TOUCH_M),
                     0.0, None)
    footprint = float(np.prod(p_hi[:2] - p_lo[:2]))
    if footprint <= 0.0 or float(np.prod(inside)) < UNDER_TOP_SHARE * footprint:
        return 0.0
    share = overlap_share(body, piece)
    return share if share >= COVERED_SHARE or _touches(piece, lo, hi) else 0.0


def _touches(piece: Box3D, lo: FloatArray, hi: FloatArray) -> bool:
    """Whether ``piece`` is a part of the table whose top spans ``lo``-``hi``: it reaches the
    top's height, within ``TOUCH_M`` of the footprint, and runs along a side of it for at least
    ``ALONG_SHARE`` of that side (a chair at the table is narrower than the side it stands at)."""
    p_lo, p_hi = piece.aabb()
    if not p_lo[2] - TOUCH_M <= hi[2] <= p_hi[2] + TOUCH_M:
        return False
    overlap = np.minimum(p_hi[:2], hi[:2]) - np.maximum(p_lo[:2], lo[:2])
    return bool(np.all(overlap >= -TOUCH_M) and np.any(overlap >= ALONG_SHARE * (hi[:2] - lo[:2])))
