"""Table legs out of the foreground blobs.

The background layer knows a table by its top plane; the legs under it survive the background
filter, and the Euclidean clustering joins a leg to the chair beside it (their gap is below the
cluster tolerance). On the simulated houses these merged blobs were the largest source of
localisation error: a leg drags the chair's centre by 0.1-0.5 m.

A table leg is a thin vertical column that rises from low down up to the underside of the
top, and stops there. ``drop_table_legs`` bins the points of each blob horizontally
(``table_leg_cell_m``); a cell near a background table (its footprint grown by
``table_leg_reach_m``: the background stage's table extents are estimates) whose points reach
from at least ``table_leg_min_height_m`` below the top to within ``table_leg_top_band_m`` of
it, and no higher, is a leg, and its points leave the blob. A chair's back legs go on up to its
backrest (higher than the table), its front legs stop at the seat (far below the top), a person
is taller still: they keep their points.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.segment import Blob, cell_inverse, sub_blob

__all__ = ["drop_table_legs", "leg_points"]

FloatArray = NDArray[np.float64]


def leg_points(
    points_map: FloatArray, tables: Sequence[Box3D], config: ForegroundConfig
) -> NDArray[np.bool_]:
    """Which of ``points_map`` (N, 3) belong to table legs (see the module docstring)."""
    legs = np.zeros(len(points_map), dtype=bool)
    if len(points_map) == 0 or not tables:
        return legs
    cell = config.table_leg_cell_m
    inverse = cell_inverse(points_map[:, :2], cell)
    n_cells = int(inverse.max()) + 1
    z = points_map[:, 2]
    z_lo = np.full(n_cells, np.inf)
    z_hi = np.full(n_cells, -np.inf)
    np.minimum.at(z_lo, inverse, z)
    np.maximum.at(z_hi, inverse, z)
    for table in tables:
        lo, hi = table.aabb()
        top_z = float(hi[2])
        reach = config.table_leg_reach_m
        near = (
            (points_map[:, 0] >= lo[0] - reach) & (points_map[:, 0] <= hi[0] + reach)
            & (points_map[:, 1] >= lo[1] - reach) & (points_map[:, 1] <= hi[1] + reach)
        )
        if not near.any():
            continue
        column = (
            (z_hi >= top_z - config.table_leg_top_band_m)
            & (z_hi <= top_z + config.table_leg_above_m)
            & (z_lo <= top_z - config.table_leg_min_height_m)
        )
        legs |= near & column[inverse]
    return legs


def drop_table_legs(
    blobs: list[Blob], tables: Sequence[Box3D], config: ForegroundConfig, step: int, width: int, height: int
) -> list[Blob]:
    """``blobs`` without their table-leg points; a blob that was only legs is gone."""
    if not tables or config.table_leg_cell_m <= 0:
        return blobs
    out: list[Blob] = []
    for blob in blobs:
        legs = leg_points(blob.points_map, tables, config)
        if not legs.any():
            out.append(blob)
            continue
        keep = np.flatnonzero(~legs)
        if len(keep) < 3 or (len(keep) < config.min_cluster_points and not blob.fragment):
            continue
        out.append(sub_blob(blob, keep, step, width, height))
    return out
