"""Geometry-only objects: what the depth shows as a solid thing but no detector names.

Three sources, each kept as one static ``unknown`` instance with its box (issue 53, point 4):
the solid things no track became (``solid_map.py``: standing on the floor or a support, outside
the background and every instance), the tables whose tops the background maps but no instance
holds (``supports.table_bodies``), and what stands proud of the walls (``wall_relief.py``).

A mapped table's object is the same real object as the background's table instance: the body
made here, or the unnamed instance of this session that holds the table (``supports.holds``:
covers its body, or continues its top). It carries that instance's uuid
(``data["same_object_as"]``, so the query layer counts the table once), and the name its views
give it (``table_views.py``: ``table`` when the detector named it in ``min_views`` views, else
``unknown``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground.class_vote import UNKNOWN
from hiper_cli.perceive.foreground.moving import at_rest
from hiper_cli.perceive.foreground.solid_map import SolidMap, SolidPart
from hiper_cli.perceive.foreground.supports import (
    floor_height_m,
    holds,
    mapped_tables,
    support_boxes,
    table_bodies,
)
from hiper_cli.perceive.foreground.table_views import TableViews
from hiper_cli.perceive.foreground.unmapped_tables import TABLE_CLASS
from hiper_cli.perceive.foreground.wall_relief import WallRelief

__all__ = ["SAME_OBJECT_KEY", "geometry_only", "grown_box", "solid_instance"]

FloatArray = NDArray[np.float64]
SAME_OBJECT_KEY = "same_object_as"  # data key: the uuid of the other layer's instance of this object

VOXEL_MARGIN_M = 0.1  # a background box grown by this on each side holds the voxels of its surface
STRUCTURE_CLASSES = ("wall", "door")  # background pieces that stand from the floor to the ceiling
STRUCTURE_HEIGHT_M = 100.0  # ... so their boxes hold every voxel above and below them
WALL_NOISE_M = 0.05  # ... and across their face a further depth noise of a wall seen from 3-4 m


def geometry_only(background: Sequence[Instance], taken: Sequence[Box3D], own: Sequence[Instance],
                  solid: SolidMap, relief: WallRelief, views: TableViews | None = None,
                  min_views: int = 1) -> list[Instance]:
    """The instances of the solid things, mapped tables and wall relief no instance holds, and
    those of ``own`` that became a mapped table's object: ``taken``, the boxes of every
    foreground instance; ``own``, this session's instances (their unnamed and table pieces may
    continue a mapped table's top: an unnamed one that does is that table's object);
    ``views``, the views that named tables (a table's object named in ``min_views`` of them is
    a ``table``)."""
    grown = [grown_box(i.box, tall=i.class_name in STRUCTURE_CLASSES) for i in background]
    ceilings = [float(i.box.aabb()[0][2]) for i in background if i.class_name == "ceiling"]
    floor_z_m = floor_height_m(background)
    parts = [solid_instance(p) for p in solid.parts(
        floor_z_m, support_boxes(background), taken, grown, min(ceilings) if ceilings else None)]
    # the tables whose tops the background maps: objects too, unless an instance holds them
    pieces = [i.box for i in (*own, *parts)
              if i.layer == "foreground" and i.class_name in (UNKNOWN, TABLE_CLASS)]
    bodies = table_bodies(background, floor_z_m, [*taken, *(i.box for i in parts)], pieces)
    for table, box, top in bodies:
        body = solid_instance(SolidPart(box, table.first_seen_s, table.last_seen_s, [], table.confidence,
                                        np.round(top, 3).tolist()))
        body.data[SAME_OBJECT_KEY] = table.uuid
        parts.append(body)
    # an unnamed instance that holds a mapped table (its other part, or all of it) is that table
    with_body = {table.uuid for table, _, _ in bodies}
    held = _holders([i for i in background if i.uuid not in with_body], floor_z_m,
                    [i for i in (*own, *parts) if SAME_OBJECT_KEY not in i.data])
    for table, inst in held:
        inst.data[SAME_OBJECT_KEY] = table.uuid
    _name_tables([*parts[len(parts) - len(bodies):], *(inst for _, inst in held)], views, min_views)
    # and the objects hung on the walls
    hung = relief.parts(floor_z_m, [*taken, *(i.box for i in parts)])
    held_own = [inst for _, inst in held if all(inst is not p for p in parts)]
    return parts + [solid_instance(p) for p in hung] + held_own


def _holders(background: Sequence[Instance], floor_z_m: float,
             candidates: Sequence[Instance]) -> list[tuple[Instance, Instance]]:
    """(table, instance) per mapped table that a static ``unknown`` instance of ``candidates``
    holds (``supports.holds``; the one that holds the most), each instance for one table."""
    unnamed = [i for i in candidates if i.layer == "foreground" and i.class_name == UNKNOWN
               and i.state == "static"]
    out: list[tuple[Instance, Instance]] = []
    used: set[str] = set()
    for table, body in mapped_tables(background, floor_z_m):
        scored = [(holds(i.box, body), i) for i in unnamed if i.uuid not in used]
        best = max(scored, key=lambda pair: pair[0], default=(0.0, None))
        if best[1] is not None and best[0] > 0.0:
            out.append((table, best[1]))
            used.add(best[1].uuid)
    return out


def _name_tables(instances: Sequence[Instance], views: TableViews | None, min_views: int) -> None:
    """Name ``table`` each of ``instances`` (a mapped table's object) that ``min_views`` views
    named so (``table_views.py``); the count is kept in ``data["named_views"]``."""
    def surface(inst: Instance) -> FloatArray:
        points = inst.data.get("surface_map")
        return np.asarray(points, dtype=np.float64).reshape(-1, 3) if points else inst.box.corners()

    named = views.named_views([(i.box, surface(i)) for i in instances]) if views else [0] * len(instances)
    for inst, n_named in zip(instances, named, strict=True):
        inst.data["named_views"] = n_named
        if n_named >= min_views:
            inst.class_name = TABLE_CLASS


def grown_box(box: Box3D, tall: bool) -> Box3D:
    """``box`` grown by ``VOXEL_MARGIN_M`` on each side; ``tall``, up and down without end along
    its most vertical axis (a wall stands from the floor to the ceiling, whatever part of it the
    background saw), and across its face by ``WALL_NOISE_M`` more: a wall seen from afar puts
    points of its face that far in front of it, which fill the voxels along it (a sheet that
    joined a table to the wall behind it up to the ceiling)."""
    extent = box.extent_m + 2.0 * VOXEL_MARGIN_M
    if tall:
        extent[int(np.argmax(np.abs(box.R[2, :])))] = STRUCTURE_HEIGHT_M
        extent[int(np.argmin(box.extent_m))] += 2.0 * WALL_NOISE_M
    return Box3D(box.center_m, extent, box.R)


def solid_instance(part: SolidPart) -> Instance:
    """The ``unknown`` instance of a geometry-only object: static, at rest at its box's centre."""
    rows = [[stamp_s, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0] for stamp_s in (part.first_seen_s, part.last_seen_s)]
    return Instance(layer="foreground", class_name=UNKNOWN, box=part.box, first_seen_s=part.first_seen_s,
                    last_seen_s=part.last_seen_s, confidence=part.seen_share,
                    observation_uuids=part.observation_uuids,
                    data={"trajectory": at_rest(rows, part.box), "closed": True, "geometry_only": True,
                          "surface_map": part.surface_m})  # a later session's empty-place test
