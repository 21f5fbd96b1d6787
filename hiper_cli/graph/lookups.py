"""Lean reads of the document store for the query layer: index rows and columns only, no
document bodies decoded (an instance body carries its trajectory, an observation its point
blob). A mixin of ``DocumentStore``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from hiper_cli.graph.grid import grid_rows
from hiper_cli.graph.poserows import pose_at
from hiper_cli.graph.sqlite_guard import GuardedConnection

__all__ = ["Lookups"]


class Lookups:
    """Reads over ``obs_cells``, ``all_links``, ``docs`` columns and ``poses``."""

    _db: GuardedConnection
    _grid_cell_m: float

    def observation_points_in(
        self, lo: Sequence[float], hi: Sequence[float], class_name: str | None = None
    ) -> list[tuple[str, str | None, float, float, float, float]]:
        """(uuid, instance uuid, stamp_s, x, y, z) of the observations whose map box centre lies
        in [lo, hi] (of class ``class_name`` when given)."""
        where = (
            "(g.min_x + g.max_x) / 2 BETWEEN ? AND ? AND (g.min_y + g.max_y) / 2 BETWEEN ? AND ? "
            "AND (g.min_z + g.max_z) / 2 BETWEEN ? AND ?"
        )
        params: list[Any] = [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]]
        if class_name is not None:
            where += " AND d.class = ?"
            params.append(class_name)
        select = (
            "SELECT d.uuid, d.instance_uuid, d.stamp_s, (g.min_x + g.max_x) / 2, "
            "(g.min_y + g.max_y) / 2, (g.min_z + g.max_z) / 2 FROM {table} g "
            "CROSS JOIN docs d ON d.id = g.id WHERE "
        )
        out = grid_rows(self._db, select, where, params, lo, hi, self._grid_cell_m)
        return [(str(u), i, float(t), float(x), float(y), float(z)) for u, i, t, x, y, z in out]

    def observation_links(self, instance_uuids: Sequence[str]) -> dict[str, list[str]]:
        """instance uuid -> the uuids of its observations, oldest link first."""
        out: dict[str, list[str]] = {u: [] for u in instance_uuids}
        for k in range(0, len(instance_uuids), 500):
            chunk = list(instance_uuids[k : k + 500])
            marks = ",".join("?" * len(chunk))
            rows = self._db.execute(
                f"SELECT instance_uuid, observation_uuid FROM all_links WHERE instance_uuid IN ({marks}) "
                "GROUP BY instance_uuid, observation_uuid ORDER BY MIN(seq), observation_uuid",
                chunk,
            )
            for inst, obs in rows:
                out[str(inst)].append(str(obs))
        return out

    def observation_stamps(self, instance_uuid: str) -> list[float]:
        """The stamps of an instance's observations, in time order."""
        rows = self._db.execute(
            "SELECT d.stamp_s FROM docs d WHERE d.uuid IN "
            "(SELECT observation_uuid FROM all_links WHERE instance_uuid = ?) ORDER BY d.stamp_s",
            (instance_uuid,),
        )
        return [float(t) for (t,) in rows if t is not None]

    def pose_before(self, stamp_s: float | None = None) -> tuple[int, int, float, list[list[float]]] | None:
        """(session id, pose id, stamp_s, T_map_cam) of the last recorded pose at or before
        ``stamp_s`` (None: the last pose of all)."""
        if stamp_s is None:
            row = self._db.execute(
                "SELECT session_id, pose_id, stamp_s, T_map_cam FROM poses ORDER BY stamp_s DESC, "
                "session_id DESC LIMIT 1"
            ).fetchone()
        else:
            row = self._db.execute(
                "SELECT session_id, pose_id, stamp_s, T_map_cam FROM poses WHERE stamp_s <= ? "
                "ORDER BY stamp_s DESC, session_id DESC LIMIT 1",
                (float(stamp_s),),
            ).fetchone()
        if row is None:
            return None
        return int(row[0]), int(row[1]), float(row[2]), pose_at(self._db, int(row[0]), float(row[2]), row[3])

    def stamp_span(self) -> tuple[float, float] | None:
        """(first, last) stamp of the poses and documents, None for an empty store."""
        lo, hi = self._db.execute(
            "SELECT MIN(t), MAX(t) FROM (SELECT MIN(stamp_s) AS t FROM poses UNION ALL "
            "SELECT MAX(stamp_s) FROM poses UNION ALL SELECT MIN(stamp_s) FROM docs "
            "WHERE type = 'observation' UNION ALL SELECT MAX(stamp_s) FROM docs WHERE type = 'observation')"
        ).fetchone()
        return None if lo is None else (float(lo), float(hi))
