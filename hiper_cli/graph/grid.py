"""The spatial index of observations: the 2 m map cell (x, y, z) of each box centre, as one
integer key in a B-tree (``obs_cells``; rows not yet merged wait in ``obs_cells_new``).

A lookup scans one key range per (x, y) column of cells that its box covers; a box covering
more than ``MAX_COLUMNS`` columns scans the table instead."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from hiper_cli.graph.sqlite_guard import GuardedConnection

__all__ = ["GRID_CELL_M", "cell_index", "cell_key", "grid_rows"]

GRID_CELL_M = 2.0  # for new stores; a store keeps the cell size it was created with (meta, else 1 m)
MAX_COLUMNS = 4096
_GRID_OFFSET = 1 << 19
_GRID_SPAN = 1 << 20


def cell_index(v: float, cell_m: float) -> int:
    return math.floor(v / cell_m)


def cell_key(ix: int, iy: int, iz: int) -> int:
    return ((ix + _GRID_OFFSET) * _GRID_SPAN + (iy + _GRID_OFFSET)) * _GRID_SPAN + (iz + _GRID_OFFSET)


def grid_rows(
    db: GuardedConnection, select: str, where: str, params: Sequence[Any], lo: Sequence[float],
    hi: Sequence[float], cell_m: float, margin_m: float = 0.0, limit: int | None = None,
) -> list[Any]:
    """Rows of ``select`` (a query over ``{table} g``, ending in WHERE) meeting ``where`` among
    the observations whose cell lies in [lo - margin_m, hi + margin_m]; the staged rows first.
    With ``limit``, stops after the column that reaches it (the caller cuts)."""
    ix0, ix1 = cell_index(lo[0] - margin_m, cell_m), cell_index(hi[0] + margin_m, cell_m)
    iy0, iy1 = cell_index(lo[1] - margin_m, cell_m), cell_index(hi[1] + margin_m, cell_m)
    iz0, iz1 = cell_index(lo[2] - margin_m, cell_m), cell_index(hi[2] + margin_m, cell_m)
    out = list(db.execute(select.format(table="obs_cells_new") + where, params))
    if (ix1 - ix0 + 1) * (iy1 - iy0 + 1) > MAX_COLUMNS:
        out += db.execute(select.format(table="obs_cells") + where, params)
        return out
    sql = select.format(table="obs_cells") + "g.cell BETWEEN ? AND ? AND " + where
    for ix in range(ix0, ix1 + 1):
        for iy in range(iy0, iy1 + 1):
            out += db.execute(sql, [cell_key(ix, iy, iz0), cell_key(ix, iy, iz1), *params])
        if limit is not None and len(out) >= limit:
            break
    return out
