"""Geometry-only objects: what the depth shows as a solid thing but no detector names.

Three sources, each kept as one static ``unknown`` instance with its box (issue 53, point 4):
the solid things no track became (``solid_map.py``: standing on the floor or a support, outside
the background and every instance), the tables whose tops the background maps but no instance
holds (``supports.table_bodies``), and what stands proud of the walls (``wall_relief.py``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground.class_vote import UNKNOWN
from hiper_cli.perceive.foreground.moving import at_rest
from hiper_cli.perceive.foreground.solid_map import SolidMap, SolidPart
from hiper_cli.perceive.foreground.supports import floor_height_m, support_boxes, table_bodies
from hiper_cli.perceive.foreground.unmapped_tables import TABLE_CLASS
from hiper_cli.perceive.foreground.wall_relief import WallRelief

__all__ = ["geometry_only", "grown_box", "solid_instance"]

VOXEL_MARGIN_M = 0.1  # a background box grown by this on each side holds the voxels of its surface
STRUCTURE_CLASSES = ("wall", "door")  # background pieces that stand from the floor to the ceiling
STRUCTURE_HEIGHT_M = 100.0  # ... so their boxes hold every voxel above and below them
WALL_NOISE_M = 0.05  # ... and across their face a further depth noise of a wall seen from 3-4 m


def geometry_only(background: Sequence[Instance], taken: Sequence[Box3D], own: Sequence[Instance],
                  solid: SolidMap, relief: WallRelief) -> list[Instance]:
    """The ``unknown`` instances of the solid things, mapped tables and wall relief no instance
    holds: ``taken``, the boxes of every foreground instance; ``own``, this session's instances
    (their unnamed and table pieces may continue a mapped table's top)."""
    grown = [grown_box(i.box, tall=i.class_name in STRUCTURE_CLASSES) for i in background]
    ceilings = [float(i.box.aabb()[0][2]) for i in background if i.class_name == "ceiling"]
    floor_z_m = floor_height_m(background)
    parts = [solid_instance(p) for p in solid.parts(
        floor_z_m, support_boxes(background), taken, grown, min(ceilings) if ceilings else None)]
    # the tables whose tops the background maps: objects too, unless an instance holds them
    pieces = [i.box for i in (*own, *parts)
              if i.layer == "foreground" and i.class_name in (UNKNOWN, TABLE_CLASS)]
    bodies = table_bodies(background, floor_z_m, [*taken, *(i.box for i in parts)], pieces)
    parts += [solid_instance(SolidPart(box, t.first_seen_s, t.last_seen_s, [], t.confidence,
                                       np.round(top, 3).tolist())) for t, box, top in bodies]
    # and the objects hung on the walls
    hung = relief.parts(floor_z_m, [*taken, *(i.box for i in parts)])
    return parts + [solid_instance(p) for p in hung]


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
