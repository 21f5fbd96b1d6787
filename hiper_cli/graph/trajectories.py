"""Long instance trajectories, stored apart from their instance document in chunks of rows.

A tracked instance is upserted on every frame that observes it, with its whole trajectory
(``data["trajectory"]``, one row of ``model.TRAJECTORY_COLUMNS`` per update). Kept in the
document, a track seen for ten minutes at 30 Hz rewrites ~1.5 MB per frame. Beyond
``INLINE_ROWS`` rows the document keeps the row count and the mean speed
(``trajectory_rows``, ``trajectory_speed_mps``) and the rows go to the ``trajectories`` table
in chunks of ``CHUNK_ROWS``; a write replaces only the chunks whose content changed (compared
by digest with what this connection wrote), so a growing track costs one chunk per frame and
a smoothed one (every row changed) is rewritten once. Reads put the rows back: callers see
the same document either way.
"""

from __future__ import annotations

import hashlib
from typing import Any

from hiper_cli.graph.codec import dumps, loads
from hiper_cli.graph.sqlite_guard import GuardedConnection
from hiper_cli.learned import typical_speed_mps

__all__ = ["CHUNK_ROWS", "INLINE_ROWS", "SCHEMA", "TrajectoryStore"]

INLINE_ROWS = 256
CHUNK_ROWS = 128
SCHEMA = """
CREATE TABLE IF NOT EXISTS trajectories (
    instance_uuid TEXT NOT NULL, chunk INTEGER NOT NULL, rows TEXT NOT NULL,
    PRIMARY KEY (instance_uuid, chunk)
) WITHOUT ROWID;
"""


class TrajectoryStore:
    """The ``trajectories`` table of one document store connection."""

    def __init__(self, db: GuardedConnection) -> None:
        self._db = db
        self._chunks: dict[str, list[bytes]] = {}  # uuid -> digests of the committed chunks
        self._pending: dict[str, list[bytes]] = {}

    def split(self, doc: dict[str, Any]) -> tuple[dict[str, Any], list[Any] | None]:
        """The document to store and the rows to store apart (None: they stay inline)."""
        data = doc.get("data")
        rows = data.get("trajectory") if isinstance(data, dict) else None
        if not isinstance(rows, list) or len(rows) <= INLINE_ROWS:
            return doc, None
        assert isinstance(data, dict)
        kept = {k: v for k, v in data.items() if k != "trajectory"}
        kept["trajectory_rows"] = len(rows)
        kept["trajectory_speed_mps"] = typical_speed_mps(rows)
        return {**doc, "data": kept}, rows

    def write(self, uuid: str, rows: list[Any] | None) -> None:
        """Store ``rows`` as the trajectory of ``uuid`` (None: it has none apart)."""
        held = self._held(uuid)
        new: list[bytes] = []
        if rows is not None:
            for k in range(0, len(rows), CHUNK_ROWS):
                text = dumps(rows[k : k + CHUNK_ROWS])
                digest = hashlib.blake2b(text.encode(), digest_size=16).digest()
                index = k // CHUNK_ROWS
                if index >= len(held) or held[index] != digest:
                    self._db.execute("INSERT OR REPLACE INTO trajectories VALUES (?, ?, ?)",
                                     (uuid, index, text))
                new.append(digest)
        if len(new) < len(held):
            self._db.execute("DELETE FROM trajectories WHERE instance_uuid = ? AND chunk >= ?",
                             (uuid, len(new)))
        if new != held:
            self._pending[uuid] = new

    def _held(self, uuid: str) -> list[bytes]:
        """Digests of the chunks stored for ``uuid`` (read once per connection)."""
        if uuid in self._pending:
            return self._pending[uuid]
        if uuid not in self._chunks:
            rows = self._db.execute("SELECT rows FROM trajectories WHERE instance_uuid = ? ORDER BY chunk",
                                    (uuid,))
            self._chunks[uuid] = [hashlib.blake2b(str(t).encode(), digest_size=16).digest() for (t,) in rows]
        return self._chunks[uuid]

    def read(self, uuid: str) -> list[Any]:
        rows: list[Any] = []
        for (text,) in self._db.execute(
            "SELECT rows FROM trajectories WHERE instance_uuid = ? ORDER BY chunk", (uuid,)
        ):
            rows.extend(loads(text))
        return rows

    def delete(self, uuid: str) -> None:
        self._db.execute("DELETE FROM trajectories WHERE instance_uuid = ?", (uuid,))
        self._pending[uuid] = []

    def commit(self) -> None:
        self._chunks.update(self._pending)
        self._pending.clear()

    def rollback(self) -> None:
        self._pending.clear()

    @staticmethod
    def restore(doc: dict[str, Any], rows: list[Any]) -> None:
        """Put the rows back into a stored document (in place)."""
        data = doc["data"]
        data.pop("trajectory_rows", None)
        data.pop("trajectory_speed_mps", None)
        data["trajectory"] = rows
