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

The top's rim: the background layer knows the top as a plane, and the few centimetres of edge
under it survive the filter; far from the camera, where the cluster tolerance is some 0.3 m,
the rim joined a chair beside the table to the cups standing on it. After the tables the
background layer has not mapped yet are out (``tables.py``), ``drop_table_legs(rims=True)``
also takes cells that lie wholly within ``table_rim_depth_m`` below the top (and
``table_rim_above_m`` above it), near the mapped top (``table_rim_reach_m``), with the legs
under them, and clusters what remains again: each part stands on the blob's support or on the
table (``standing_on``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D, point_bounds
from hiper_cli.perceive.foreground.background_filter import BACKGROUND_MARGIN_PER_M2
from hiper_cli.perceive.foreground.config import RefineConfig, SegmentConfig
from hiper_cli.perceive.foreground.segment import SUPPORT_GAP_M, Blob, cell_inverse, grid_components, sub_blob

__all__ = ["drop_table_legs", "leg_points"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
TABLE_LEG_CELL_M: float = 0.05
"""Table legs leave the blobs (``legs.py``): points are binned horizontally in cells this
wide (0: off) ..."""
TABLE_LEG_REACH_M: float = 0.1
"""... near a background table (its footprint grown by this) ..."""
TABLE_LEG_MIN_HEIGHT_M: float = 0.4
"""... a cell whose points reach from this far below the table top ..."""
TABLE_LEG_TOP_BAND_M: float = 0.2
"""... up to within this of the top ..."""
TABLE_LEG_ABOVE_M: float = 0.03
"""... and no more than this above it is a leg."""
TABLE_RIM_DEPTH_M: float = 0.08
"""After the unmapped tables (``drop_unseen_tables``): a cell near a table whose points all
lie between this far below its top and ``table_rim_above_m`` above it is the top's edge
(the background layer knows the top as a plane; the few centimetres of edge under it
survive the filter, and at 4-5 m, with the cluster tolerance grown to 0.3 m, they joined a
chair to the cups on the table) and leaves the blob with the legs; the rest is clustered
again (0: off)."""
TABLE_RIM_ABOVE_M: float = 0.01
TABLE_RIM_REACH_M: float = 0.1
"""Rim cells count this far outside the mapped top, and the legs under them too."""

FloatArray = NDArray[np.float64]


def leg_points(
    points_map: FloatArray, tables: Sequence[Box3D], config: SegmentConfig, rims: bool = False
) -> NDArray[np.bool_]:
    """Which of ``points_map`` (N, 3) belong to table legs (see the module docstring)."""
    legs = np.zeros(len(points_map), dtype=bool)
    if len(points_map) == 0 or not tables:
        return legs
    cell = TABLE_LEG_CELL_M
    inverse = cell_inverse(points_map[:, :2], cell)
    n_cells = int(inverse.max()) + 1
    z = points_map[:, 2]
    z_lo = np.full(n_cells, np.inf)
    z_hi = np.full(n_cells, -np.inf)
    np.minimum.at(z_lo, inverse, z)
    np.maximum.at(z_hi, inverse, z)
    for table in tables:
        lo, hi = table.aabb()  # new arrays: the rim may grow them
        top_z = float(hi[2])
        if rims:
            # The top's rim, and the part of the top the background layer has not mapped yet:
            # cells that lie wholly in the top's band; the legs under them count too.
            rim_cells = (z_lo >= top_z - TABLE_RIM_DEPTH_M) & (
                z_hi <= top_z + TABLE_RIM_ABOVE_M
            )
            grow = TABLE_RIM_REACH_M
            xy = points_map[:, :2]
            inside = np.all(xy >= lo[:2] - grow, axis=1) & np.all(xy <= hi[:2] + grow, axis=1)
            rim = rim_cells[inverse] & inside
            if rim.any():
                rim_lo, rim_hi = point_bounds(points_map[rim, :2])
                lo[:2] = np.minimum(lo[:2], rim_lo)
                hi[:2] = np.maximum(hi[:2], rim_hi)
        reach = TABLE_LEG_REACH_M
        near = (
            (points_map[:, 0] >= lo[0] - reach) & (points_map[:, 0] <= hi[0] + reach)
            & (points_map[:, 1] >= lo[1] - reach) & (points_map[:, 1] <= hi[1] + reach)
        )
        if not near.any():
            continue
        column = (
            (z_hi >= top_z - TABLE_LEG_TOP_BAND_M)
            & (z_hi <= top_z + TABLE_LEG_ABOVE_M)
            & (z_lo <= top_z - TABLE_LEG_MIN_HEIGHT_M)
        )
        if rims:
            column |= rim_cells
        legs |= near & column[inverse]
    return legs


def standing_on(blob: Blob, supports_z_m: Sequence[float | None], config: SegmentConfig) -> float | None:
    """The first of ``supports_z_m`` (support top heights, in order of preference; None: no
    support) that the blob's base is within the filter margin plus ``support_gap_m`` above."""
    base = float(blob.bounds_map[0][2])
    depth = float(np.median(blob.points_cam[:, 2]))
    reach = config.background_margin_m + BACKGROUND_MARGIN_PER_M2 * depth * depth
    for support in supports_z_m:
        if support is not None and 0.0 <= base - support <= reach + SUPPORT_GAP_M:
            return support
    return None


def drop_table_legs(
    blobs: list[Blob], tables: Sequence[Box3D], config: RefineConfig, step: int, width: int, height: int,
    rims: bool = False,
) -> list[Blob]:
    """``blobs`` without their table-leg points; a blob that was only legs is gone."""
    if not tables or TABLE_LEG_CELL_M <= 0:
        return blobs
    # A table farther from a blob's bounds than the reach of its legs (and rim) cannot take a
    # point of it: only the tables near it are tested (same result, a fraction of the work).
    reach = TABLE_LEG_REACH_M + (TABLE_RIM_REACH_M if rims else 0.0)
    footprints = [table.aabb() for table in tables]
    tops = [float(hi[2]) for _, hi in footprints]
    out: list[Blob] = []
    for blob in blobs:
        lo, hi = blob.bounds_map
        near = [
            table for table, (t_lo, t_hi) in zip(tables, footprints, strict=True)
            if np.all(lo[:2] <= t_hi[:2] + reach) and np.all(hi[:2] >= t_lo[:2] - reach)
        ]
        if not near:
            out.append(blob)
            continue
        legs = leg_points(blob.points_map, near, config, rims)
        if not legs.any():
            out.append(blob)
            continue
        keep = np.flatnonzero(~legs)
        if len(keep) < 3 or (len(keep) < config.min_cluster_points and not blob.fragment):
            continue
        if rims and not blob.fragment:
            for part in grid_components(blob, keep, step, config):
                fragment = len(part) < config.min_cluster_points
                if len(part) < 3 or (fragment and not config.detection_join):
                    continue
                piece = sub_blob(blob, keep[part], step, width, height)
                piece.fragment = fragment
                piece.support_z_m = standing_on(piece, [*tops, blob.support_z_m], config)
                out.append(piece)
            continue
        out.append(sub_blob(blob, keep, step, width, height))
    return out
