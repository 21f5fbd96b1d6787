"""Column reads for the interpretation: instances of a class and their trajectory rows as numpy
arrays, straight from SQLite, without building a document or an ``Instance`` per row.

SQLite's JSON functions pick the few fields needed out of each instance body; trajectory rows
come from ``track_cache`` (raw float64 bytes, parsed from the JSON once per document change).
The window selects instances seen in [t0, t1] (an instance's ``stamp_s`` column is its last
sighting) and rows whose stamp lies in it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import orjson
from numpy.typing import NDArray

from hiper_cli.graph.documents import DocumentStore
from hiper_cli.graph.track_cache import ROW_WIDTH, track_rows
from hiper_cli.model import Instance

__all__ = [
    "InstanceColumns",
    "TrajectoryColumns",
    "columns_of_instances",
    "foreground_classes",
    "instance_columns",
    "newest_stamp_s",
    "trajectory_columns",
    "window_bounds",
]


@dataclass(frozen=True)
class InstanceColumns:
    """Instances, one entry per instance: class and box (map frame), first and last sighting."""

    uuids: list[str]
    class_names: list[str]
    center_map_m: NDArray[np.float64]  # (N, 3)
    extent_m: NDArray[np.float64]  # (N, 3), along the box's own axes
    half_aabb_m: NDArray[np.float64]  # (N, 3), half size of the axis-aligned map-frame box
    first_seen_s: NDArray[np.float64]  # (N,)
    last_seen_s: NDArray[np.float64]  # (N,)
    static: NDArray[np.bool_]  # (N,) the tracker's state: it never moved


@dataclass(frozen=True)
class TrajectoryColumns:
    """Trajectory rows of instances: ``rows`` (M, 7) [stamp_s, x, y, z, vx, vy, vz] in the map
    frame, ``track`` (M,) the index of each row's instance in ``instances``."""

    instances: InstanceColumns
    rows: NDArray[np.float64]
    track: NDArray[np.int64]


_INSTANCES = (
    "SELECT uuid, class, json_extract(body, '$.box.center_m'), json_extract(body, '$.box.extent_m'), "
    "json_extract(body, '$.first_seen_s'), stamp_s, seq, json_extract(body, '$.box.R'), "
    "json_extract(body, '$.state') FROM docs "
    "WHERE type = 'instance' AND layer = ?{where} ORDER BY id"
)


def _select(
    docs: DocumentStore,
    class_name: str | None,
    t0: float | None,
    t1: float | None,
    layer: str = "foreground",
) -> list[tuple[object, ...]]:
    where, params = "", list[object]([layer])
    if class_name is not None:
        where += " AND class = ?"
        params.append(class_name)
    if t0 is not None:
        where += " AND stamp_s >= ?"
        params.append(t0)
    if t1 is not None:
        where += " AND json_extract(body, '$.first_seen_s') <= ?"
        params.append(t1)
    sql = _INSTANCES.format(where=where)
    return list(docs.connection.execute(sql, params))


def instance_columns(
    docs: DocumentStore,
    class_name: str | None = None,
    t0: float | None = None,
    t1: float | None = None,
    *,
    layer: str = "foreground",
) -> InstanceColumns:
    """The boxes of the instances of ``layer`` seen in the window, of ``class_name`` or of every
    class."""
    return _instances(_select(docs, class_name, t0, t1, layer=layer))


def _instances(rows: list[tuple[object, ...]]) -> InstanceColumns:
    n = len(rows)
    centers = np.array([orjson.loads(str(r[2])) for r in rows], dtype=np.float64).reshape(n, 3)
    extents = np.array([orjson.loads(str(r[3])) for r in rows], dtype=np.float64).reshape(n, 3)
    rot = np.array(
        [orjson.loads(str(r[7])) if r[7] is not None else np.eye(3) for r in rows], dtype=np.float64
    )
    half = np.einsum("nij,nj->ni", np.abs(rot.reshape(n, 3, 3)), extents / 2.0)
    return InstanceColumns(
        uuids=[str(r[0]) for r in rows],
        class_names=[str(r[1]) for r in rows],
        center_map_m=centers,
        extent_m=extents,
        half_aabb_m=half,
        first_seen_s=np.array([float(r[4]) for r in rows], dtype=np.float64),  # type: ignore[arg-type]
        last_seen_s=np.array([float(r[5]) for r in rows], dtype=np.float64),  # type: ignore[arg-type]
        static=np.array([r[8] == "static" for r in rows], dtype=bool),
    )


def trajectory_columns(
    docs: DocumentStore, class_name: str | None = None, t0: float | None = None, t1: float | None = None
) -> TrajectoryColumns:
    """The trajectory rows in the window of the foreground instances of ``class_name`` (or of
    every class) seen in it, ordered by instance, then stamp (rows from ``track_cache``)."""
    selected = _select(docs, class_name, t0, t1)
    instances = _instances(selected)
    parts = track_rows(docs, [(str(r[0]), int(r[6])) for r in selected])  # type: ignore[call-overload]
    if parts:
        rows = np.concatenate(parts)
        track = np.repeat(np.arange(len(parts), dtype=np.int64), [len(p) for p in parts])
    else:
        rows, track = np.zeros((0, ROW_WIDTH)), np.zeros(0, dtype=np.int64)
    if t0 is not None or t1 is not None:
        keep = window_bounds(rows[:, 0], t0, t1)
        rows, track = rows[keep], track[keep]
    same = track[1:] == track[:-1]
    if np.any(same & (np.diff(rows[:, 0]) < 0)):  # rows are stored in time order; sort if not
        order = np.lexsort((rows[:, 0], track))
        rows, track = rows[order], track[order]
    return TrajectoryColumns(instances, rows, track)


def window_bounds(stamps_s: NDArray[np.float64], t0: float | None, t1: float | None) -> NDArray[np.bool_]:
    """Which stamps lie in [t0, t1] (a None bound is open)."""
    keep = np.ones(len(stamps_s), dtype=bool)
    if t0 is not None:
        keep &= stamps_s >= t0
    if t1 is not None:
        keep &= stamps_s <= t1
    return keep


def newest_stamp_s(docs: DocumentStore) -> float | None:
    """The last sighting of the newest foreground instance (None: there is none)."""
    row = docs.connection.execute(
        "SELECT MAX(stamp_s) FROM docs WHERE type = 'instance' AND layer = 'foreground'"
    ).fetchone()
    return None if row is None or row[0] is None else float(row[0])


def foreground_classes(docs: DocumentStore) -> list[str]:
    """The classes of the foreground instances, sorted."""
    rows = docs.connection.execute(
        "SELECT DISTINCT class FROM docs WHERE type = 'instance' AND layer = 'foreground' ORDER BY 1"
    )
    return [str(c) for (c,) in rows if c is not None]


def columns_of_instances(instances: Sequence[Instance]) -> TrajectoryColumns:
    """The same columns from instances in memory (an evaluation's world, a test)."""
    fg = [i for i in instances if i.layer == "foreground"]
    parts = [
        np.asarray(i.data.get("trajectory") or np.zeros((0, ROW_WIDTH)), dtype=np.float64).reshape(
            -1, ROW_WIDTH
        )
        for i in fg
    ]
    cols = InstanceColumns(
        uuids=[i.uuid for i in fg],
        class_names=[i.class_name for i in fg],
        center_map_m=np.array([i.box.center_m for i in fg], dtype=np.float64).reshape(-1, 3),
        extent_m=np.array([i.box.extent_m for i in fg], dtype=np.float64).reshape(-1, 3),
        half_aabb_m=np.array(
            [(i.box.aabb()[1] - i.box.aabb()[0]) / 2.0 for i in fg], dtype=np.float64
        ).reshape(-1, 3),
        first_seen_s=np.array([i.first_seen_s for i in fg], dtype=np.float64),
        last_seen_s=np.array([i.last_seen_s for i in fg], dtype=np.float64),
        static=np.array([i.state == "static" for i in fg], dtype=bool),
    )
    rows = np.concatenate(parts) if parts else np.zeros((0, ROW_WIDTH))
    track = (
        np.concatenate([np.full(len(p), k, dtype=np.int64) for k, p in enumerate(parts)])
        if parts
        else np.zeros(0, dtype=np.int64)
    )
    return TrajectoryColumns(cols, rows, track)
