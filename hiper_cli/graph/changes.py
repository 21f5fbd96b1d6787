"""The change feed of the document store: what the scene graph replays after its high-water
mark (changed documents, provenance links and observation batches, tombstones), plus the
counts ``kb check`` compares with the graph. A mixin of ``DocumentStore``."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from hiper_cli.graph.codec import loads
from hiper_cli.graph.sqlite_guard import GuardedConnection

__all__ = ["ChangeFeed"]


class ChangeFeed:
    """Reads over the ``docs``, ``all_links`` and ``tombstones`` tables by change sequence."""

    _db: GuardedConnection

    def _scalar(self, sql: str, params: Sequence[Any] = ()) -> Any:
        row = self._db.execute(sql, params).fetchone()
        return None if row is None else row[0]

    def changed_docs(
        self, after_seq: int, upto_seq: int, batch: int = 2000, *, observation_bodies: bool = True,
        observations: bool = True,
    ) -> Iterator[list[tuple[dict[str, Any], bool]]]:
        """Batches of (document, created) changed in (after_seq, upto_seq], in change order;
        ``created`` is true when the document was first written after ``after_seq`` (a graph
        synchronised up to ``after_seq`` cannot hold its node yet). Without
        ``observation_bodies`` observations come as stubs of their indexed columns (uuid, type,
        layer, class, stamp_s, instance_uuid, env_uuid): no JSON to parse; without
        ``observations`` they are left out."""
        cursor = self._db.execute(
            "SELECT uuid, type, layer, class, stamp_s, instance_uuid, env_uuid, created_seq, "
            "CASE WHEN ? OR type != 'observation' THEN body END FROM docs WHERE seq > ? AND seq <= ? "
            f"{'' if observations else 'AND type != ' + repr('observation')} ORDER BY seq",
            (int(observation_bodies), after_seq, upto_seq),
        )
        while rows := cursor.fetchmany(batch):
            out = []
            for uuid, kind, layer, cls, stamp, inst, env, created, body in rows:
                if body is None:
                    doc = {"uuid": uuid, "type": kind, "layer": layer, "class": cls, "stamp_s": stamp,
                           "instance_uuid": inst, "env_uuid": env}
                else:
                    doc = self._stored(body, env)
                out.append((doc, created is not None and created > after_seq))
            yield out

    @staticmethod
    def _stored(body: str, env: str | None) -> dict[str, Any]:
        """A body as stored (instances without their observation list), plus ``env_uuid``."""
        doc: dict[str, Any] = loads(body)
        if env is not None:
            doc.setdefault("env_uuid", env)
        return doc

    def sample(self, n: int, seed: int = 0) -> list[dict[str, Any]]:
        """Up to ``n`` documents spread evenly over the store, in the form ``changed_docs`` gives."""
        total = int(self._scalar("SELECT MAX(id) FROM docs") or 0)
        if total == 0 or n <= 0:
            return []
        step = max(1, total // n)
        rows = self._db.execute(
            "SELECT body, env_uuid FROM docs WHERE (id + ?) % ? = 0 LIMIT ?", (seed, step, n)
        ).fetchall()
        return [self._stored(body, env) for body, env in rows]

    _LINK_LAYER = (
        "COALESCE((SELECT layer FROM docs WHERE uuid = l.instance_uuid), "
        "(SELECT layer FROM docs WHERE uuid = l.observation_uuid), 'foreground')"
    )

    def changed_links(
        self, after_seq: int, upto_seq: int, batch: int = 20000
    ) -> Iterator[list[tuple[str, str, str]]]:
        """Batches of (instance, observation, layer of the instance) links added in
        (after_seq, upto_seq]."""
        cursor = self._db.execute(
            f"SELECT DISTINCT l.instance_uuid, l.observation_uuid, {self._LINK_LAYER} FROM all_links l "
            "WHERE l.seq > ? AND l.seq <= ?",
            (after_seq, upto_seq),
        )
        while rows := cursor.fetchmany(batch):
            yield rows

    # Observation batches (the graph's "batch" detail): the observations of one instance from one
    # session within one window of ``batch_s`` seconds (window = CAST(stamp_s / batch_s AS INTEGER)).
    _BATCH_KEY = "l.instance_uuid, d.session_id, CAST(d.stamp_s / ? AS INTEGER)"

    def changed_batches(
        self, after_seq: int, upto_seq: int, batch_s: float
    ) -> list[tuple[str, int | None, int]]:
        """(instance, session, window) of the batches that links added in (after_seq, upto_seq]
        fall into."""
        rows = self._db.execute(
            f"SELECT DISTINCT {self._BATCH_KEY} FROM all_links l JOIN docs d ON d.uuid = l.observation_uuid "
            "WHERE l.seq > ? AND l.seq <= ?",
            (batch_s, after_seq, upto_seq),
        )
        return [(str(i), None if s is None else int(s), int(w)) for i, s, w in rows]

    def batches_of(
        self, instance_uuid: str, batch_s: float, first_window: int, last_window: int
    ) -> list[tuple[int | None, int, int, float, float]]:
        """(session, window, observations, first stamp, last stamp) of an instance's batches
        with windows in [first_window, last_window]."""
        rows = self._db.execute(
            "SELECT d.session_id, CAST(d.stamp_s / ?1 AS INTEGER) AS w, COUNT(DISTINCT d.uuid), "
            "MIN(d.stamp_s), MAX(d.stamp_s) FROM all_links l JOIN docs d ON d.uuid = l.observation_uuid "
            "WHERE l.instance_uuid = ?2 AND w BETWEEN ?3 AND ?4 GROUP BY d.session_id, w",
            (batch_s, instance_uuid, first_window, last_window),
        )
        return [(None if s is None else int(s), int(w), int(n), float(t0), float(t1))
                for s, w, n, t0, t1 in rows]

    def batch_count(self, batch_s: float) -> dict[str, int]:
        """Batches per layer of their instance."""
        rows = self._db.execute(
            "SELECT COALESCE((SELECT layer FROM docs WHERE uuid = b.instance_uuid), 'foreground') AS layer, "
            f"COUNT(*) FROM (SELECT DISTINCT {self._BATCH_KEY} AS w FROM all_links l "
            "JOIN docs d ON d.uuid = l.observation_uuid) b GROUP BY layer",
            (batch_s,),
        )
        return {str(layer): int(n) for layer, n in rows}

    def layer_of(self, uuid: str) -> str | None:
        value = self._scalar("SELECT layer FROM docs WHERE uuid = ?", (uuid,))
        return None if value is None else str(value)

    def link_counts_by_layer(self) -> dict[str, int]:
        rows = self._db.execute(f"SELECT {self._LINK_LAYER} AS layer, COUNT(*) FROM "
                                "(SELECT DISTINCT instance_uuid, observation_uuid FROM all_links) l "
                                "GROUP BY layer")
        return {str(layer): int(n) for layer, n in rows}

    def tombstones(self, after_seq: int, upto_seq: int) -> list[tuple[str, str, str | None]]:
        return list(
            self._db.execute(
                "SELECT uuid, type, layer FROM tombstones WHERE seq > ? AND seq <= ?", (after_seq, upto_seq)
            )
        )

    def all_links(self) -> Iterator[tuple[str, str]]:
        yield from self._db.execute("SELECT DISTINCT instance_uuid, observation_uuid FROM all_links")

    def link_count(self) -> int:
        return int(self._scalar("SELECT COUNT(*) FROM (SELECT DISTINCT instance_uuid, observation_uuid "
                                "FROM all_links)"))
