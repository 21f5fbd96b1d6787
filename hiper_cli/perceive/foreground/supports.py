"""The background's supports as the foreground stage reads them: the floors and table tops
objects stand on (their tops at the fitted plane), and the floor's height, map frame."""

from __future__ import annotations

from collections.abc import Iterable

from hiper_cli.model import Box3D, Instance

SUPPORT_CLASSES = ("floor", "table")
HORIZONTAL_PLANE_MIN_NZ = 0.9  # a support plane this close to horizontal (|n_z|) gives the top
SUPPORT_TOP_BELOW_BOX_M = 0.05  # ... when the plane's height lies this far below its box at most


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
