"""Bounded storage: observations that add nothing are summarised, debris is not kept.

A memory meant for months cannot append every sighting of a chair that stands where it
stood: at 15-30 Hz that is gigabytes a day whatever changed. ``compact`` keeps, per static
instance, the observations that say something:

- the first of each session;
- every observation that gives a class none kept gave (class evidence);
- every observation of a foreground object whose map box centre lies ``MOVE_M`` from every
  one kept (the object somewhere new);
- every observation of a plane (background) whose map box reaches ``COVER_M`` beyond each kept
  one's, earlier sessions' included: the kept pieces cover the fused outline, so
  ``hiper reanchor`` folds them again into the same plane under new poses;

and summarises the others into the instance's stretches in view (``data.view_spans``: first
and last stamp of each run of observations closer than ``STRETCH_GAP_S``; "time in view" reads
them, ``spans.span_stamps``);

and drops the others, counting them in the instance (``data.observations_summarised``: its
``observation_count`` stays what was seen). Observations of a session whose stamps fall inside
a stretch already covered by earlier sessions of a found-again object (the same log perceived
again) add nothing either. Observations no instance holds (debris that never became an
object, tracks merged away) are dropped. Movers keep every observation, as a stub: their
sightings are their trajectory. Only observations older than ``keep_raw_s`` before the newest
stamp are touched (``--keep-observations``); the geometry of those kept is rounded to 10 µm.
Pose rows keep their matrix only where the camera's motion is not a straight line between its
neighbours (``poserows.py``).

The graph is rebuilt from the documents afterwards (observation batches change); queries over
instances, events and trajectories answer the same. ``--keep-observations DURATION`` keeps every
raw observation of the last DURATION (a window a loop closure may still change in detail).
"""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from hiper_cli.graph.codec import dumps, loads
from hiper_cli.graph.poserows import thin_session
from hiper_cli.graph.spans import VIEW_SPANS

if TYPE_CHECKING:
    from hiper_cli.graph.kb import KnowledgeBase

__all__ = ["VIEW_SPANS", "CompactReport", "compact", "merge_spans"]

STRETCH_GAP_S = 1.0  # observations further apart start a new stretch (the query layer's view_gap_s)
MOVE_M = 0.25  # an observation this far from every one kept shows the object somewhere new
DECIMALS = 5  # kept observations' coordinates to 10 µm, directions to 1e-5
COVER_M = 0.2  # a plane's piece reaching this far beyond every kept one's box shows more of it
SUMMARISED = "observations_summarised"


@dataclass
class CompactReport:
    observations_before: int = 0
    debris_dropped: int = 0
    summarised: int = 0
    observations_after: int = 0
    pose_matrices_dropped: int = 0  # pose rows whose matrix their neighbours give (``poserows.py``)
    bytes_before: int = 0
    bytes_after: int = 0
    seconds: float = 0.0
    cpu_seconds: float = 0.0  # this process's CPU time (its threads' too): the cost, whatever the load

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


Bounds = tuple[float, float, float, float, float, float]  # map-frame min_x, max_x, min_y, max_y, min_z, max_z
# id, uuid, stamp, class, session, map x, y of the box centre, map box
Row = tuple[int, str, float, str | None, int | None, float, float, Bounds]


def _keep(rows: list[Row], covered: list[tuple[float, float]], keep_after_s: float,
          background: bool = False, boxes: list[Bounds] | None = None,
          ) -> tuple[set[int], list[tuple[float, float]]]:
    """Ids of the observations of one static instance (one session) kept, and the stretches in
    view the others are summarised into (module docstring). ``covered``: stretches earlier
    sessions' observations of the instance span; one inside them adds nothing. ``boxes``: the
    map boxes of a plane's observations kept so far, earlier sessions' included (extended)."""
    keep: set[int] = set()
    spans: list[tuple[float, float]] = []
    classes: set[str | None] = set()  # the classes the kept observations give
    places: list[tuple[float, float]] = []  # where the kept observations lie
    boxes = [] if boxes is None else boxes  # the kept observations' map boxes (a plane's coverage)
    for row in rows:
        oid, _, stamp, cls, _, x, y, bounds = row
        if spans and stamp - spans[-1][1] <= STRETCH_GAP_S:
            spans[-1] = (spans[-1][0], stamp)
        else:
            spans.append((stamp, stamp))
        if background:  # a plane's pieces lie all along it: new where they reach beyond the kept ones
            new_place = not any(_inside(bounds, box) for box in boxes)
        else:
            new_place = all((x - px) ** 2 + (y - py) ** 2 > MOVE_M ** 2 for px, py in places)
        if (stamp >= keep_after_s or cls not in classes
                or (new_place and not any(a <= stamp <= b for a, b in covered))):
            keep.add(oid)
            classes.add(cls)
            places.append((x, y))
            boxes.append(bounds)
    return keep, spans


def _inside(bounds: Bounds, box: Bounds) -> bool:
    """Whether ``bounds`` lies within ``box`` grown by ``COVER_M`` on every side."""
    return all(bounds[k] >= box[k] - COVER_M for k in (0, 2, 4)) and all(
        bounds[k] <= box[k] + COVER_M for k in (1, 3, 5))


def merge_spans(spans: Iterable[Sequence[float]]) -> list[list[float]]:
    """Stretches in view, sorted and joined where they overlap or lie ``STRETCH_GAP_S`` apart."""
    out: list[list[float]] = []
    for a, b in sorted((float(a), float(b)) for a, b in spans):
        if out and a - out[-1][1] <= STRETCH_GAP_S:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return out


def _covered(row: Row, stretches: dict[int | None, list[tuple[float, float]]]) -> bool:
    """Whether an earlier session saw the instance at this observation's stamp."""
    return any(a <= row[2] <= b for other, spans in stretches.items()
               if other != row[4] and (other or 0) < (row[4] or 0) for a, b in spans)


def _stretches(rows: Iterable[Row]) -> dict[int | None, list[tuple[float, float]]]:
    """Per session: the stretches in view its observations of one instance span."""
    out: dict[int | None, list[tuple[float, float]]] = defaultdict(list)
    by_session: dict[int | None, list[float]] = defaultdict(list)
    for row in rows:
        by_session[row[4]].append(row[2])
    for session, stamps in by_session.items():
        stamps.sort()
        start = prev = stamps[0]
        for s in stamps[1:]:
            if s - prev > STRETCH_GAP_S:
                out[session].append((start, prev))
                start = s
            prev = s
        out[session].append((start, prev))
    return out


def _instances(db: Any) -> dict[str, dict[str, Any]]:
    return {u: loads(body) for u, body in db.execute("SELECT uuid, body FROM docs WHERE type = 'instance'")}


def _observation_rows(db: Any) -> dict[str, list[Row]]:
    """Per instance, its observations (id, uuid, stamp, class, session, map x, y), oldest first."""
    cursor = db.execute(
        "SELECT d.id, d.uuid, d.stamp_s, d.class, d.session_id, l.instance_uuid, "
        "COALESCE(c.min_x + c.max_x, n.min_x + n.max_x, 0) / 2.0, "
        "COALESCE(c.min_y + c.max_y, n.min_y + n.max_y, 0) / 2.0, "
        "COALESCE(c.min_x, n.min_x, 0), COALESCE(c.max_x, n.max_x, 0), COALESCE(c.min_y, n.min_y, 0), "
        "COALESCE(c.max_y, n.max_y, 0), COALESCE(c.min_z, n.min_z, 0), COALESCE(c.max_z, n.max_z, 0) "
        "FROM all_links l JOIN docs d ON d.uuid = l.observation_uuid "
        "LEFT JOIN obs_cells c ON c.id = d.id LEFT JOIN obs_cells_new n ON n.id = d.id "
        "ORDER BY l.instance_uuid, d.stamp_s, d.id")
    out: dict[str, list[Row]] = defaultdict(list)
    last: tuple[str, int] | None = None
    for oid, uuid, stamp, cls, session, inst, x, y, *bounds in cursor:
        if (inst, oid) != last:  # obs_cells may hold a row per cell (next to each other: sorted)
            last = (inst, oid)
            box = tuple(float(v) for v in bounds)
            out[inst].append((int(oid), str(uuid), float(stamp or 0.0), cls, session, float(x), float(y),
                              box))  # type: ignore[arg-type]
    return out


def _drop(db: Any, ids: list[int]) -> None:
    """Delete observation documents by row id, with their index rows and links. When most of
    the observations go, the rows that stay are copied aside and the tables emptied whole
    (SQLite frees an unconditioned DELETE's pages at once, indexes included): deleting 10^6 rows
    one by one through three indexes was most of a compaction."""
    db.execute("CREATE TEMP TABLE IF NOT EXISTS drop_ids (id INTEGER PRIMARY KEY, uuid TEXT)")
    db.execute("DELETE FROM drop_ids")
    db.executemany("INSERT OR IGNORE INTO drop_ids (id) VALUES (?)", [(i,) for i in ids])
    db.execute("UPDATE drop_ids SET uuid = (SELECT uuid FROM docs WHERE docs.id = drop_ids.id)")
    db.execute("CREATE INDEX IF NOT EXISTS temp.drop_ids_uuid ON drop_ids (uuid)")
    db.execute("DELETE FROM docs_box WHERE id IN (SELECT id FROM drop_ids)")
    total = int(db.execute("SELECT COUNT(*) FROM docs").fetchone()[0])
    whole = len(ids) > total // 2
    for table, key, column in (("obs_cells", "id", "id"), ("obs_cells_new", "id", "id"),
                               ("links", "uuid", "observation_uuid"),
                               ("links_new", "uuid", "observation_uuid"), ("docs", "id", "id")):
        where = f"{column} IN (SELECT {key} FROM drop_ids)"
        if whole:
            db.execute(f"CREATE TEMP TABLE kept_rows AS SELECT * FROM {table} WHERE NOT {where}")
            db.execute(f"DELETE FROM {table}")
            db.execute(f"INSERT INTO {table} SELECT * FROM kept_rows")
            db.execute("DROP TABLE kept_rows")
        else:
            db.execute(f"DELETE FROM {table} WHERE {where}")


def _stub(db: Any, ids: list[int]) -> None:
    """Observations kept for their stamp and place only: their low-level data goes."""
    for k in range(0, len(ids), 900):
        chunk = ids[k:k + 900]
        rows = db.execute(f"SELECT id, body FROM docs WHERE id IN ({','.join('?' * len(chunk))})", chunk)
        updates = []
        for oid, body in rows.fetchall():
            doc = loads(body)
            if doc.get("data"):
                doc["data"] = {"summary": True}
                updates.append((dumps(doc), oid))
        db.executemany("UPDATE docs SET body = ? WHERE id = ?", updates)


def _rounded(value: Any) -> Any:
    """``value`` with every float rounded to ``DECIMALS`` places (lists and dicts through)."""
    if isinstance(value, float):
        return round(value, DECIMALS)
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    return value


def _round_kept(db: Any, before_s: float) -> None:
    """The geometry of the observations kept (box and data, not stamps) to ``DECIMALS``
    places: a kept plane's outline at full float precision is twice the bytes."""
    rows = db.execute("SELECT id, body FROM docs WHERE type = 'observation' AND stamp_s < ?", (before_s,))
    updates = []
    for oid, body in rows.fetchall():
        doc = loads(body)
        doc["box"], doc["data"] = _rounded(doc.get("box")), _rounded(doc.get("data"))
        text = dumps(doc)
        if len(text) < len(body):
            updates.append((text, oid))
    db.executemany("UPDATE docs SET body = ? WHERE id = ?", updates)


def compact(kb: KnowledgeBase, *, keep_raw_s: float = 0.0, vacuum: bool = True) -> CompactReport:
    """Summarise the observations of ``kb`` (module docstring); one transaction, then the
    graph is rebuilt and (``vacuum``) the file shrunk."""
    started, cpu_started = time.perf_counter(), time.process_time()
    report = CompactReport(bytes_before=_bytes(kb))
    docs = kb.docs
    db = docs._db
    report.observations_before = int(docs._scalar("SELECT COUNT(*) FROM docs WHERE type = 'observation'"))
    newest = float(docs._scalar("SELECT MAX(stamp_s) FROM docs WHERE type = 'observation'") or 0.0)
    keep_after_s = newest - keep_raw_s if keep_raw_s > 0 else float("inf")
    with docs.transaction() as seq:
        debris = [int(i) for (i,) in db.execute(  # NOT IN: one index over the links, not a scan each
            "SELECT d.id FROM docs d WHERE d.type = 'observation' AND d.stamp_s < ? AND d.uuid NOT IN "
            "(SELECT observation_uuid FROM all_links)", (keep_after_s,))]
        instances = _instances(db)
        drop: list[int] = []
        summarised: dict[str, int] = {}
        stub_ids: list[int] = []
        spans: dict[str, list[tuple[float, float]]] = {}
        for inst, rows in _observation_rows(db).items():
            stretches = _stretches(rows)
            if inst not in instances:
                continue
            if instances[inst].get("state", "static") != "static":  # a mover: stubs, but not twice
                again = {r[0] for r in rows if r[2] < keep_after_s and _covered(r, stretches)}
                stub_ids += [r[0] for r in rows if r[2] < keep_after_s and r[0] not in again]
                if again:
                    drop += sorted(again)
                    summarised[inst] = len(again)
                continue
            keep: set[int] = set()
            boxes: list[Bounds] = []  # a plane's coverage, over the sessions in turn
            for session in sorted({r[4] for r in rows}, key=lambda s: s or 0):
                mine = [r for r in rows if r[4] == session]
                covered = [s for other, spans_ in stretches.items() if other != session
                           and (other or 0) < (session or 0) for s in spans_]
                kept, session_spans = _keep(mine, covered, keep_after_s,
                                            instances[inst].get("layer") == "background", boxes)
                keep |= kept
                spans.setdefault(inst, []).extend(session_spans)
            gone = [r[0] for r in rows if r[0] not in keep]
            if gone:
                drop += gone
                summarised[inst] = len(gone)
        _stub(db, stub_ids)
        _drop(db, debris + drop)
        _round_kept(db, keep_after_s)
        for (session_id,) in db.execute("SELECT id FROM sessions").fetchall():
            report.pose_matrices_dropped += thin_session(db, int(session_id), keep_after_s)
        for inst, n in summarised.items():
            doc = instances[inst]
            data = doc.setdefault("data", {})
            data[SUMMARISED] = int(data.get(SUMMARISED, 0)) + n
            if inst in spans:
                data[VIEW_SPANS] = merge_spans([*data.get(VIEW_SPANS, []), *spans[inst]])
            db.execute("UPDATE docs SET body = ?, seq = ? WHERE uuid = ?", (dumps(doc), seq, inst))
        report.debris_dropped, report.summarised = len(debris), len(drop)
    docs._link_counts.clear()
    docs._pending_link_counts.clear()
    docs._staged = -1
    kb.sync_graph(rebuild=True)
    if vacuum:
        db.execute("VACUUM")
        db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        optimize = getattr(kb.graph, "optimize", None)  # a local graph store: shrink it too
        if optimize is not None:
            optimize()
            kb.detach_graph()  # reopening lets the store drop its obsolete write-ahead logs
            kb.attach_graph()
    report.observations_after = int(docs._scalar("SELECT COUNT(*) FROM docs WHERE type = 'observation'"))
    report.bytes_after = _bytes(kb)
    report.seconds = time.perf_counter() - started
    report.cpu_seconds = time.process_time() - cpu_started
    return report


def _bytes(kb: KnowledgeBase) -> int:
    """The documents' bytes on disk, write-ahead log included."""
    path = kb.docs.path
    wal = path.with_name(path.name + "-wal")
    return path.stat().st_size + (wal.stat().st_size if wal.exists() else 0)


def summarised_count(doc: dict[str, Any]) -> int:
    """Observations of an instance summarised away (added to its link count)."""
    return int((doc.get("data") or {}).get(SUMMARISED, 0))
