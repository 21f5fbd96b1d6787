"""Where the RDF scene graph lives: an on-disk pyoxigraph store, or a SPARQL 1.1 endpoint.

Both backends offer the same small interface (``GraphBackend``) so the knowledge base and its
tests do not care which one they talk to. Writes are idempotent replacements of whole nodes:
replaying a batch after a crash gives the same graph, which is what lets the knowledge base
bring the graph up to date from its documents with a high-water mark.
"""

from __future__ import annotations

import contextlib
import functools
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, Protocol, TypeVar

import pyoxigraph as ox

from hiper_cli.errors import GraphDamagedError, KnowledgeBaseError, QueryError
from hiper_cli.graph.ontology import HIPER, PROV, meta_graph
from hiper_cli.graph.sparql_safety import DEFAULT_TIMEOUT_S, readonly_form, run_with_timeout

__all__ = ["DetachedGraph", "GraphBackend", "LocalGraph", "SparqlGraph", "open_graph"]

_SYNCED = ox.NamedNode(HIPER + "syncedSeq")
_DIRTY = ox.NamedNode(HIPER + "syncDirty")
_TRUE = ox.Literal("true", datatype=ox.NamedNode("http://www.w3.org/2001/XMLSchema#boolean"))
# Below this many bytes of N-Quads a transactional load is as fast as the bulk loader (which
# writes new files on every call) and keeps the write atomic.
BULK_MIN_BYTES = 1 << 20
_XSD = "http://www.w3.org/2001/XMLSchema#"
_INTEGER = ox.NamedNode(_XSD + "integer")
_PREFIXES = f"PREFIX hiper: <{HIPER}>\nPREFIX prov: <{PROV}>\nPREFIX sosa: <http://www.w3.org/ns/sosa/>\n"


def _kb_node(kb_id: str) -> ox.NamedNode:
    return ox.NamedNode(f"urn:hiper:kb:{kb_id}")


class GraphBackend(Protocol):
    """The scene graph of one knowledge base (``kb_id``) in some quad store."""

    location: str

    def write(
        self, kb_id: str, refresh: Sequence[str], drop: Sequence[str], quads: Sequence[ox.Quad]
    ) -> None:
        """Remove the triples of the subjects in ``refresh`` (except their provenance links) and
        all triples of the subjects in ``drop``, then add ``quads``. Subjects are IRIs."""
        ...

    def append_nquads(self, text: str) -> None:
        """Add the quads of an N-Quads document; large ones through a bulk loader that is not
        atomic (see ``begin_sync``)."""
        ...

    def objects(self, subject: str, predicate: str) -> list[str]:
        """The IRIs that ``subject predicate ?o`` points to, in any graph."""
        ...

    def synced_seq(self, kb_id: str) -> int:
        """The high-water mark: the last document change the graph reflects (0 if none)."""
        ...

    def sync_state(self, kb_id: str) -> tuple[int, bool]:
        """The high-water mark and whether a sync after it was interrupted (dirty)."""
        ...

    def begin_sync(self, kb_id: str) -> None:
        """Mark the graph dirty until ``set_synced_seq``: non-atomic writes follow."""
        ...

    def set_synced_seq(self, kb_id: str, seq: int) -> None:
        """Move the mark to ``seq`` and mark the graph clean, in one atomic write."""
        ...

    def clear(self, graphs: Sequence[ox.NamedNode]) -> None: ...

    def query(self, sparql: str, bindings: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
        """SELECT results as rows of {variable: pyoxigraph term}. The hiper, prov and sosa
        prefixes are predeclared. ``bindings`` give variables a value before evaluation (a
        template's variables, never text pasted into it); bound variables must be projected."""
        ...

    def run_readonly(self, sparql: str, media_type: str,
                     timeout_s: float | None = DEFAULT_TIMEOUT_S) -> tuple[bytes, str]:
        """A SELECT, ASK, CONSTRUCT or DESCRIBE query over the union of all graphs, serialised
        as ``media_type`` (a SPARQL results or RDF media type); (body, media type). Updates
        and ``SERVICE`` are refused, and a query running past ``timeout_s``, with ``QueryError``."""
        ...

    def quads(self, graphs: Sequence[ox.NamedNode]) -> list[ox.Quad]: ...

    def flush(self) -> None:
        """Persist buffered writes (frees the local store's write buffers)."""
        ...

    def buffered_quads(self) -> int:
        """About how many quads were written and not yet flushed (0 where nothing is buffered)."""
        ...

    def close(self) -> None: ...


def _solutions(result: Any) -> list[dict[str, Any]]:
    names = [v.value for v in result.variables]
    return [{n: sol[n] for n in names if sol[n] is not None} for sol in result]


def _is_lock_error(err: BaseException) -> bool:
    """Whether RocksDB refused the store because another process holds its LOCK file."""
    text = str(err).lower()
    return "lock file" in text or "/lock:" in text or "temporarily unavailable" in text


def _open_store(path: Path, wait_s: float = 3.0) -> ox.Store:
    """The on-disk store, waiting up to ``wait_s`` for a lock that a dying process (a graph
    follower killed with its writer) still holds."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            return ox.Store(str(path))
        except OSError as err:
            if not _is_lock_error(err) or time.monotonic() > deadline:
                raise
            time.sleep(0.05)


READ_ONLY_REFRESH_S = 1.0


def _open_read_only(path: Path, tries: int = 20) -> ox.Store:
    """The store read-only; while a writer compacts it, a file listed at open may vanish before
    it is read (RocksDB: "No such file"), and while a writer creates it its column families
    may not all be there yet, so the open is tried again."""
    for attempt in range(tries):
        try:
            return ox.Store.read_only(str(path))
        except (OSError, RuntimeError) as err:
            text = str(err).lower()
            transient = "no such file" in text or "column family not found" in text
            if not transient or attempt == tries - 1:
                raise
            time.sleep(0.05)
    raise AssertionError("unreachable")


F = TypeVar("F", bound=Callable[..., Any])


def store_error(path: str, err: BaseException) -> KnowledgeBaseError:
    """The one-line error for a failure of the on-disk graph store at ``path``."""
    text = " ".join(str(err).split())
    if "no space" in text.lower() or "file too large" in text.lower():
        return KnowledgeBaseError(f"{path}: the disk is full ({text}); free some space; the documents "
                                  "are kept and 'hiper kb check' brings the scene graph up to date")
    if "read-only" in text.lower() or "permission denied" in text.lower():
        return KnowledgeBaseError(f"{path}: the scene graph cannot be written ({text}); the knowledge "
                                  "base is read-only: copy it to a writable folder to change it")
    return GraphDamagedError(f"{path}: the scene graph is damaged ({text[:200]}); it is derived from the "
                             f"documents: run 'hiper kb check --kb {Path(path).parent}' to rebuild it")


def _guarded(method: F) -> F:
    """Store errors of a ``LocalGraph`` method as one-line ``KnowledgeBaseError``s."""
    @functools.wraps(method)
    def wrapper(self: LocalGraph, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except (OSError, RuntimeError) as err:
            raise store_error(self.location, err) from err

    return wrapper  # type: ignore[return-value]


def _drop_old_logs(path: Path) -> None:
    """RocksDB keeps the info log of every earlier open (``LOG.old.*``, ~140 KB each); they are
    diagnostics only, so each open removes them and the folder does not grow by reading."""
    for old in path.glob("LOG.old.*"):
        old.unlink(missing_ok=True)


class LocalGraph:
    """The scene graph in an on-disk pyoxigraph (RocksDB) store, one process at a time."""

    def __init__(self, path: Path, *, read_only: bool = False) -> None:
        self.location = str(path)
        self.read_only = read_only
        self._opened_s: float = 0.0
        self._opened: ox.Store
        try:
            self._store = _open_read_only(path) if read_only else _open_store(path)
        except (OSError, RuntimeError) as err:
            if _is_lock_error(err):
                raise KnowledgeBaseError(
                    f"{path}: cannot open the scene graph ({err}); is another hiper process writing "
                    "this knowledge base? wait for it or use another --kb"
                ) from err
            raise store_error(str(path), err) from err
        if not read_only:
            _drop_old_logs(path)
        self._link = ox.NamedNode(PROV + "wasDerivedFrom")
        self._buffered = 0  # quads written (added or removed) since the last flush

    @property
    def _store(self) -> ox.Store:
        """The store; read-only, a snapshot at its opening, so it is opened again when older
        than ``READ_ONLY_REFRESH_S`` (a long-lived reader, ``hiper serve`` or ``hiper mcp``,
        follows a ``perceive`` run writing the knowledge base)."""
        if self.read_only and time.monotonic() - self._opened_s > READ_ONLY_REFRESH_S:
            # on failure the snapshot in hand is kept; the next read tries again
            with contextlib.suppress(OSError, RuntimeError):
                self._opened = _open_read_only(Path(self.location))
            self._opened_s = time.monotonic()
        return self._opened

    @_store.setter
    def _store(self, store: ox.Store) -> None:
        self._opened, self._opened_s = store, time.monotonic()

    @_store.deleter
    def _store(self) -> None:
        del self._opened

    @_guarded
    def write(
        self, kb_id: str, refresh: Sequence[str], drop: Sequence[str], quads: Sequence[ox.Quad]
    ) -> None:
        store = self._store
        old: list[ox.Quad] = []
        for iri in refresh:
            old.extend(q for q in store.quads_for_pattern(ox.NamedNode(iri), None, None)
                       if q.predicate != self._link)
        for iri in drop:
            old.extend(store.quads_for_pattern(ox.NamedNode(iri), None, None))
        for q in old:
            store.remove(q)
        store.extend(quads)
        self._buffered += len(old) + len(quads)

    @_guarded
    def append_nquads(self, text: str) -> None:
        if not text:
            return
        data = text.encode("utf-8")
        try:
            if len(data) >= BULK_MIN_BYTES:
                self._store.flush()  # the dirty mark (begin_sync) on disk before any bulk-loaded file
                self._buffered = 0
                self._store.bulk_load(data, format=ox.RdfFormat.N_QUADS)
            else:
                self._store.load(data, format=ox.RdfFormat.N_QUADS)
                self._buffered += text.count("\n")
        except SyntaxError as err:
            raise KnowledgeBaseError(f"{self.location}: a generated graph node does not parse ({err}); "
                                     "a document uuid is not a plain uuid? run 'hiper kb check'") from err

    @_guarded
    def objects(self, subject: str, predicate: str) -> list[str]:
        found = self._store.quads_for_pattern(ox.NamedNode(subject), ox.NamedNode(predicate), None)
        return [q.object.value for q in found if isinstance(q.object, ox.NamedNode)]

    def synced_seq(self, kb_id: str) -> int:
        return self.sync_state(kb_id)[0]

    @_guarded
    def sync_state(self, kb_id: str) -> tuple[int, bool]:
        s, g = _kb_node(kb_id), meta_graph(kb_id)
        seq = 0
        for q in self._store.quads_for_pattern(s, _SYNCED, None, g):
            seq = int(str(getattr(q.object, "value", 0)))
        dirty = any(True for _ in self._store.quads_for_pattern(s, _DIRTY, None, g))
        return seq, dirty

    @_guarded
    def begin_sync(self, kb_id: str) -> None:
        # not flushed here: a flush costs ~70 ms whatever its size, and only a bulk
        # load needs the mark on disk first (``append_nquads`` flushes before one)
        self._store.add(ox.Quad(_kb_node(kb_id), _DIRTY, _TRUE, meta_graph(kb_id)))

    @_guarded
    def set_synced_seq(self, kb_id: str, seq: int) -> None:
        s, g = _kb_node(kb_id), meta_graph(kb_id)
        old = list(self._store.quads_for_pattern(s, _SYNCED, None, g))
        old += self._store.quads_for_pattern(s, _DIRTY, None, g)
        self._store.update(
            "".join(f"DELETE DATA {{ GRAPH {q.graph_name} {{ {q.subject} {q.predicate} {q.object} }} }} ;\n"
                    for q in old)
            + f"INSERT DATA {{ GRAPH {g} {{ {s} {_SYNCED} {ox.Literal(str(seq), datatype=_INTEGER)} }} }}"
        )

    @_guarded
    def clear(self, graphs: Sequence[ox.NamedNode]) -> None:
        for g in graphs:
            self._store.clear_graph(g)

    @_guarded
    def query(self, sparql: str, bindings: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
        try:
            if bindings:
                subs = {ox.Variable(k): term(v) for k, v in bindings.items()}
                return _solutions(self._store.query(_PREFIXES + sparql, substitutions=subs))
            return _solutions(self._store.query(_PREFIXES + sparql))
        except SyntaxError as err:
            raise KnowledgeBaseError(f"SPARQL query does not parse: {err}") from err

    @_guarded
    def run_readonly(self, sparql: str, media_type: str,
                     timeout_s: float | None = DEFAULT_TIMEOUT_S) -> tuple[bytes, str]:
        readonly_form(sparql, _PREFIXES)

        def evaluate() -> tuple[bytes, str]:  # lazy results: serialising runs the query
            try:
                result = self._store.query(_PREFIXES + sparql, use_default_graph_as_union=True)
                return serialize_results(result, media_type)
            except SyntaxError as err:
                raise QueryError(f"SPARQL query does not parse: {err}") from err

        return run_with_timeout(evaluate, timeout_s)

    @_guarded
    def quads(self, graphs: Sequence[ox.NamedNode]) -> list[ox.Quad]:
        out: list[ox.Quad] = []
        for g in graphs:
            out.extend(self._store.quads_for_pattern(None, None, None, g))
        return out

    @_guarded
    def flush(self) -> None:
        if not self.read_only:
            self._store.flush()
            self._buffered = 0

    def buffered_quads(self) -> int:
        return self._buffered

    def optimize(self) -> None:
        """Compact the on-disk store (after many deletes, e.g. ``kb compact``)."""
        if not self.read_only:
            self._store.optimize()
            self._store.flush()

    def close(self) -> None:
        self.flush()
        del self._store


class SparqlGraph:
    """The scene graph on a SPARQL 1.1 endpoint (query at ``BASE/query``, update at
    ``BASE/update``, as the ``oxigraph serve`` server lays them out). One update request per
    write, so each write is atomic on the server."""

    def __init__(self, base_url: str, timeout_s: float = 60.0) -> None:
        base = base_url.rstrip("/")
        for suffix in ("/query", "/sparql"):
            if base.endswith(suffix):
                base = base[: -len(suffix)]
        self.location = base
        self._timeout_s = timeout_s
        try:
            self._post("query", "ASK { }", "application/sparql-query")
        except KnowledgeBaseError as err:
            raise KnowledgeBaseError(
                f"{base}: no SPARQL endpoint answers there ({err}); start one with "
                "'oxigraph serve --location DIR --bind 127.0.0.1:7878' or fix --kb"
            ) from err

    def _post(self, path: str, body: str, content_type: str, accept: str | None = None) -> bytes:
        request = urllib.request.Request(
            f"{self.location}/{path}", data=body.encode("utf-8"), method="POST",
            headers={"Content-Type": content_type, **({"Accept": accept} if accept else {})},
        )
        try:
            with urllib.request.urlopen(request, timeout=self._timeout_s) as response:
                return bytes(response.read())
        except urllib.error.HTTPError as err:
            detail = err.read().decode("utf-8", "replace")[:300]
            raise KnowledgeBaseError(f"{self.location}/{path}: HTTP {err.code}: {detail}") from err
        except (urllib.error.URLError, OSError) as err:
            raise KnowledgeBaseError(f"{self.location}/{path}: {err}") from err

    def _update(self, text: str) -> None:
        self._post("update", _PREFIXES + text, "application/sparql-update")

    @staticmethod
    def _values(iris: Iterable[str]) -> str:
        return " ".join(f"<{i}>" for i in iris)

    def write(
        self, kb_id: str, refresh: Sequence[str], drop: Sequence[str], quads: Sequence[ox.Quad]
    ) -> None:
        ops: list[str] = []
        if refresh:
            ops.append(
                "DELETE { GRAPH ?g { ?s ?p ?o } } WHERE { VALUES ?s { " + self._values(refresh) + " } "
                "GRAPH ?g { ?s ?p ?o } FILTER(?p != prov:wasDerivedFrom) }"
            )
        if drop:
            ops.append(
                "DELETE { GRAPH ?g { ?s ?p ?o } } WHERE { VALUES ?s { " + self._values(drop) + " } "
                "GRAPH ?g { ?s ?p ?o } }"
            )
        if quads:
            body = "\n".join(
                f"GRAPH {q.graph_name} {{ {q.subject} {q.predicate} {q.object} }}" for q in quads
            )
            ops.append("INSERT DATA {\n" + body + "\n}")
        if ops:
            self._update(" ;\n".join(ops))

    def append_nquads(self, text: str) -> None:
        if text:
            quads = list(ox.parse(text.encode("utf-8"), format=ox.RdfFormat.N_QUADS))
            for k in range(0, len(quads), 20000):
                self.write("", [], [], quads[k : k + 20000])

    def objects(self, subject: str, predicate: str) -> list[str]:
        rows = self.query(f"SELECT ?o WHERE {{ GRAPH ?g {{ <{subject}> <{predicate}> ?o }} }}")
        return [r["o"].value for r in rows if isinstance(r.get("o"), ox.NamedNode)]

    def synced_seq(self, kb_id: str) -> int:
        return self.sync_state(kb_id)[0]

    def sync_state(self, kb_id: str) -> tuple[int, bool]:
        s, g = _kb_node(kb_id), meta_graph(kb_id)
        rows = self.query(f"SELECT ?n ?d WHERE {{ GRAPH {g} {{ OPTIONAL {{ {s} hiper:syncedSeq ?n }} "
                          f"OPTIONAL {{ {s} hiper:syncDirty ?d }} }} }}")
        seq = int(rows[0]["n"].value) if rows and "n" in rows[0] else 0
        return seq, bool(rows and "d" in rows[0])

    def begin_sync(self, kb_id: str) -> None:
        s, g = _kb_node(kb_id), meta_graph(kb_id)
        self._update(f"INSERT DATA {{ GRAPH {g} {{ {s} hiper:syncDirty true }} }}")

    def set_synced_seq(self, kb_id: str, seq: int) -> None:
        s, g = _kb_node(kb_id), meta_graph(kb_id)
        self._update(
            f"DELETE WHERE {{ GRAPH {g} {{ {s} hiper:syncedSeq ?n }} }} ;\n"
            f"DELETE WHERE {{ GRAPH {g} {{ {s} hiper:syncDirty ?d }} }} ;\n"
            f"INSERT DATA {{ GRAPH {g} {{ {s} hiper:syncedSeq {seq} }} }}"
        )

    def clear(self, graphs: Sequence[ox.NamedNode]) -> None:
        if graphs:
            self._update(" ;\n".join(f"CLEAR SILENT GRAPH {g}" for g in graphs))

    def query(self, sparql: str, bindings: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
        if bindings:
            sparql = values_bound(sparql, bindings)
        raw = self._post("query", _PREFIXES + sparql, "application/sparql-query",
                         accept="application/sparql-results+json")
        return _solutions(ox.parse_query_results(raw, format=ox.QueryResultsFormat.JSON))

    def run_readonly(self, sparql: str, media_type: str,
                     timeout_s: float | None = DEFAULT_TIMEOUT_S) -> tuple[bytes, str]:
        readonly_form(sparql, _PREFIXES)
        try:
            body = run_with_timeout(
                lambda: self._post("query", _PREFIXES + sparql, "application/sparql-query",
                                   accept=media_type),
                timeout_s)
            return body, media_type
        except KnowledgeBaseError as err:
            raise QueryError(str(err)) from err

    def quads(self, graphs: Sequence[ox.NamedNode]) -> list[ox.Quad]:
        out: list[ox.Quad] = []
        for g in graphs:
            for row in self.query(f"SELECT ?s ?p ?o WHERE {{ GRAPH {g} {{ ?s ?p ?o }} }}"):
                out.append(ox.Quad(row["s"], row["p"], row["o"], g))
        return out

    def flush(self) -> None:
        pass

    def buffered_quads(self) -> int:
        return 0

    def close(self) -> None:
        pass


class DetachedGraph:
    """Stands in for a local graph store another process owns (a ``GraphFollower``)."""

    def __init__(self, location: str) -> None:
        self.location = location

    def busy(self) -> KnowledgeBaseError:
        return KnowledgeBaseError(
            f"{self.location}: the scene graph is being written by the graph follower process; "
            "read it after the follower stops (or open the knowledge base from another process "
            "with open_kb_for_reading)"
        )

    def __getattr__(self, name: str) -> Any:
        raise self.busy()

    def close(self) -> None:
        pass


def term(value: Any) -> Any:
    """A pyoxigraph term for a binding: terms as they are, floats as xsd:double, ints as
    xsd:integer, bools as xsd:boolean, anything else as a plain string literal."""
    if isinstance(value, ox.NamedNode | ox.Literal | ox.BlankNode):
        return value
    if isinstance(value, bool):
        return ox.Literal("true" if value else "false", datatype=ox.NamedNode(_XSD + "boolean"))
    if isinstance(value, int):
        return ox.Literal(str(value), datatype=_INTEGER)
    if isinstance(value, float):
        return ox.Literal(repr(value), datatype=ox.NamedNode(_XSD + "double"))
    return ox.Literal(str(value))


def values_bound(sparql: str, bindings: Mapping[str, Any]) -> str:
    """The query with a ``VALUES`` row of the bindings opening its WHERE group, for endpoints
    (the SPARQL 1.1 Protocol has no bindings). Values are serialised RDF terms (quotes and
    brackets escaped by pyoxigraph), so they cannot change the query's structure."""
    import re

    match = re.search(r"\bWHERE\s*\{", sparql, flags=re.IGNORECASE)
    if match is None:
        raise QueryError("a bound query needs a 'WHERE {' group to bind its variables in")
    names = " ".join(f"?{ox.Variable(k).value}" for k in bindings)
    row = " ".join(str(term(v)) for v in bindings.values())
    return f"{sparql[: match.end()]} VALUES ({names}) {{ ({row}) }} {sparql[match.end():]}"


RESULT_FORMATS = {
    "application/sparql-results+json": ox.QueryResultsFormat.JSON,
    "application/sparql-results+xml": ox.QueryResultsFormat.XML,
    "text/csv": ox.QueryResultsFormat.CSV,
    "text/tab-separated-values": ox.QueryResultsFormat.TSV,
}
GRAPH_FORMATS = {
    "text/turtle": ox.RdfFormat.TURTLE,
    "application/n-triples": ox.RdfFormat.N_TRIPLES,
    "application/rdf+xml": ox.RdfFormat.RDF_XML,
}


def serialize_results(result: Any, media_type: str) -> tuple[bytes, str]:
    """Serialise pyoxigraph query results: solutions and booleans in a SPARQL results format
    (JSON unless ``media_type`` names another), triples in an RDF format (Turtle unless)."""
    if isinstance(result, ox.QueryTriples):
        media = media_type if media_type in GRAPH_FORMATS else "text/turtle"
        return bytes(result.serialize(format=GRAPH_FORMATS[media]) or b""), media
    media = media_type if media_type in RESULT_FORMATS else "application/sparql-results+json"
    return bytes(result.serialize(format=RESULT_FORMATS[media]) or b""), media


def open_graph(location: str | Path, *, read_only: bool = False) -> LocalGraph | SparqlGraph:
    """A ``SparqlGraph`` for ``http(s)://`` locations, else a ``LocalGraph`` directory."""
    text = str(location)
    if text.startswith(("http://", "https://")):
        return SparqlGraph(text)
    return LocalGraph(Path(text), read_only=read_only)
