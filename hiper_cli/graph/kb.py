"""The knowledge base: documents (source of truth) plus the RDF scene graph derived from them.

Layout of a knowledge-base directory (``--kb PATH``, default ``./scene.hiper``)::

    PATH/documents.sqlite   the documents (SQLite, WAL), see ``documents.py``
    PATH/graph/             the scene graph (pyoxigraph on-disk store), unless the graph lives
                            on a SPARQL endpoint (``open_kb("http://...", docs_dir=PATH)``)

A perception frame is written with ``write_frame`` in one SQLite transaction. The graph is
brought up to date with ``sync_graph`` (the pipeline calls it every few seconds and at the end),
replaying every document change after the graph's high-water mark; ``open_kb`` does it too, so
a crash at any instant leaves a knowledge base that reopens with both stores in agreement.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import time
import uuid as _uuid
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli import DEFAULT_KB
from hiper_cli.errors import ConfigError, GraphDamagedError, KnowledgeBaseError
from hiper_cli.files import folder_bytes
from hiper_cli.graph.documents import DocumentStore, Session
from hiper_cli.graph.door import DOCUMENTS_FILE, KbDoor, is_knowledge_base
from hiper_cli.graph.location import kb_location
from hiper_cli.graph.migrate import GRAPH_REBUILD_KEY, MigrationReport, migrate_documents
from hiper_cli.graph.ontology import (
    OBSERVATION_BATCH_S,
    OBSERVATION_DETAIL,
    WAS_DERIVED_FROM,
    batch_quads,
    doc_quads,
    layer_graph,
    meta_graph,
    node,
)
from hiper_cli.graph.reads import KbReads
from hiper_cli.graph.scenegraph import DetachedGraph, LocalGraph, SparqlGraph, open_graph
from hiper_cli.graph.sync import SyncReport, sync_graph
from hiper_cli.model import LAYERS, Analysis, Box3D, Environment, FrameResult, Instance, Observation, World

__all__ = [
    "DEFAULT_KB",
    "CheckReport",
    "KbConfig",
    "KnowledgeBase",
    "SyncReport",
    "is_knowledge_base",
    "migrate_kb",
    "open_kb",
    "open_kb_for_reading",
]

GRAPH_DIR = "graph"


@dataclass(frozen=True)
class KbConfig:
    """``observation_detail``: how much of each observation the graph holds ("batch": nothing
    per observation, instances derive from observation batches; "summary": a node and the
    provenance link; "full": also class, stamp, pose id, frame, confidence and box); see
    ``ontology.OBSERVATION_DETAIL``.
    ``sync_batch``: documents per graph write when catching up. ``check_sample``: documents
    whose graph nodes ``check`` compares triple by triple (beyond comparing all counts)."""

    observation_detail: str = "batch"
    sync_batch: int = 20000
    check_sample: int = 500

    def __post_init__(self) -> None:
        if self.observation_detail not in OBSERVATION_DETAIL:
            raise KnowledgeBaseError(
                f"observation_detail {self.observation_detail!r}; expected one of {OBSERVATION_DETAIL}"
            )


@dataclass
class CheckReport:
    ok: bool
    problems: list[str] = field(default_factory=list)
    repaired: bool = False
    graph_counts: dict[str, int] = field(default_factory=dict)
    document_counts: dict[str, int] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "ok": self.ok,
            "problems": self.problems,
            "repaired": self.repaired,
            "graph_counts": self.graph_counts,
            "document_counts": self.document_counts,
        }


def _aabb(lo: Any, hi: Any) -> tuple[list[float], list[float]]:
    return [float(v) for v in lo], [float(v) for v in hi]


def _map_aabbs(boxes: Sequence[Box3D], T_map_box: Any) -> list[tuple[list[float], list[float]]]:
    """(min, max) of the axis-aligned map-frame box around each box, given in a frame mapped
    into the map by ``T_map_box`` (None = the boxes are in the map frame already); one
    vectorised pass per frame."""
    R = np.array([b.R for b in boxes])  # np.array over a list: half the cost of np.stack here
    c = np.array([b.center_m for b in boxes])
    half_extent = np.array([b.extent_m for b in boxes]) / 2.0
    if T_map_box is not None:
        R = T_map_box[:3, :3] @ R
        c = c @ T_map_box[:3, :3].T + T_map_box[:3, 3]
    half = (np.abs(R) * half_extent[:, None, :]).sum(axis=2)
    return list(zip((c - half).tolist(), (c + half).tolist(), strict=True))


def _value(term: Any) -> Any:
    """A comparable value of an RDF term: numbers by value (stores canonicalise "10.0" to "10")."""
    datatype = getattr(getattr(term, "datatype", None), "value", "")
    if datatype.endswith("#double"):
        return float(term.value)
    if datatype.endswith("#integer"):
        return int(term.value)
    return str(term)


class KnowledgeBase(KbReads, KbDoor):
    """Open with ``open_kb``. Not thread-safe; one writer process at a time. The typed reads
    of the query layer come from ``KbReads`` (``reads.py``), those of the other packages from
    ``KbDoor`` (``door.py``)."""

    def __init__(
        self,
        root: Path,
        graph: LocalGraph | SparqlGraph | DetachedGraph,
        docs: DocumentStore,
        config: KbConfig,
        read_only: bool = False,
    ) -> None:
        self.root = root
        self.graph = graph
        self.docs = docs
        self.config = config
        self.read_only = read_only
        self.graph_rebuilt = False  # set by open_kb when it replaced a damaged graph
        kb_id = docs.meta("kb_id")
        if kb_id is None and read_only:
            raise KnowledgeBaseError(f"{root}: the knowledge base was never written (no id); "
                                     "open it writable once, e.g. 'hiper kb check'")
        if kb_id is None:
            kb_id = str(_uuid.uuid4())
            docs.set_meta("kb_id", kb_id)
        self.kb_id = kb_id
        detail = docs.meta("observation_detail")
        if detail is None and not read_only:
            docs.set_meta("observation_detail", config.observation_detail)
        elif detail is not None and detail != config.observation_detail:
            self.config = KbConfig(observation_detail=detail, sync_batch=config.sync_batch,
                                   check_sample=config.check_sample)

    # -- lifecycle ----------------------------------------------------------------------------

    @property
    def location(self) -> str:
        """The knowledge base as the user names it: its directory, or the endpoint URL."""
        return self.graph.location if isinstance(self.graph, SparqlGraph) else str(self.root)

    def close(self, *, sync: bool = True) -> None:
        """Bring the graph up to date (``sync``) and close both stores (always, even when the
        sync fails)."""
        try:
            if sync and not self.read_only and not self.graph_detached:
                self.sync_graph()
        finally:
            try:
                self.graph.close()
            finally:
                self.docs.close()

    @property
    def graph_detached(self) -> bool:
        return isinstance(self.graph, DetachedGraph)

    def detach_graph(self) -> None:
        """Close the local graph store so that another process (a ``GraphFollower``) can own
        it; graph reads raise until ``attach_graph``."""
        if not self.graph_detached:
            location = self.graph.location
            self.graph.close()
            self.graph = DetachedGraph(location)

    def attach_graph(self) -> None:
        if self.graph_detached:
            self.graph = open_graph(self.graph.location)

    def __enter__(self) -> KnowledgeBase:
        return self

    def __exit__(self, kind: object, *exc: object) -> None:
        if kind is None:
            self.close()
            return
        with contextlib.suppress(KnowledgeBaseError):  # leaving on an error: let a second one not hide it
            self.close()

    def graphs(self) -> list[Any]:
        """The named graphs of this knowledge base: four layers and the meta graph."""
        return [layer_graph(self.kb_id, layer) for layer in LAYERS] + [meta_graph(self.kb_id)]

    # -- writes -------------------------------------------------------------------------------

    def environment(self, name: str) -> Environment:
        """The environment called ``name``, created on first use."""
        for doc in self.docs.find(type="environment"):
            if doc["name"] == name:
                return Environment.from_dict(doc)
        env = Environment(name=name)
        with self.docs.transaction():
            self.docs.put(env.to_dict(), env_uuid=env.uuid)
        return env

    def environments(self) -> list[Environment]:
        return [Environment.from_dict(d) for d in self.docs.find(type="environment")]

    def start_session(self, env: Environment, log_path: str, stages: Sequence[str]) -> Session:
        with self.docs.transaction():
            return self.docs.start_session(env.uuid, log_path, stages)

    def resumable_session(self, env: Environment, log_path: str) -> Session | None:
        """The newest unfinished session of ``log_path`` in ``env``, if any."""
        found = [s for s in self.docs.sessions() if s.env_uuid == env.uuid and s.log_path == log_path]
        return found[-1] if found and not found[-1].finished else None

    def sessions_of(self, env: Environment, log_path: str,
                    stages: Sequence[str] | None = None) -> list[Session]:
        """The sessions of ``log_path`` in ``env`` (with exactly these ``stages`` when given)."""
        return [s for s in self.docs.sessions() if s.env_uuid == env.uuid and s.log_path == log_path
                and (stages is None or sorted(s.stages) == sorted(stages))]

    def restart_session(self, session: Session) -> Session:
        """Drop what ``session`` wrote, in one transaction, and hand it back empty and unfinished
        (for perceiving its log again in its place); the graph is rebuilt from the documents."""
        from hiper_cli.graph.mapcloud import drop_map_cloud

        with self.docs.transaction():
            self.docs.clear_session(session.id)
            if not any(s.id != session.id for s in self.sessions(session.env_uuid)):
                # the place's cloud is this session's alone: perceived again, the log must
                # not be registered to its own earlier run
                drop_map_cloud(self.docs, session.env_uuid)
        self.sync_graph(rebuild=True)
        restarted = self.docs.session(session.id)
        assert restarted is not None
        return restarted

    def record_alignment(self, session: Session, alignment: Any) -> None:
        """The transform that carried ``session``'s log into the map frame (``sessions.py``)."""
        from hiper_cli.graph.sessions import record_alignment

        with self.docs.transaction():
            record_alignment(self.docs, session.id, alignment)

    def map_cloud(self, env: Environment) -> Any:
        """The place's background cloud (map frame, ``mapcloud.py``), or None before its first session."""
        from hiper_cli.graph.mapcloud import load_map_cloud

        return load_map_cloud(self.docs, env.uuid)

    def store_map_cloud(self, env: Environment, points_m: Any) -> int:
        from hiper_cli.graph.mapcloud import store_map_cloud

        with self.docs.transaction():
            return store_map_cloud(self.docs, env.uuid, points_m)

    def write_changes(self, session: Session, changes: Sequence[Any]) -> None:
        """Store a session's change events (``history.Change``) in one transaction."""
        if changes:
            with self.docs.transaction():
                self.docs.put_many([(c.to_dict(), None) for c in changes], session_id=session.id,
                                   env_uuid=session.env_uuid)

    def instance_sessions(self, uuid: str) -> list[int]:
        """The sessions whose observations an instance holds."""
        rows = self.docs._db.execute(
            "SELECT DISTINCT d.session_id FROM all_links l JOIN docs d ON d.uuid = l.observation_uuid "
            "WHERE l.instance_uuid = ? AND d.session_id IS NOT NULL", (uuid,))
        return sorted(int(s) for (s,) in rows)

    def changes(self, env: Environment | None = None) -> list[dict[str, Any]]:
        """Every change event (documents of type ``change``), in stamp order."""
        return self.docs.find(type="change", env_uuid=None if env is None else env.uuid)

    def end_session(self, session: Session) -> None:
        with self.docs.transaction():
            self.docs.end_session(session.id)

    def write_frame(
        self,
        session: Session,
        result: FrameResult,
        *,
        pose_id: int | None = None,
        stamp_s: float | None = None,
        T_map_cam: Any = None,
    ) -> int:
        """Write one frame's merged result atomically; ``pose_id`` None = the end-of-log flush.

        Observations get their map-frame box indexed through ``T_map_cam``. Returns the change
        sequence number of the write.
        """
        T = None if T_map_cam is None else np.asarray(T_map_cam, dtype=np.float64)
        with self.docs.transaction() as seq:
            self._put_result(result, session.id, session.env_uuid, T)
            if pose_id is not None:
                self.docs.record_frame(session.id, pose_id, float(stamp_s or 0.0),
                                       T if T is not None else np.eye(4))
        return seq

    def _put_result(self, result: FrameResult, session_id: int | None, env_uuid: str, T: Any) -> None:
        boxes: list[Any] = [None] * len(result.observations)
        if T is not None and result.observations:
            boxes = _map_aabbs([o.box for o in result.observations], T)
        obs_items = [(o.to_dict(), b) for o, b in zip(result.observations, boxes, strict=True)]
        self.docs.put_many(obs_items, session_id=session_id, env_uuid=env_uuid)
        inst_boxes = _map_aabbs([i.box for i in result.instances], None) if result.instances else []
        inst_items = [(i.to_dict(), b) for i, b in zip(result.instances, inst_boxes, strict=True)]
        self.docs.put_many(inst_items, session_id=session_id, env_uuid=env_uuid)
        for uuid in result.deleted_instances:
            self.docs.delete(uuid)

    def put_documents(self, docs: Iterable[dict[str, Any]], env_uuid: str | None = None) -> int:
        """Write documents (``to_dict`` forms) in one transaction, e.g. from an import."""
        n = 0
        with self.docs.transaction():
            for doc in docs:
                box_map = None
                if doc["type"] == "instance":
                    inst = Instance.from_dict(doc)
                    box_map = _aabb(*inst.box.aabb())
                self.docs.put(doc, env_uuid=doc.get("env_uuid", env_uuid), box_map=box_map)
                n += 1
        return n

    def put_analyses(self, analyses: Sequence[Analysis], env_uuid: str | None = None) -> None:
        self.put_documents((a.to_dict() for a in analyses), env_uuid=env_uuid)

    # -- graph synchronisation ----------------------------------------------------------------

    def sync_graph(self, *, rebuild: bool = False) -> SyncReport:
        """Bring the scene graph up to date with the documents (everything after its high-water
        mark, or everything when ``rebuild``). Idempotent; safe to interrupt."""
        if isinstance(self.graph, DetachedGraph):
            raise self.graph.busy()
        return sync_graph(self.docs, self.graph, self.kb_id, self.graphs(),
                          detail=self.config.observation_detail, batch=self.config.sync_batch,
                          rebuild=rebuild)

    def graph_counts(self) -> dict[str, int]:
        """Nodes per type in the graph ("layer/Type") plus provenance links and sessions."""
        out: dict[str, int] = {}
        for layer in LAYERS:
            g = layer_graph(self.kb_id, layer)
            rows = self.graph.query(
                f"SELECT ?t (COUNT(?s) AS ?n) WHERE {{ GRAPH {g} {{ ?s a ?t }} }} GROUP BY ?t"
            )
            for r in rows:
                name = r["t"].value.rsplit("#", 1)[-1]
                out[f"{layer}/{name}"] = int(r["n"].value)
            links = self.graph.query(
                f"SELECT (COUNT(*) AS ?n) WHERE {{ GRAPH {g} {{ ?i prov:wasDerivedFrom ?o }} }}"
            )
            n = int(links[0]["n"].value) if links else 0
            if n:
                out[f"{layer}/wasDerivedFrom"] = n
        return out

    def document_counts(self) -> dict[str, int]:
        """The same keys as ``graph_counts``, computed from the documents."""
        out: dict[str, int] = {}
        type_layer = {"environment": "environment", "analysis": "map"}
        for kind, layer, _cls, n in self.docs.counts():
            key = f"{layer or type_layer.get(kind, 'map')}/{kind.capitalize()}"
            out[key] = out.get(key, 0) + n
        sessions = len(self.docs.sessions())
        if sessions:
            out["environment/Session"] = sessions
        if self.config.observation_detail == "batch":  # observations are summarised in batches
            for layer in LAYERS:
                out.pop(f"{layer}/Observation", None)
            for layer, n in self.docs.batch_count(OBSERVATION_BATCH_S).items():
                out[f"{layer}/ObservationBatch"] = n
                out[f"{layer}/wasDerivedFrom"] = n
        else:
            for layer, n in self.docs.link_counts_by_layer().items():
                out[f"{layer}/wasDerivedFrom"] = n
        return out

    def _compare_nodes(self, n: int) -> list[str]:
        """Compare the graph nodes of up to ``n`` documents, spread over the store, triple by
        triple with what the documents say they should be."""
        docs = self.docs.sample(n)
        if not docs:
            return []
        detail = self.config.observation_detail
        expected = {(str(q.subject), str(q.predicate), _value(q.object), str(q.graph_name))
                    for d in docs for q in doc_quads(self.kb_id, d, detail)}
        subjects = " ".join(str(node(d["uuid"])) for d in docs)
        rows = self.graph.query(
            f"SELECT ?s ?p ?o ?g WHERE {{ VALUES ?s {{ {subjects} }} GRAPH ?g {{ ?s ?p ?o }} "
            "FILTER(?p != prov:wasDerivedFrom) }"
        )
        actual = {(str(r["s"]), str(r["p"]), _value(r["o"]), str(r["g"])) for r in rows}
        if detail == "batch":  # the batch nodes of the sampled instances, links included
            instances = [d for d in docs if d["type"] == "instance"]
            for d in instances:
                layer = d.get("layer") or "foreground"
                for session, window, count, first_s, last_s in self.docs.batches_of(
                    d["uuid"], OBSERVATION_BATCH_S, -(1 << 62), 1 << 62
                ):
                    expected |= {(str(q.subject), str(q.predicate), _value(q.object), str(q.graph_name))
                                 for q in batch_quads(self.kb_id, layer, d["uuid"], session, window, count,
                                                      first_s, last_s)}
            if instances:
                subjects = " ".join(str(node(d["uuid"])) for d in instances)
                rows = self.graph.query(
                    f"SELECT ?i ?b ?p ?o ?g WHERE {{ VALUES ?i {{ {subjects} }} GRAPH ?g {{ "
                    "?i prov:wasDerivedFrom ?b OPTIONAL { ?b ?p ?o } } }"
                )
                for r in rows:
                    actual.add((str(r["i"]), f"<{WAS_DERIVED_FROM.value}>", _value(r["b"]), str(r["g"])))
                    if "p" in r:
                        actual.add((str(r["b"]), str(r["p"]), _value(r["o"]), str(r["g"])))
        if actual == expected:
            return []
        return [f"graph nodes differ from their documents: {len(expected - actual)} triples missing, "
                f"{len(actual - expected)} unexpected, in a sample of {len(docs)} documents"]

    def check(self, *, repair: bool = True) -> CheckReport:
        """Verify the documents and that the graph agrees with them; rebuild the graph from the
        documents when it does not, or when it cannot be read at all (``repair``). Damaged
        documents raise: they are the source of truth and cannot be rebuilt from anything."""
        problems = self.docs.integrity_problems()
        if self.graph_rebuilt:
            problems.append("the scene graph could not be opened; it was rebuilt from the documents")
        doc_counts = self.document_counts()
        graph_counts: dict[str, int] = {}
        try:
            synced = self.graph.synced_seq(self.kb_id)
            if synced != self.docs.seq:
                problems.append(f"graph high-water mark {synced} != document sequence {self.docs.seq}")
            graph_counts = self.graph_counts()
            if graph_counts != doc_counts:
                keys = sorted(set(graph_counts) | set(doc_counts))
                diff = [f"{k}: graph {graph_counts.get(k, 0)} vs documents {doc_counts.get(k, 0)}"
                        for k in keys if graph_counts.get(k, 0) != doc_counts.get(k, 0)]
                problems.append("graph and documents disagree: " + "; ".join(diff))
            problems += self._compare_nodes(self.config.check_sample)
        except GraphDamagedError as err:
            problems.append(str(err))
            if repair and not self.read_only and isinstance(self.graph, LocalGraph):
                path = Path(self.graph.location)
                with contextlib.suppress(KnowledgeBaseError):
                    self.graph.close()
                self.graph = _fresh_graph(path)
        report = CheckReport(ok=not problems, problems=problems, graph_counts=graph_counts,
                             document_counts=doc_counts, repaired=self.graph_rebuilt)
        if problems and repair and not self.read_only:
            self.sync_graph(rebuild=True)
            report.repaired = True
            report.graph_counts = self.graph_counts()
            report.ok = report.graph_counts == doc_counts and not self.docs.integrity_problems()
        return report

    # -- reads --------------------------------------------------------------------------------

    def load_world(self, env: Environment) -> World:
        """The live instances and the analyses of ``env``, for resuming perception."""
        world = World()
        for doc in self.docs.find(type="instance", env_uuid=env.uuid):
            inst = Instance.from_dict(doc)
            world.layer(inst.layer)[inst.uuid] = inst
        world.analyses = [Analysis.from_dict(d) for d in self.docs.find(type="analysis")]
        return world

    def session_records(self) -> list[dict[str, Any]]:
        """Every session with its place, log stamps and alignment (``sessions.session_record``)."""
        from hiper_cli.graph.sessions import session_record

        names = {e.uuid: e.name for e in self.environments()}
        return [session_record(self.docs, s, names) for s in self.docs.sessions()]

    def observation(self, uuid: str) -> Observation | None:
        doc = self.docs.get(uuid)
        return Observation.from_dict(doc) if doc and doc["type"] == "observation" else None

    def instance(self, uuid: str) -> Instance | None:
        doc = self.docs.get(uuid)
        return Instance.from_dict(doc) if doc and doc["type"] == "instance" else None

    def instances(self, *, layer: str | None = None, class_name: str | None = None) -> list[Instance]:
        return [Instance.from_dict(d) for d in self.docs.find(type="instance", layer=layer,
                                                              class_name=class_name)]

    def query(self, sparql: str) -> list[dict[str, Any]]:
        """SPARQL SELECT over the scene graph (prefixes hiper:, prov:, sosa: predeclared)."""
        rows: list[dict[str, Any]] = self.graph.query(sparql)
        return rows

    def info(self) -> dict[str, Any]:
        """Counts per type, layer and class, sessions, environments and size on disk."""
        counts = [
            {"type": t, "layer": layer, "class": cls, "count": n} for t, layer, cls, n in self.docs.counts()
        ]
        size = folder_bytes(self.root)
        return {
            "kb": self.location,
            "documents_path": str(self.docs.path),
            "kb_id": self.kb_id,
            "observation_detail": self.config.observation_detail,
            "environments": [e.to_dict() | {"data": None} for e in self.environments()],
            "sessions": [s.to_dict() for s in self.docs.sessions()],
            "counts": counts,
            "totals": {
                kind: sum(c["count"] for c in counts if c["type"] == kind)
                for kind in ("observation", "instance", "analysis", "environment")
            },
            "change_seq": self.docs.seq,
            "graph_synced_seq": self.graph.synced_seq(self.kb_id),
            "size_bytes": size,
        }


def open_kb_for_reading(
    location: str | Path = DEFAULT_KB, *, docs_dir: str | Path | None = None
) -> KnowledgeBase:
    """Open an existing knowledge base to read it: read-only where it cannot be written
    (read-only media, a ``perceive`` run writing it: the graph may then lag the documents by
    the writer's sync interval), else as ``open_kb`` does, which catches the graph up."""
    remote, _ = kb_location(location)
    root = Path(docs_dir) if docs_dir is not None else Path(str(location))
    if not remote and _graph_locked(root):
        return _open_beside_writer(location, docs_dir)
    if not remote and not _writable(root):
        return open_kb(location, docs_dir=docs_dir, read_only=True)
    try:
        return open_kb(location, docs_dir=docs_dir, create=False)
    except GraphDamagedError:
        raise
    except KnowledgeBaseError as err:
        if not any(why in str(err) for why in ("another hiper process", "disk is full", "read-only")):
            raise
        return _open_beside_writer(location, docs_dir)


def _open_beside_writer(location: str | Path, docs_dir: str | Path | None, wait_s: float = 5.0
                        ) -> KnowledgeBase:
    """Read-only, while another process writes; one that is creating the knowledge base right
    now has not written its id yet, so that is waited for (up to ``wait_s``)."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            return open_kb(location, docs_dir=docs_dir, read_only=True)
        except KnowledgeBaseError as err:
            if "never written" not in str(err) or time.monotonic() > deadline:
                raise
            time.sleep(0.05)


def _graph_locked(root: Path) -> bool:
    """Whether another process holds the graph store (a perceive run writing it now): then a
    reader opens it read-only at once instead of waiting for the lock."""
    import fcntl

    lock = root / GRAPH_DIR / "LOCK"
    try:
        with open(lock, "r+b") as handle:
            try:
                fcntl.lockf(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                return True
            fcntl.lockf(handle, fcntl.LOCK_UN)
    except OSError:  # no store yet, or not ours to open: the usual path decides
        return False
    return False


def _writable(root: Path) -> bool:
    docs = root / DOCUMENTS_FILE
    return not docs.exists() or (os.access(root, os.W_OK) and os.access(docs, os.W_OK))


def _no_kb(root: Path) -> KnowledgeBaseError:
    return KnowledgeBaseError(
        f"{root}: no knowledge base there ({DOCUMENTS_FILE} missing); check the --kb path, or "
        f"create one with 'hiper perceive LOG --kb {root}'"
    )


def open_kb(
    location: str | Path = DEFAULT_KB,
    *,
    docs_dir: str | Path | None = None,
    read_only: bool = False,
    config: KbConfig | None = None,
    sync: bool = True,
    create: bool = True,
    rebuild_damaged_graph: bool = False,
) -> KnowledgeBase:
    """Open (creating on first use, unless ``create`` is False) the knowledge base at ``location``.

    ``location`` is a directory, or the URL of a SPARQL 1.1 endpoint holding the scene graph; in
    that case the documents live in ``docs_dir`` (default ``./scene.hiper``). On open the graph is
    brought up to date with the documents (``sync``), which repairs an interrupted write. A local
    graph that cannot be opened raises ``GraphDamagedError`` unless ``rebuild_damaged_graph``:
    then it is replaced by one rebuilt from the documents.
    """
    remote, text = kb_location(location)
    if docs_dir is not None and not remote:
        raise ConfigError(f"--kb-docs {docs_dir}: only for a --kb that is a SPARQL endpoint (http://...); "
                          f"the documents of --kb {text} live inside that folder")
    root = Path(docs_dir) if docs_dir is not None else (Path(DEFAULT_KB) if remote else Path(text))
    if root.exists() and not root.is_dir():
        raise KnowledgeBaseError(
            f"{root}: is a file, not a knowledge-base directory; pass a directory to --kb"
        )
    docs_path = root / DOCUMENTS_FILE
    if (read_only or not create) and not docs_path.exists():
        raise _no_kb(root)
    if not read_only:
        try:
            root.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise KnowledgeBaseError(f"{root}: cannot create the knowledge-base folder ({err.strerror}); "
                                     "pass a writable --kb path") from err
    docs = DocumentStore(docs_path, read_only=read_only)
    rebuilt = False
    try:
        try:
            graph = open_graph(text if remote else root / GRAPH_DIR, read_only=read_only)
        except GraphDamagedError:
            if remote or read_only or not rebuild_damaged_graph:
                raise
            graph = _fresh_graph(root / GRAPH_DIR)
            rebuilt = True
    except BaseException:
        docs.close()
        raise
    kb = KnowledgeBase(root, graph, docs, config or KbConfig(), read_only=read_only)
    if rebuilt or (not read_only and docs.meta(GRAPH_REBUILD_KEY) is not None):
        kb.sync_graph(rebuild=True)  # a damaged graph, or one a migration changed (migrate.py)
        docs.connection.execute("DELETE FROM meta WHERE key = ?", (GRAPH_REBUILD_KEY,))
        kb.graph_rebuilt = rebuilt
    elif sync and not read_only:
        try:
            kb.sync_graph()
        except BaseException:
            kb.close(sync=False)
            raise
    return kb


def migrate_kb(location: str | Path = DEFAULT_KB, *, docs_dir: str | Path | None = None) -> MigrationReport:
    """Carry the knowledge base at ``location`` forward to this hiper's schema version, after a
    backup copy beside it (``migrate.py``), and rebuild its graph when the migration asks for it."""
    report = migrate_documents(location, docs_dir=docs_dir)
    if report.migrated:
        with open_kb(location, docs_dir=docs_dir, create=False):
            pass  # the open rebuilds the graph the migration marked
    return report


def _fresh_graph(path: Path) -> LocalGraph:
    """An empty graph store in place of the damaged one at ``path`` (derived data: the caller
    rebuilds it from the documents)."""
    if path.is_dir():
        shutil.rmtree(path)
    elif path.exists():
        path.unlink()
    return LocalGraph(path)
