"""Bringing the scene graph up to date with the documents: the high-water-mark replay.

The documents are the source of truth. Every write transaction there takes the next change
sequence number; the graph records the last one it reflects (``hiper:syncedSeq`` in the
knowledge base's meta graph). ``sync_graph`` replays every document change after that mark:

- a document first written after the mark has no node in the graph yet: its triples are only
  added; any other changed document has its node replaced (its triples removed, except the
  provenance links, then added again); deleted documents (tombstones) lose their node;
- in the "batch" detail (the default) observations have no node: the nodes of the observation
  batches that new links fall into are replaced, with counts over all their observations;
- observations in the "summary" detail (the bulk of the data) and provenance links go in as
  N-Quads text through the store's bulk loader (~3x the rate of a transactional insert,
  measured), which is not atomic: the graph is marked dirty (``hiper:syncDirty``) before and
  clean with the new mark after, and a sync that finds it dirty replaces every node it replays,
  so an interrupted sync is repaired by the next one (``open_kb`` runs one);
- the mark moves last, in one transaction with the clean flag.
"""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from hiper_cli.graph.ontology import (
    OBSERVATION_BATCH_S,
    WAS_DERIVED_FROM,
    batch_node,
    batch_quads,
    doc_quads,
    link_nquads,
    node,
    observation_nquads,
    session_node,
    session_quads,
)

if TYPE_CHECKING:
    from hiper_cli.graph.documents import DocumentStore, Session
    from hiper_cli.graph.scenegraph import LocalGraph, SparqlGraph

__all__ = ["FLUSH_MIN_QUADS", "SyncReport", "sync_graph"]

FLUSH_MIN_QUADS = 50_000  # a sync flushes the graph store's write buffers once this many gathered


@dataclass
class SyncReport:
    documents: int = 0
    links: int = 0
    deleted: int = 0
    sessions: int = 0
    seconds: float = 0.0
    rebuilt: bool = False


def sync_graph(
    docs: DocumentStore,
    graph: LocalGraph | SparqlGraph,
    kb_id: str,
    graphs: Sequence[Any],
    *,
    detail: str = "batch",
    batch: int = 20000,
    rebuild: bool = False,
) -> SyncReport:
    """Replay the document changes after the graph's mark (all of them when ``rebuild``) into
    ``graph``; ``graphs`` are the knowledge base's named graphs (cleared on a rebuild).
    Idempotent and safe to interrupt."""
    start = time.perf_counter()
    report = SyncReport(rebuilt=rebuild)
    upto = docs.seq
    after, dirty = (0, False) if rebuild else graph.sync_state(kb_id)
    if after > upto:  # the graph is ahead of the documents (restored backup): rebuild
        after, report.rebuilt = 0, True
    if after == upto and not dirty and not report.rebuilt:
        return report
    if after == 0:
        graph.clear(graphs)  # the mark goes with the meta graph: an interrupted rebuild restarts
    else:
        graph.begin_sync(kb_id)
    fast = detail == "summary"
    batched = detail == "batch"
    chunks = docs.changed_docs(after, upto, batch, observation_bodies=not fast, observations=not batched)
    for chunk in chunks:
        refresh: list[str] = []
        quads = []
        lines: list[str] = []
        for doc, created in chunk:
            if after > 0 and (dirty or not created):
                refresh.append(node(doc["uuid"]).value)
            if fast and doc["type"] == "observation":
                lines.append(observation_nquads(kb_id, doc["uuid"], doc.get("layer") or "foreground"))
            else:
                quads.extend(doc_quads(kb_id, doc, detail))
        graph.write(kb_id, refresh, [], quads)
        graph.append_nquads("".join(lines))
        report.documents += len(chunk)
    if batched:
        report.links = _sync_batches(docs, graph, kb_id, after, upto)
    else:
        for links in docs.changed_links(after, upto, batch):
            graph.append_nquads("".join(link_nquads(kb_id, i, o, layer) for i, o, layer in links))
            report.links += len(links)
    dead = [node(u).value for u, _, _ in docs.tombstones(after, upto)]
    if dead and after > 0:
        if batched:  # an instance's batch nodes go with it
            dead += [b for iri in dead for b in graph.objects(iri, WAS_DERIVED_FROM.value)]
        graph.write(kb_id, [], dead, [])
    report.deleted = len(dead)
    sessions = docs.sessions(after_seq=after, upto_seq=upto)
    if sessions:
        graph.write(kb_id, [session_node(kb_id, s.id).value for s in sessions], [],
                    [q for s in sessions for q in session_quads(kb_id, _with_alignment(docs, s))])
    report.sessions = len(sessions)
    graph.set_synced_seq(kb_id, upto)
    # RocksDB keeps one write buffer per index in memory until flushed: flushing after large
    # catch-ups bounds the writer's memory (it halves it at 60 k observations). A flush costs
    # ~70 ms however little it writes, most of a sync after every live frame: small syncs
    # leave their quads buffered (in the write-ahead log, which readers see too) until
    # FLUSH_MIN_QUADS have gathered.
    if graph.buffered_quads() >= FLUSH_MIN_QUADS:
        graph.flush()
    report.seconds = time.perf_counter() - start
    return report


def _sync_batches(docs: DocumentStore, graph: LocalGraph | SparqlGraph, kb_id: str, after: int,
                  upto: int) -> int:
    """Replace the nodes of the observation batches that links added in (after, upto] fall
    into, with their counts and stamps over all their observations; the number of batches."""
    windows: dict[str, list[int]] = defaultdict(list)
    for instance_uuid, _session, window in docs.changed_batches(after, upto, OBSERVATION_BATCH_S):
        windows[instance_uuid].append(window)
    refresh: list[str] = []
    quads = []
    n = 0
    for instance_uuid, ws in windows.items():
        layer = docs.layer_of(instance_uuid) or "foreground"
        for session, window, count, first_s, last_s in docs.batches_of(
            instance_uuid, OBSERVATION_BATCH_S, min(ws), max(ws)
        ):
            if window not in ws:
                continue
            refresh.append(batch_node(instance_uuid, session, window).value)
            quads += batch_quads(kb_id, layer, instance_uuid, session, window, count, first_s, last_s)
            n += 1
        if len(quads) >= 20000:
            graph.write(kb_id, refresh, [], quads)
            refresh, quads = [], []
    graph.write(kb_id, refresh, [], quads)
    return n



def _with_alignment(docs: DocumentStore, session: Session) -> dict[str, Any]:
    """The session's fields plus the transform that aligned it (``sessions.py``), if any."""
    from hiper_cli.graph.sessions import alignment_of

    align = alignment_of(docs, session.id)
    return session.to_dict() | ({} if align is None else {"alignment": align.to_dict()})
