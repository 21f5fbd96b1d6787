"""A column cache of trajectory rows: each foreground instance's rows as one float64 blob,
keyed by the change sequence of the document they were read from.

Trajectories are stored as JSON text (inline, or in chunks, see ``trajectories.py``); parsing
a million rows of it takes seconds. The interpretation reads them over and over, so the first
read of an instance's trajectory writes its rows here as raw bytes, and later reads take the
bytes as long as the document's ``seq`` has not moved. The cache is derived data: not part of
the change feed, never in the scene graph, rebuilt row by row whenever it is stale or missing,
and skipped (rows parsed each time) on a read-only knowledge base.
"""

from __future__ import annotations

import sqlite3
from collections.abc import Sequence

import numpy as np
import orjson
from numpy.typing import NDArray

from hiper_cli.errors import KnowledgeBaseError
from hiper_cli.graph.documents import DocumentStore
from hiper_cli.graph.sqlite_guard import GuardedConnection

__all__ = ["ROW_WIDTH", "track_rows"]

ROW_WIDTH = 7  # [stamp_s, x, y, z, vx, vy, vz], map frame
_SCHEMA = (
    "CREATE TABLE IF NOT EXISTS track_columns (instance_uuid TEXT PRIMARY KEY, seq INTEGER NOT NULL, "
    "rows BLOB NOT NULL)"
)
_BATCH = 500


def _parse(texts: Sequence[object]) -> NDArray[np.float64]:
    """Rows from JSON texts (each a list of rows); rows narrower than 7 values are dropped."""
    blocks = []
    for text in texts:
        block = np.asarray(orjson.loads(str(text)), dtype=np.float64)
        if block.size and block.ndim == 2 and block.shape[1] >= ROW_WIDTH:
            blocks.append(block[:, :ROW_WIDTH])
    return np.concatenate(blocks) if blocks else np.zeros((0, ROW_WIDTH))


def _has_table(db: GuardedConnection) -> bool:
    return db.execute("SELECT 1 FROM sqlite_master WHERE name = 'track_columns'").fetchone() is not None


def _parse_from_documents(db: GuardedConnection, uuids: Sequence[str]) -> dict[str, NDArray[np.float64]]:
    out: dict[str, NDArray[np.float64]] = {}
    apart: list[str] = []
    for start in range(0, len(uuids), _BATCH):
        batch = list(uuids[start : start + _BATCH])
        marks = ",".join("?" * len(batch))
        sql = f"SELECT uuid, json_extract(body, '$.data.trajectory') FROM docs WHERE uuid IN ({marks})"
        for uuid, text in db.execute(sql, batch):
            if text is None:
                apart.append(str(uuid))
            else:
                out[str(uuid)] = _parse([text])
    for start in range(0, len(apart), _BATCH):
        batch = apart[start : start + _BATCH]
        marks = ",".join("?" * len(batch))
        chunks: dict[str, list[object]] = {}
        sql = (
            f"SELECT instance_uuid, rows FROM trajectories WHERE instance_uuid IN ({marks}) ORDER BY 1, chunk"
        )
        for uuid, text in db.execute(sql, batch):
            chunks.setdefault(str(uuid), []).append(text)
        for uuid in batch:
            out[uuid] = _parse(chunks.get(uuid, []))
    return out


def _store(db: GuardedConnection, items: list[tuple[str, int, bytes]]) -> None:
    """Write cache rows in one transaction; a locked or read-only store is left as it is."""
    try:
        db.execute("BEGIN IMMEDIATE")
    except (sqlite3.OperationalError, KnowledgeBaseError):
        return
    try:
        db.execute(_SCHEMA)
        db.executemany("INSERT OR REPLACE INTO track_columns VALUES (?, ?, ?)", items)
        db.execute("COMMIT")
    except (sqlite3.OperationalError, KnowledgeBaseError):
        db.execute("ROLLBACK")


def track_rows(docs: DocumentStore, instances: Sequence[tuple[str, int]]) -> list[NDArray[np.float64]]:
    """The trajectory rows (N_k, 7) of each (uuid, seq) instance, in the given order."""
    db = docs.connection
    found: dict[str, NDArray[np.float64]] = {}
    if _has_table(db):
        seqs = dict(instances)
        uuids = list(seqs)
        for start in range(0, len(uuids), _BATCH):
            batch = uuids[start : start + _BATCH]
            marks = ",".join("?" * len(batch))
            sql = f"SELECT instance_uuid, seq, rows FROM track_columns WHERE instance_uuid IN ({marks})"
            for uuid, seq, blob in db.execute(sql, batch):
                if seqs.get(str(uuid)) == int(seq):
                    found[str(uuid)] = np.frombuffer(blob, dtype=np.float64).reshape(-1, ROW_WIDTH)
    stale = [u for u, _ in instances if u not in found]
    if stale:
        parsed = _parse_from_documents(db, stale)
        found.update(parsed)
        if not docs.read_only:
            seq_of = dict(instances)
            _store(db, [(u, seq_of[u], rows.tobytes()) for u, rows in parsed.items()])
    return [found.get(u, np.zeros((0, ROW_WIDTH))) for u, _ in instances]
