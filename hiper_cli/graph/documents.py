"""The document store: the knowledge base's source of truth, in stdlib SQLite (WAL mode).

Every entity (observation, instance, analysis, environment) is one JSON document keyed by uuid,
with indexed columns for what queries filter on: type, layer, class, stamp, instance link,
session, environment; observations are indexed spatially by the 2 m map cell of their box
centre (``obs_cells``), instances in an R*Tree over their map-frame box. Spatial-index rows
and instance links are staged in append-only tables and moved in batches (see docs/kb.md).

Every write transaction takes the next value of a monotonically increasing change sequence
(``seq``); changed rows carry it, deletions leave a tombstone carrying it. The scene graph is
brought up to date from the documents by replaying everything after its high-water mark, so a
crash between the two stores is repaired on the next open.

Chosen by measurement (see docs/kb.md): TinyDB's JSON storage rewrites the whole file on every
write (~1,300 docs/s at 2 k documents, ~600/s at 5 k), SQLite with JSON documents keeps
> 10 k observations/s at 500 k rows with per-frame transactions.
"""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.errors import KnowledgeBaseError
from hiper_cli.graph.changes import ChangeFeed
from hiper_cli.graph.codec import dumps, loads
from hiper_cli.graph.grid import GRID_CELL_M, cell_index, cell_key, grid_rows
from hiper_cli.graph.lookups import Lookups
from hiper_cli.graph.poserows import pose_at
from hiper_cli.graph.schema import DOCUMENTS_SCHEMA
from hiper_cli.graph.sqlite_guard import (
    GuardedConnection,
    connect_read_only,
    damaged_error,
    inspect_existing,
    translate,
)
from hiper_cli.graph.trajectories import SCHEMA as TRAJECTORIES_SCHEMA
from hiper_cli.graph.trajectories import TrajectoryStore
from hiper_cli.graph.versions import SCHEMA_VERSION, check_version, stored_version

__all__ = ["SCHEMA_VERSION", "DocumentStore", "Session", "dumps"]

PAGE_SIZE = 2048
# Observations' spatial-index rows and instance links are first appended to two small staging
# tables (``obs_cells_new``, ``links_new``) and moved into their clustered tables once this many
# rows wait, inside the transaction of the frame that reaches it; reads look at both.
STAGED_ROWS = 4000
# The R*Tree row of a moving document (an instance) is its box grown by this much; updates
# inside it leave the index alone.
BOX_SLACK_M = 0.25

def pose_text(T_map_cam: Any) -> str:
    """A pose row's 4×4 matrix as compact JSON: rotation to 1e-6, translation to 10 µm (a
    pose row a frame is most of what a session adds once its observations are summarised;
    this is about half the full-precision text)."""
    rows = T_map_cam.tolist() if hasattr(T_map_cam, "tolist") else T_map_cam
    top = [[round(float(v), 6) for v in row[:3]] + [round(float(row[3]), 5)] for row in rows[:3]]
    return json.dumps([*top, [0, 0, 0, 1]], separators=(",", ":"))


@dataclass(frozen=True)
class Session:
    """One ``perceive`` run: which log, into which environment, how far it got."""

    id: int
    env_uuid: str
    log_path: str
    stages: tuple[str, ...]
    started_s: float
    ended_s: float | None
    frames: int
    last_pose_id: int | None
    last_stamp_s: float | None

    @property
    def finished(self) -> bool:
        return self.ended_s is not None

    def to_dict(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "env_uuid": self.env_uuid,
            "log_path": self.log_path,
            "stages": list(self.stages),
            "started_s": self.started_s,
            "ended_s": self.ended_s,
            "frames": self.frames,
            "last_pose_id": self.last_pose_id,
            "last_stamp_s": self.last_stamp_s,
        }


@dataclass
class _Batch:
    """The rows one ``put_many`` writes: documents, instance boxes, observation grid cells (and
    the largest half-extent among them), observation -> instance links, long trajectories."""

    rows: list[tuple[Any, ...]] = field(default_factory=list)
    boxes: list[tuple[Any, ...]] = field(default_factory=list)
    grid: list[tuple[Any, ...]] = field(default_factory=list)
    margin_m: float = 0.0
    obs_links: list[tuple[str, str, int]] = field(default_factory=list)
    trajectories: list[tuple[str, list[Any] | None]] = field(default_factory=list)


_SESSION_COLUMNS = "id, env_uuid, log_path, stages, started_s, ended_s, frames, last_pose_id, last_stamp_s"


def _session(row: Sequence[Any]) -> Session:
    return Session(
        id=int(row[0]),
        env_uuid=str(row[1]),
        log_path=str(row[2]),
        stages=tuple(json.loads(row[3])),
        started_s=float(row[4]),
        ended_s=None if row[5] is None else float(row[5]),
        frames=int(row[6]),
        last_pose_id=None if row[7] is None else int(row[7]),
        last_stamp_s=None if row[8] is None else float(row[8]),
    )


Box = tuple[Sequence[float], Sequence[float]]

# Observations are indexed by the map cell of their box centre (graph/grid.py); a query widens
# its box by the largest half extent stored (meta ``grid_margin_m``). Other documents
# (instances, few and moving) stay in the R*Tree ``docs_box``.
def _box_meets(doc: dict[str, Any], lo: Sequence[float], hi: Sequence[float]) -> bool:
    """Whether the map-frame box of a document (``box``: centre, extent, rotation) meets the
    axis-aligned box [lo, hi]; a document without a box passes."""
    box = doc.get("box")
    if not box:
        return True
    c, e = box["center_m"], box["extent_m"]
    R = box.get("R") or [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    for k in range(3):
        half = sum(abs(R[k][j]) * e[j] / 2.0 for j in range(3))
        if c[k] + half < lo[k] or c[k] - half > hi[k]:
            return False
    return True


class DocumentStore(ChangeFeed, Lookups):
    """JSON documents in one SQLite file. Writes happen inside ``transaction()``."""

    def __init__(self, path: Path, *, read_only: bool = False) -> None:
        self.path = Path(path)
        self.read_only = read_only
        if self.path.is_file() and self.path.stat().st_size > 0:
            inspect_existing(self.path)  # read-only: refuse another program's file before any write
            check_version(self.path.parent, stored_version(self.path))  # and another schema version
        try:
            if read_only:
                self._db = GuardedConnection(connect_read_only(self.path), self.path)
            else:
                self._db = GuardedConnection(sqlite3.connect(str(self.path), isolation_level=None,
                                                             timeout=30.0), self.path)
                # 2 KiB pages (only takes effect on a new file): a frame dirties a few dozen
                # index pages spread over the file and COMMIT copies each into the WAL, so
                # smaller pages mean fewer bytes per commit (2 KiB ingests ~20 % faster than
                # 4 KiB at 100 k observations; 1 KiB is slower: deeper trees)
                self._db.execute(f"PRAGMA page_size={PAGE_SIZE}")
                self._db.execute("PRAGMA journal_mode=WAL")
                # NORMAL in WAL mode: a killed process never loses a committed transaction;
                # only a power cut may lose the last ones (never corrupts).
                self._db.execute("PRAGMA synchronous=NORMAL")
                # A bounded page cache (32 MiB) and fewer, larger checkpoints (a WAL of up to
                # 40,000 pages = 80 MiB on disk: pages rewritten by many frames are copied back
                # once per checkpoint) ingest ~1/3 faster at 500 k documents than SQLite's
                # defaults; memory stays bounded.
                self._db.execute("PRAGMA cache_size=-32768")
                self._db.execute("PRAGMA wal_autocheckpoint=40000")
                # the tables and the schema version in one transaction: a process killed while
                # creating the store leaves an empty file (which the next open initialises), never
                # tables without a version (which would read as another program's database)
                self._db.executescript(
                    "BEGIN IMMEDIATE;\n" + DOCUMENTS_SCHEMA + TRAJECTORIES_SCHEMA
                    + f"\nINSERT OR IGNORE INTO meta VALUES ('schema_version', '{SCHEMA_VERSION}');"
                    "\nINSERT OR IGNORE INTO meta VALUES ('seq', '0');\nCOMMIT;"
                )
                columns = {str(r[1]) for r in self._db.execute("PRAGMA table_info(docs)")}
                if "created_seq" not in columns:  # a store written before it existed: NULL = old
                    self._db.execute("ALTER TABLE docs ADD COLUMN created_seq INTEGER")
        except (sqlite3.Error, KnowledgeBaseError) as err:
            if hasattr(self, "_db"):
                self._db.close()
            if isinstance(err, KnowledgeBaseError):
                raise
            raise translate(self.path, err) from err
        self._seq: int | None = None
        cell = self.meta("grid_cell_m")
        legacy = self._scalar("SELECT name FROM sqlite_master WHERE name = 'obs_grid'") is not None
        if not read_only and (cell is None or legacy):
            self._migrate_grid(cell, legacy)
            cell = self.meta("grid_cell_m")
        self._grid_cell_m = float(cell or 1.0)
        # instance uuid -> number of its links, for links committed by this connection (saves a
        # COUNT per instance upsert); entries written in an open transaction wait in _pending
        self._link_counts: dict[str, int] = {}
        self._pending_link_counts: dict[str, int] = {}
        self._staged = -1  # rows in the staging tables, -1 = count them
        # uuid -> the R*Tree row of a document's box as committed by this connection / pending
        self._boxes: dict[str, tuple[float, ...]] = {}
        self._pending_boxes: dict[str, tuple[float, ...]] = {}
        self._traj = TrajectoryStore(self._db)

    def _migrate_grid(self, cell: str | None, legacy: bool) -> None:
        """Stores written before the (cell, id) keyed ``obs_cells`` table (1 m cells in
        ``obs_grid``) keep their cell size and move their rows over, once."""
        self._db.execute("BEGIN IMMEDIATE")
        try:
            if cell is None:
                cell = "1.0" if legacy else repr(GRID_CELL_M)
                self.set_meta("grid_cell_m", cell)
            if legacy:
                self._db.execute("INSERT OR REPLACE INTO obs_cells SELECT cell, id, min_x, max_x, min_y, "
                                 "max_y, min_z, max_z FROM obs_grid")
                self._db.execute("DROP TABLE obs_grid")
        except BaseException:
            self._db.execute("ROLLBACK")
            raise
        self._db.execute("COMMIT")

    @property
    def connection(self) -> GuardedConnection:
        """The SQLite connection, for column reads (``columns.py``); write through ``put``."""
        return self._db

    def close(self) -> None:
        self._db.close()

    # -- transactions -------------------------------------------------------------------------

    @contextmanager
    def transaction(self) -> Iterator[int]:
        """One atomic write; yields its change sequence number."""
        if self._seq is not None:
            raise KnowledgeBaseError("nested knowledge-base transactions are not supported")
        self._db.execute("BEGIN IMMEDIATE")
        try:
            seq = int(self._scalar("SELECT value FROM meta WHERE key = 'seq'")) + 1
            self._db.execute("UPDATE meta SET value = ? WHERE key = 'seq'", (str(seq),))
            self._seq = seq
            yield seq
            if self._staged_rows() >= STAGED_ROWS:
                self._unstage()
        except BaseException:
            self._seq = None
            self._forget_pending()
            self._db.execute("ROLLBACK")
            raise
        self._seq = None
        try:
            self._db.execute("COMMIT")
        except BaseException:
            self._forget_pending()
            raise
        self._link_counts.update(self._pending_link_counts)
        self._pending_link_counts.clear()
        self._boxes.update(self._pending_boxes)
        self._pending_boxes.clear()
        self._traj.commit()

    def _forget_pending(self) -> None:
        self._traj.rollback()
        self._pending_link_counts.clear()
        self._pending_boxes.clear()
        self._staged = -1

    def _staged_rows(self) -> int:
        if self._staged < 0:
            self._staged = int(self._scalar("SELECT (SELECT COUNT(*) FROM obs_cells_new) + "
                                            "(SELECT COUNT(*) FROM links_new)"))
        return self._staged

    def _unstage(self) -> None:
        """Move the staged rows into the clustered tables (in the open transaction)."""
        db = self._db
        db.execute("INSERT OR REPLACE INTO obs_cells SELECT cell, id, min_x, max_x, min_y, max_y, min_z, "
                   "max_z FROM obs_cells_new ORDER BY cell, id")
        db.execute("DELETE FROM obs_cells_new")
        db.execute("INSERT OR IGNORE INTO links SELECT instance_uuid, observation_uuid, seq FROM links_new "
                   "ORDER BY instance_uuid, observation_uuid")
        db.execute("DELETE FROM links_new")
        self._staged = 0

    def _current_seq(self) -> int:
        if self._seq is None:
            raise KnowledgeBaseError("document writes must happen inside DocumentStore.transaction()")
        return self._seq

    def meta(self, key: str) -> str | None:
        value = self._scalar("SELECT value FROM meta WHERE key = ?", (key,))
        return None if value is None else str(value)

    def set_meta(self, key: str, value: str) -> None:
        self._db.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)", (key, value))

    def drop_meta(self, key: str) -> None:
        self._db.execute("DELETE FROM meta WHERE key = ?", (key,))

    @property
    def seq(self) -> int:
        """The sequence number of the last committed write."""
        return int(self._scalar("SELECT value FROM meta WHERE key = 'seq'") or 0)

    # -- writes -------------------------------------------------------------------------------

    def put(
        self,
        doc: dict[str, Any],
        *,
        session_id: int | None = None,
        env_uuid: str | None = None,
        box_map: Box | None = None,
    ) -> None:
        """Insert or replace ``doc`` (a ``to_dict`` form); ``box_map`` = (min, max) in the map frame."""
        self.put_many([(doc, box_map)], session_id=session_id, env_uuid=env_uuid)

    _UPSERT = (
        "INSERT INTO docs (uuid, type, layer, class, stamp_s, instance_uuid, session_id, env_uuid, "
        "seq, body, created_seq) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?9) ON CONFLICT(uuid) DO UPDATE SET "
        "class=excluded.class, stamp_s=excluded.stamp_s, seq=excluded.seq, body=excluded.body"
    )  # an update sets only what changes (each indexed column in SET costs an index rewrite);
    # a document keeps its type, layer, instance link, session, environment and creation seq

    _INSERT_NEW = _UPSERT[: _UPSERT.index(" ON CONFLICT")] + " ON CONFLICT(uuid) DO NOTHING"

    def put_many(
        self,
        items: Sequence[tuple[dict[str, Any], Box | None]],
        *,
        session_id: int | None = None,
        env_uuid: str | None = None,
    ) -> None:
        """Insert or replace documents, each with its map-frame (min, max) box or None."""
        if not items:
            return
        seq = self._current_seq()
        batch = self._batch(items, session_id, env_uuid, seq)
        existing = self._write_rows(batch.rows)
        index_rows = [r for r in map(self._index_box, batch.boxes) if r is not None]
        if index_rows:
            self._db.executemany(
                "INSERT OR REPLACE INTO docs_box SELECT id, ?, ?, ?, ?, ?, ? FROM docs WHERE uuid = ?",
                index_rows,
            )
        if batch.grid:
            self._write_cells(batch.grid, batch.margin_m, existing)
        if batch.obs_links:
            self._write_obs_links(batch.obs_links, existing)
        for doc, _ in items:
            if doc["type"] == "instance":
                self._link_instance(doc["uuid"], doc.get("observation_uuids", []), seq)
        for uuid, apart in batch.trajectories:
            self._traj.write(uuid, apart)
        self._revive([r[0] for r in batch.rows])

    def _batch(self, items: Sequence[tuple[dict[str, Any], Box | None]], session_id: int | None,
               env_uuid: str | None, seq: int) -> _Batch:
        """The rows of ``put_many``: documents, instance boxes, observation cells and links."""
        batch = _Batch()
        cell_m = self._grid_cell_m
        for doc, box_map in items:
            stamp = doc.get("stamp_s", doc.get("last_seen_s", doc.get("t_end_s")))
            stored = doc
            if doc["type"] == "instance":  # the observation list lives in ``links`` only
                stored = {k: v for k, v in doc.items() if k != "observation_uuids"}
                stored["observation_count"] = len(doc.get("observation_uuids", [])) + int(
                    (doc.get("data") or {}).get("observations_summarised", 0))  # see compact.py
                stored, apart = self._traj.split(stored)  # long trajectories: see trajectories.py
                batch.trajectories.append((doc["uuid"], apart))
            batch.rows.append((doc["uuid"], doc["type"], doc.get("layer"), doc.get("class"), stamp,
                               doc.get("instance_uuid"), session_id, env_uuid, seq, dumps(stored)))
            if box_map is not None:
                lo, hi = box_map
                if doc["type"] == "observation":
                    c = [(lo[k] + hi[k]) / 2.0 for k in range(3)]
                    batch.margin_m = max(batch.margin_m, *(hi[k] - c[k] for k in range(3)))
                    batch.grid.append((cell_key(*(cell_index(v, cell_m) for v in c)),
                                       lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], doc["uuid"]))
                else:
                    batch.boxes.append((lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], doc["uuid"]))
            if doc["type"] == "observation" and doc.get("instance_uuid"):
                batch.obs_links.append((doc["instance_uuid"], doc["uuid"], seq))
        return batch

    def _write_rows(self, rows: list[tuple[Any, ...]]) -> set[str]:
        """Insert or replace the document rows; the uuids of observations that were there already."""
        db = self._db
        obs_rows = [r for r in rows if r[1] == "observation"]
        existing: set[str] = set()
        if obs_rows:
            # observations are almost always new: insert them, and only when some uuid was
            # there already (an import, a re-anchoring, a repeat) write them all again as
            # updates, treating every one as a rewrite (cheaper than looking each up first)
            before = db.total_changes
            db.executemany(self._INSERT_NEW, obs_rows)
            if db.total_changes - before < len(obs_rows):
                existing = {r[0] for r in obs_rows}
                db.executemany(self._UPSERT, obs_rows)
        other = [r for r in rows if r[1] != "observation"] if obs_rows else rows
        if other:
            db.executemany(self._UPSERT, other)
        return existing

    def _write_cells(self, grid: list[tuple[Any, ...]], margin_m: float, existing: set[str]) -> None:
        """The observations' grid cells; a re-written observation may move to another cell."""
        if existing:
            self._db.executemany("DELETE FROM obs_cells WHERE id = (SELECT id FROM docs WHERE uuid = ?)",
                                 [(u,) for u in existing])
        self._db.executemany(
            "INSERT OR REPLACE INTO obs_cells_new SELECT id, ?, ?, ?, ?, ?, ?, ? FROM docs "
            "WHERE uuid = ?",
            grid,
        )
        self._staged += len(grid) if self._staged >= 0 else 0
        if margin_m > self._grid_margin():
            self.set_meta("grid_margin_m", repr(margin_m))

    def _write_obs_links(self, obs_links: list[tuple[str, str, int]], existing: set[str]) -> None:
        """The links of new observations to their instances, and the instances' pending counts."""
        self._db.executemany("INSERT INTO links_new VALUES (?, ?, ?)", obs_links)
        self._staged += len(obs_links) if self._staged >= 0 else 0
        for instance_uuid, observation_uuid, _ in obs_links:
            known = self._known_links(instance_uuid)
            new = known >= 0 and observation_uuid not in existing
            self._pending_link_counts[instance_uuid] = known + 1 if new else -1

    def _revive(self, uuids: list[str]) -> None:
        """A document written again after its deletion: no tombstone any more, and its
        creation is unknown (the graph may still hold the node of its earlier life)."""
        if not self._scalar("SELECT EXISTS (SELECT 1 FROM tombstones)"):
            return
        marks = ",".join("?" * len(uuids))
        found = self._db.execute(f"SELECT uuid FROM tombstones WHERE uuid IN ({marks})", uuids)
        revived = [(u,) for (u,) in found]
        if revived:
            self._db.executemany("DELETE FROM tombstones WHERE uuid = ?", revived)
            self._db.executemany("UPDATE docs SET created_seq = NULL WHERE uuid = ?", revived)

    def _index_box(self, bounds: tuple[Any, ...]) -> tuple[Any, ...] | None:
        """The R*Tree row for a document's box (min_x, max_x, ..., max_z, uuid), or None while
        the box stays inside the row the index holds: rows are the box grown by
        ``BOX_SLACK_M`` on every side. A tracked instance moves a little every frame, and
        re-inserting it into the R*Tree each time would be ~20 % of the ingest; queries
        test each document's own box after the index."""
        uuid = bounds[6]
        held = self._pending_boxes.get(uuid, self._boxes.get(uuid))
        if held is not None and all(held[k] <= bounds[k] for k in (0, 2, 4)) and all(
            held[k] >= bounds[k] for k in (1, 3, 5)
        ):
            return None
        grown = tuple(bounds[k] + (BOX_SLACK_M if k % 2 else -BOX_SLACK_M) for k in range(6))
        self._pending_boxes[uuid] = grown
        return (*grown, uuid)

    def _link_instance(self, instance_uuid: str, observation_uuids: Sequence[str], seq: int) -> None:
        """Links of an instance to its observations. Observation lists usually only grow, so
        only the tail beyond the stored count is inserted; anything else inserts them all."""
        if self._known_links(instance_uuid) == len(observation_uuids):
            return
        known = self._count_links(instance_uuid)
        if known != len(observation_uuids):
            sql = "INSERT OR IGNORE INTO links VALUES (?, ?, ?)"
            self._db.executemany(sql, [(instance_uuid, o, seq) for o in observation_uuids[known:]])
            known = self._count_links(instance_uuid)
            if known < len(observation_uuids):
                self._db.executemany(sql, [(instance_uuid, o, seq) for o in observation_uuids])
                known = self._count_links(instance_uuid)
        self._pending_link_counts[instance_uuid] = known

    def _known_links(self, instance_uuid: str) -> int:
        """The cached number of links of an instance, -1 when unknown."""
        return self._pending_link_counts.get(instance_uuid, self._link_counts.get(instance_uuid, -1))

    def _count_links(self, instance_uuid: str) -> int:
        sql = "SELECT COUNT(DISTINCT observation_uuid) FROM all_links WHERE instance_uuid = ?"
        return int(self._scalar(sql, (instance_uuid,)))

    def _decode(self, body: str) -> dict[str, Any]:
        """A stored body as its ``to_dict`` form (instances get their observation list back,
        oldest link first, and a trajectory stored apart)."""
        doc: dict[str, Any] = loads(body)
        if doc.get("type") == "instance":
            doc.pop("observation_count", None)
            doc["observation_uuids"] = [
                str(o) for (o,) in self._db.execute(
                    "SELECT observation_uuid FROM all_links WHERE instance_uuid = ? "
                    "GROUP BY observation_uuid ORDER BY MIN(seq), observation_uuid",
                    (doc["uuid"],),
                )
            ]
            if "trajectory_rows" in (doc.get("data") or {}):
                TrajectoryStore.restore(doc, self._traj.read(doc["uuid"]))
        return doc

    def delete(self, uuid: str) -> bool:
        """Delete a document (and its links); leaves a tombstone for the graph. False if absent."""
        seq = self._current_seq()
        row = self._db.execute("SELECT id, type, layer FROM docs WHERE uuid = ?", (uuid,)).fetchone()
        if row is None:
            return False
        self._db.execute("DELETE FROM docs WHERE id = ?", (row[0],))
        self._db.execute("DELETE FROM docs_box WHERE id = ?", (row[0],))
        self._boxes.pop(uuid, None)
        self._pending_boxes.pop(uuid, None)
        self._traj.delete(uuid)
        self._db.execute("DELETE FROM obs_cells WHERE id = ?", (row[0],))
        self._db.execute("DELETE FROM obs_cells_new WHERE id = ?", (row[0],))
        self._db.execute("DELETE FROM links WHERE instance_uuid = ?", (uuid,))
        self._db.execute("DELETE FROM links_new WHERE instance_uuid = ?", (uuid,))
        self._staged = -1
        self._pending_link_counts[uuid] = 0
        self._db.execute("INSERT OR REPLACE INTO tombstones VALUES (?, ?, ?, ?)", (uuid, row[1], row[2], seq))
        return True

    def start_session(self, env_uuid: str, log_path: str, stages: Sequence[str]) -> Session:
        seq = self._current_seq()
        now = time.time()
        cur = self._db.execute(
            "INSERT INTO sessions (env_uuid, log_path, stages, started_s, seq) VALUES (?, ?, ?, ?, ?)",
            (env_uuid, log_path, json.dumps(list(stages)), now, seq),
        )
        session = self.session(int(cur.lastrowid or 0))
        assert session is not None
        return session

    def record_frame(self, session_id: int, pose_id: int, stamp_s: float, T_map_cam: Any) -> None:
        """The pose row of a committed frame and the session's progress."""
        seq = self._current_seq()
        self._db.execute(
            "INSERT OR REPLACE INTO poses VALUES (?, ?, ?, ?)",
            (session_id, pose_id, stamp_s, pose_text(T_map_cam)),
        )
        self._db.execute(
            "UPDATE sessions SET frames = frames + 1, last_pose_id = ?, last_stamp_s = ?, seq = ? "
            "WHERE id = ?",
            (pose_id, stamp_s, seq, session_id),
        )

    def clear_session(self, session_id: int) -> int:
        """Delete the documents a session created (observations, instances: tombstones for the
        graph), its pose rows and every link to its observations, and restart the session row
        (no frames, unfinished). Instances of other sessions it updated keep their update.
        Returns the number of documents deleted."""
        seq = self._current_seq()
        db = self._db
        uuids = [str(u) for (u,) in db.execute("SELECT uuid FROM docs WHERE session_id = ?", (session_id,))]
        db.execute("DELETE FROM links WHERE observation_uuid IN "
                   "(SELECT uuid FROM docs WHERE session_id = ? AND type = 'observation')", (session_id,))
        db.execute("DELETE FROM links_new WHERE observation_uuid IN "
                   "(SELECT uuid FROM docs WHERE session_id = ? AND type = 'observation')", (session_id,))
        for uuid in uuids:
            self.delete(uuid)
        self._link_counts.clear()
        self._pending_link_counts.clear()
        db.execute("DELETE FROM poses WHERE session_id = ?", (session_id,))
        db.execute("UPDATE sessions SET frames = 0, last_pose_id = NULL, last_stamp_s = NULL, "
                   "ended_s = NULL, "
                   "started_s = ?, seq = ? WHERE id = ?", (time.time(), seq, session_id))
        return len(uuids)

    def end_session(self, session_id: int) -> None:
        seq = self._current_seq()
        self._db.execute(
            "UPDATE sessions SET ended_s = ?, seq = ? WHERE id = ?", (time.time(), seq, session_id)
        )

    # -- reads --------------------------------------------------------------------------------

    def get(self, uuid: str) -> dict[str, Any] | None:
        body = self._scalar("SELECT body FROM docs WHERE uuid = ?", (uuid,))
        return None if body is None else self._decode(body)

    def find(
        self,
        *,
        type: str | None = None,
        layer: str | None = None,
        class_name: str | None = None,
        t_start_s: float | None = None,
        t_end_s: float | None = None,
        env_uuid: str | None = None,
        limit: int | None = None,
    ) -> list[dict[str, Any]]:
        """Documents matching every given filter, in stamp order (the stamp of an instance is
        its last sighting, of an analysis its window end)."""
        where, params = self._where(type, layer, class_name, t_start_s, t_end_s, env_uuid)
        sql = f"SELECT body FROM docs{where} ORDER BY stamp_s, id"
        if limit is not None:
            sql += f" LIMIT {int(limit)}"
        return [self._decode(b) for (b,) in self._db.execute(sql, params)]

    def count(
        self, *, type: str | None = None, layer: str | None = None, class_name: str | None = None
    ) -> int:
        where, params = self._where(type, layer, class_name, None, None, None)
        return int(self._scalar(f"SELECT COUNT(*) FROM docs{where}", params))

    @staticmethod
    def _where(
        type: str | None,
        layer: str | None,
        class_name: str | None,
        t0: float | None,
        t1: float | None,
        env_uuid: str | None,
    ) -> tuple[str, list[Any]]:
        clauses: list[str] = []
        params: list[Any] = []
        filters = (("type", type), ("layer", layer), ("class", class_name), ("env_uuid", env_uuid))
        for column, value in filters:
            if value is not None:
                clauses.append(f"{column} = ?")
                params.append(value)
        if t0 is not None:
            clauses.append("stamp_s >= ?")
            params.append(t0)
        if t1 is not None:
            clauses.append("stamp_s <= ?")
            params.append(t1)
        return (" WHERE " + " AND ".join(clauses) if clauses else ""), params

    def summaries(self, uuids: Sequence[str]) -> dict[str, tuple[str | None, float | None]]:
        """uuid -> (class, stamp) of the documents among ``uuids``."""
        marks = ",".join("?" * len(uuids))
        rows = self._db.execute(f"SELECT uuid, class, stamp_s FROM docs WHERE uuid IN ({marks})", list(uuids))
        return {str(u): (cls, stamp) for u, cls, stamp in rows}

    def observations_of(self, instance_uuid: str) -> list[dict[str, Any]]:
        """The observation documents an instance was formed from, in time order."""
        rows = self._db.execute(
            "SELECT d.body FROM docs d WHERE d.uuid IN "
            "(SELECT observation_uuid FROM all_links WHERE instance_uuid = ?) ORDER BY d.stamp_s",
            (instance_uuid,),
        )
        return [loads(b) for (b,) in rows]

    def in_box(
        self, lo: Sequence[float], hi: Sequence[float], *, type: str | None = None, limit: int | None = None
    ) -> list[dict[str, Any]]:
        """Documents whose map-frame box intersects the axis-aligned box [lo, hi]."""
        out: list[dict[str, Any]] = []
        if type in (None, "observation"):
            out = self._observations_in_box(lo, hi, limit)
        if type == "observation" or (limit is not None and len(out) >= limit):
            return out
        sql = (
            "SELECT d.body FROM docs_box b CROSS JOIN docs d ON d.id = b.id "
            "WHERE b.max_x >= ? AND b.min_x <= ? AND b.max_y >= ? AND b.min_y <= ? "
            "AND b.max_z >= ? AND b.min_z <= ?"
        )
        params: list[Any] = [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]]
        if type is not None:
            sql += " AND d.type = ?"
            params.append(type)
        docs = (self._decode(b) for (b,) in self._db.execute(sql, params))
        found = [d for d in docs if _box_meets(d, lo, hi)]
        return out + (found if limit is None else found[: int(limit) - len(out)])

    def _grid_margin(self) -> float:
        value = self.meta("grid_margin_m")
        return 0.0 if value is None else float(value)

    def _observations_in_box(
        self, lo: Sequence[float], hi: Sequence[float], limit: int | None
    ) -> list[dict[str, Any]]:
        bounds = [hi[0], lo[0], hi[1], lo[1], hi[2], lo[2]]
        where = ("g.min_x <= ? AND g.max_x >= ? AND g.min_y <= ? AND g.max_y >= ? "
                 "AND g.min_z <= ? AND g.max_z >= ?")
        select = "SELECT d.body FROM {table} g CROSS JOIN docs d ON d.id = g.id WHERE "
        rows = grid_rows(self._db, select, where, bounds, lo, hi, self._grid_cell_m,
                         margin_m=self._grid_margin(), limit=limit)
        out = [self._decode(b) for (b,) in rows]
        return out if limit is None else out[:limit]

    def counts(self) -> list[tuple[str, str | None, str | None, int]]:
        """(type, layer, class, count) for every group of documents."""
        rows = self._db.execute(
            "SELECT type, layer, class, COUNT(*) FROM docs GROUP BY type, layer, class ORDER BY 1, 2, 3"
        )
        return [(str(t), layer, cls, int(n)) for t, layer, cls, n in rows]

    def uuids(self, type: str) -> Iterator[str]:
        for (uuid,) in self._db.execute("SELECT uuid FROM docs WHERE type = ?", (type,)):
            yield str(uuid)

    def session(self, session_id: int) -> Session | None:
        sql = f"SELECT {_SESSION_COLUMNS} FROM sessions WHERE id = ?"
        row = self._db.execute(sql, (session_id,)).fetchone()
        return None if row is None else _session(row)

    def sessions(self, *, after_seq: int | None = None, upto_seq: int | None = None) -> list[Session]:
        sql = f"SELECT {_SESSION_COLUMNS} FROM sessions"
        params: list[Any] = []
        if after_seq is not None and upto_seq is not None:
            sql += " WHERE seq > ? AND seq <= ?"
            params = [after_seq, upto_seq]
        return [_session(r) for r in self._db.execute(sql + " ORDER BY id", params)]

    def pose(self, session_id: int, pose_id: int) -> tuple[float, list[list[float]]] | None:
        row = self._db.execute(
            "SELECT stamp_s, T_map_cam FROM poses WHERE session_id = ? AND pose_id = ?", (session_id, pose_id)
        ).fetchone()
        return None if row is None else (float(row[0]), pose_at(self._db, session_id, float(row[0]), row[1]))

    def pose_count(self, session_id: int) -> int:
        return int(self._scalar("SELECT COUNT(*) FROM poses WHERE session_id = ?", (session_id,)))

    def integrity_problems(self) -> list[str]:
        """SQLite's own integrity check plus the store's invariants; empty when all is well."""
        # SQLite may report several problems in one row, one per line, under a "*** in database" header
        damage = [line for r in self._db.execute("PRAGMA quick_check") if r[0] != "ok"
                  for line in str(r[0]).splitlines() if line.strip() and not line.startswith("***")]
        if damage:
            raise damaged_error(self.path, f"{len(damage)} problems, first: {damage[0]}")
        problems: list[str] = []
        orphans = int(
            self._scalar("SELECT COUNT(*) FROM docs_box b LEFT JOIN docs d ON d.id = b.id WHERE d.id IS NULL")
        )
        for table in ("obs_cells", "obs_cells_new"):
            orphans += int(self._scalar(
                f"SELECT COUNT(*) FROM {table} g LEFT JOIN docs d ON d.id = g.id WHERE d.id IS NULL"
            ))
        if orphans:
            problems.append(f"{orphans} spatial index rows without a document")
        for s in self.sessions():
            n = self.pose_count(s.id)
            if n != s.frames:
                problems.append(f"session {s.id}: {s.frames} frames recorded but {n} pose rows")
        return problems
