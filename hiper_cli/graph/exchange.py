"""Export a knowledge base to Turtle, N-Quads, JSON-LD, GraphML or JSON, and import it back.

* ``turtle``: every triple of the four layer graphs (Turtle has no named graphs, so each node
  gets its ``hiper:layer``); ``nquads``: the four named graphs as they are (both serialised by
  pyoxigraph); ``jsonld``: the named graphs through rdflib's JSON-LD serialiser.
* ``graphml`` (networkx): one node per graph node (attributes: ``iri``, ``type``, ``layer`` and
  every literal property by its local name), one edge per object property (``predicate``).
* ``json``: the documented export for other tools and LLM agents (schema in docs/kb.md):
  environments, sessions, instances (class, layer, box centre/extent in metres, first/last seen,
  state, observation count, speed), analyses and, with ``observations=True``, the full
  observation documents.

Import reads all five back into documents (then the graph is rebuilt from them). The RDF and
GraphML forms carry the high-level attributes only: imported observations have no low-level
data, and their boxes are zero unless the graph held them (``observation_detail="full"``).
"""

from __future__ import annotations

import json
import math
import re
import time
import warnings
from collections import defaultdict
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from hiper_cli.errors import DataError, KnowledgeBaseError
from hiper_cli.files import atomic_output, os_error, refuse_inside
from hiper_cli.graph.history import validity
from hiper_cli.graph.import_check import check_documents, check_json_shape, check_unique, read_json_export
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.graph.ontology import HIPER, PROV, RDF_TYPE, doc_quads, h, layer_graph, link_quad, speed_mps
from hiper_cli.model import LAYERS, Instance

__all__ = ["EXPORT_FORMATS", "export_kb", "guess_format", "import_kb", "json_export", "read_export_instances"]

EXPORT_FORMATS = ("turtle", "nquads", "jsonld", "graphml", "json")
_SUFFIX = {".ttl": "turtle", ".nq": "nquads", ".jsonld": "jsonld", ".graphml": "graphml", ".json": "json"}
JSON_FORMAT_NAME = "hiper-kb-export"
JSON_FORMAT_VERSION = 2  # 2: instances' "state" is present | removed, their motion is "motion"
CHANGE_FIELDS = ("uuid", "kind", "class", "instance_uuid", "session", "stamp_s", "from_m", "to_m")


def guess_format(path: Path) -> str:
    fmt = _SUFFIX.get(path.suffix.lower())
    if fmt is None:
        raise DataError(f"{path}: cannot tell the format from '{path.suffix}'; use --format "
                        f"({', '.join(EXPORT_FORMATS)}) or a suffix {', '.join(_SUFFIX)}")
    return fmt


def _layer_quads(kb: KnowledgeBase) -> list[ox.Quad]:
    kb.sync_graph() if not kb.read_only else None
    quads: list[ox.Quad] = kb.graph.quads([layer_graph(kb.kb_id, layer) for layer in LAYERS])
    return quads


def _with_observations(kb: KnowledgeBase, quads: list[ox.Quad]) -> list[ox.Quad]:
    """Add every observation as a node (class, stamp, pose, frame, confidence, box) with its
    provenance link from its instance, from the documents (the scene graph may hold only
    observation batches, see ``ontology.OBSERVATION_DETAIL``)."""
    have = set(quads)
    extra: list[ox.Quad] = []
    for doc in kb.docs.find(type="observation"):
        extra += (q for q in doc_quads(kb.kb_id, doc, "full") if q not in have)
    for links in kb.docs.changed_links(0, kb.docs.seq):
        extra += (q for q in (link_quad(kb.kb_id, i, o, layer) for i, o, layer in links) if q not in have)
    return quads + extra


def _with_layers(kb: KnowledgeBase, quads: list[ox.Quad]) -> list[ox.Quad]:
    """Add ``hiper:layer`` to nodes that lack it and, to "summary" observation nodes (the graph
    holds only their type and provenance), their class and stamp from the documents."""
    graph_layer = {layer_graph(kb.kb_id, layer).value: layer for layer in LAYERS}
    has_layer = {q.subject for q in quads if q.predicate == h("layer")}
    extra = {
        ox.Quad(q.subject, h("layer"), h(graph_layer[q.graph_name.value]), q.graph_name)
        for q in quads
        if q.predicate == RDF_TYPE and q.subject not in has_layer and isinstance(q.graph_name, ox.NamedNode)
    }
    has_class = {q.subject for q in quads if q.predicate == h("className")}
    bare = [q for q in quads if q.predicate == RDF_TYPE and q.object == h("Observation")
            and q.subject not in has_class and isinstance(q.subject, ox.NamedNode)]
    double = ox.NamedNode("http://www.w3.org/2001/XMLSchema#double")
    for k in range(0, len(bare), 10000):
        chunk = bare[k : k + 10000]
        uuids = [str(getattr(q.subject, "value", "")).removeprefix("urn:uuid:") for q in chunk]
        found = kb.docs.summaries(uuids)
        for q, uuid in zip(chunk, uuids, strict=True):
            cls, stamp = found.get(uuid, (None, None))
            if cls is not None:
                extra.add(ox.Quad(q.subject, h("className"), ox.Literal(cls), q.graph_name))
            if stamp is not None:
                extra.add(ox.Quad(q.subject, h("stampS"), ox.Literal(repr(float(stamp)), datatype=double),
                                  q.graph_name))
    return quads + sorted(extra, key=str)


def _to_rdflib(term: Any) -> Any:
    import rdflib

    if isinstance(term, ox.NamedNode):
        return rdflib.URIRef(term.value)
    if isinstance(term, ox.Literal):
        if term.language:
            return rdflib.Literal(term.value, lang=term.language)
        return rdflib.Literal(term.value, datatype=rdflib.URIRef(term.datatype.value))
    return rdflib.BNode(str(term))


def _local(iri: str) -> str:
    for base in (HIPER, PROV, "http://www.w3.org/1999/02/22-rdf-syntax-ns#"):
        if iri.startswith(base):
            return iri[len(base):]
    return iri


def export_kb(kb: KnowledgeBase, out: Path, fmt: str, *, observations: bool = False) -> dict[str, Any]:
    """Write ``kb`` to ``out`` in ``fmt``; returns a summary (format, path, counts).

    The file is written beside ``out`` and renamed into place when complete, so a failure
    leaves an earlier file of that name whole; ``out`` may not lie inside a knowledge base."""
    if fmt not in EXPORT_FORMATS:
        raise DataError(f"export format {fmt!r}; expected one of {', '.join(EXPORT_FORMATS)}")
    refuse_inside(out, "export")
    if out.is_dir():
        raise DataError(f"{out}: is a folder; pass a file name for the export")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise os_error(out.parent, err, "create") from err
    summary: dict[str, Any] = {"format": fmt, "path": str(out)}
    if fmt == "json":
        data = json_export(kb, observations=observations)
        with atomic_output(out) as target, target.open("w") as f:
            json.dump(data, f, indent=1)
            f.write("\n")
        keys = ("environments", "instances", "analyses", "observations")
        summary["counts"] = {k: len(data[k]) for k in keys}
        return summary
    quads = _layer_quads(kb)
    if observations:
        quads = _with_observations(kb, quads)
    quads = _with_layers(kb, quads)
    summary["quads"] = len(quads)
    with atomic_output(out) as target:
        _write_rdf(quads, target, fmt)
    return summary


def _write_rdf(quads: list[ox.Quad], out: Path, fmt: str) -> None:
    prefixes = {"hiper": HIPER, "prov": PROV, "sosa": "http://www.w3.org/ns/sosa/"}
    if fmt == "nquads":
        ox.serialize(quads, str(out), ox.RdfFormat.N_QUADS)
    elif fmt == "turtle":
        ox.serialize([ox.Triple(q.subject, q.predicate, q.object) for q in quads], str(out),
                     ox.RdfFormat.TURTLE, prefixes=prefixes)
    elif fmt == "jsonld":
        import rdflib

        dataset = rdflib.Dataset()
        for q in quads:
            dataset.graph(_to_rdflib(q.graph_name)).add(
                (_to_rdflib(q.subject), _to_rdflib(q.predicate), _to_rdflib(q.object))
            )
        for name, iri in prefixes.items():
            dataset.bind(name, iri)
        with warnings.catch_warnings():  # rdflib 7.x's own JSON-LD plugin uses deprecated calls
            warnings.simplefilter("ignore", DeprecationWarning)
            dataset.serialize(destination=str(out), format="json-ld")
    else:
        import networkx as nx

        g = nx.MultiDiGraph()
        for q in quads:
            s = str(getattr(q.subject, "value", q.subject))
            g.add_node(s, iri=s)
            key = _local(q.predicate.value)
            if isinstance(q.object, ox.Literal):
                g.nodes[s][key] = _xml_text(q.object.value)
                continue
            o = str(getattr(q.object, "value", q.object))
            if key in ("type", "layer"):
                g.nodes[s][key] = _local(o)
            else:
                g.add_node(o, iri=o)
                g.add_edge(s, o, predicate=key)
        nx.write_graphml(g, str(out))


_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")


def _xml_text(text: str) -> str:
    """``text`` without the characters XML 1.0 cannot hold (written as ``\\xNN``)."""
    return _NOT_XML.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


def _plane(doc: dict[str, Any]) -> list[float] | None:
    """A background instance's plane ``[a, b, c, d]`` (unit normal, map frame, ``a x + b y +
    c z + d = 0``) from its low-level data; None for the others. A plane piece's box is thin
    along the normal, but a reader that ignores ``R`` cannot tell which way: the plane says it."""
    plane = (doc.get("data") or {}).get("plane_map")
    if doc.get("layer") != "background" or plane is None or len(plane) != 4:
        return None
    values = [float(v) for v in plane]
    return values if all(math.isfinite(v) for v in values) else None


def json_export(kb: KnowledgeBase, *, observations: bool = False) -> dict[str, Any]:
    """The documented JSON form of a knowledge base (see docs/kb.md)."""
    docs = kb.docs
    instances = []
    for d in docs.find(type="instance"):
        box = d["box"]
        instances.append({
            "uuid": d["uuid"], "layer": d["layer"], "class": d["class"],
            "box": {"center_m": box["center_m"], "extent_m": box["extent_m"], "R": box.get("R")},
            "plane": _plane(d),
            "frame": d.get("frame_id", "map"),
            "first_seen_s": d["first_seen_s"], "last_seen_s": d["last_seen_s"], "motion": d.get("state"),
            **validity(d),  # valid_from_s, valid_to_s, state: present | removed
            "confidence": d.get("confidence"),
            "observation_count": len(d.get("observation_uuids", [])),
            "speed_mps": speed_mps(d),
            "vacated_s": (d.get("data") or {}).get("vacated_s"),
            # the other layer's instance of the same real object: count it once
            "same_object_as": (d.get("data") or {}).get("same_object_as"),
            **({"observation_uuids": d["observation_uuids"]} if observations else {}),
            "data": d.get("data", {}) if observations else None,
        })
    return {
        "format": JSON_FORMAT_NAME,
        "version": JSON_FORMAT_VERSION,
        "kb_id": kb.kb_id,
        "exported_s": time.time(),
        "units": {"length": "m", "time": "s", "speed": "m/s"},
        "environments": [{"uuid": d["uuid"], "name": d["name"]} for d in docs.find(type="environment")],
        "sessions": [s.to_dict() for s in docs.sessions()],
        "instances": instances,
        "analyses": [{k: v for k, v in d.items() if k != "type"} for d in docs.find(type="analysis")],
        "changes": [{k: d.get(k) for k in CHANGE_FIELDS} for d in docs.find(type="change")],
        "observations": docs.find(type="observation") if observations else [],
    }


def _docs_from_json(data: Any, source: Path) -> list[tuple[str, dict[str, Any]]]:
    """(where in the file, document) for every document of a JSON export."""
    check_json_shape(data, source)
    if data.get("format") != JSON_FORMAT_NAME:
        raise DataError(f"{source}: not a hiper JSON export (format {data.get('format')!r}); "
                        f"expected {JSON_FORMAT_NAME!r} written by 'hiper export --format json'")
    out: list[tuple[str, dict[str, Any]]] = []
    for k, e in enumerate(data.get("environments", [])):
        out.append((f"environments[{k}]", {"uuid": e.get("uuid"), "type": "environment",
                                           "name": e.get("name"),
                                           "data": {}, "env_uuid": e.get("uuid")}))
    for k, i in enumerate(data.get("instances", [])):
        box = dict(i["box"]) if isinstance(i.get("box"), dict) else i.get("box")
        if isinstance(box, dict) and box.get("R") is None:
            box.pop("R", None)
        out.append((f"instances[{k}]", {
            "uuid": i.get("uuid"), "type": "instance", "layer": i.get("layer"), "class": i.get("class"),
            "box": box, "first_seen_s": i.get("first_seen_s"), "last_seen_s": i.get("last_seen_s"),
            "state": i.get("motion") or (i.get("state") if i.get("state") in ("static", "dynamic") else None)
            or "static",
            "confidence": 1.0 if i.get("confidence") is None else i["confidence"],
            "observation_uuids": i.get("observation_uuids", []), "frame_id": i.get("frame", "map"),
            "data": {**(i.get("data") or {}),
                     **({"vacated_s": i["vacated_s"]} if i.get("vacated_s") is not None else {}),
                     **({"same_object_as": i["same_object_as"]} if i.get("same_object_as") else {})},
        }))
    for k, a in enumerate(data.get("analyses", [])):
        out.append((f"analyses[{k}]", {**a, "type": "analysis"}))
    for k, c in enumerate(data.get("changes", [])):
        out.append((f"changes[{k}]", {**c, "type": "change", "layer": "foreground"}))
    live = {d["uuid"] for _, d in out if d["type"] == "instance"}
    for k, o in enumerate(data.get("observations", [])):
        if o.get("instance_uuid") not in live:  # its instance was merged away before the export
            o = {**o, "instance_uuid": None}
        out.append((f"observations[{k}]", o))
    return out


def read_export_instances(path: Path) -> tuple[list[Instance], list[dict[str, Any]]]:
    """The instances and sessions of a JSON export, read as its knowledge base returns them
    (a background piece's exported ``plane`` back in its ``data["plane_map"]``), for scoring."""
    data = read_json_export(path)
    planes = {i.get("uuid"): i.get("plane") for i in data.get("instances", [])}
    instances = []
    for _, doc in _docs_from_json(data, path):
        if doc["type"] == "instance":
            if planes.get(doc["uuid"]) is not None:
                doc["data"].setdefault("plane_map", planes[doc["uuid"]])
            instances.append(Instance.from_dict(doc))
    return instances, list(data.get("sessions", []))


def _vec(text: str | None) -> list[float]:
    return [float(v) for v in text.split()] if text else [0.0, 0.0, 0.0]


def _docs_from_props(props: dict[str, dict[str, list[str]]]) -> list[tuple[str, dict[str, Any]]]:
    """(node, document) from node properties keyed by local predicate name (RDF or GraphML)."""
    out: list[dict[str, Any]] = []
    links: dict[str, list[str]] = defaultdict(list)
    for iri, p in props.items():
        for target in p.get("wasDerivedFrom", []):
            if target.startswith("urn:uuid:"):  # observations (not observation batches)
                links[iri].append(target.removeprefix("urn:uuid:"))

    def one(p: dict[str, list[str]], key: str, default: Any = None) -> Any:
        values = p.get(key)
        return values[0] if values else default

    for iri, p in props.items():
        if not iri.startswith("urn:uuid:"):
            continue
        uuid = iri.removeprefix("urn:uuid:")
        kind = one(p, "type")
        layer = one(p, "layer")
        if kind == "Observation":
            out.append({
                "uuid": uuid, "type": "observation", "layer": layer or "foreground",
                "class": one(p, "className"),
                "confidence": float(one(p, "confidence", 1.0)), "stamp_s": float(one(p, "stampS", 0.0)),
                "pose_id": int(one(p, "poseId", -1)), "frame_id": one(p, "frame", "camera"),
                "box": {"center_m": _vec(one(p, "boxCenterM")), "extent_m": _vec(one(p, "boxExtentM"))},
                "instance_uuid": None, "data": {},
            })
        elif kind == "Instance":
            env, vacated, same = one(p, "inEnvironment"), one(p, "vacatedS"), one(p, "sameObjectAs")
            out.append({
                "uuid": uuid, "type": "instance", "layer": layer, "class": one(p, "className"),
                "box": {"center_m": _vec(one(p, "boxCenterM")), "extent_m": _vec(one(p, "boxExtentM"))},
                "first_seen_s": float(one(p, "firstSeenS", 0.0)),
                "last_seen_s": float(one(p, "lastSeenS", 0.0)),
                "state": one(p, "state", "static"), "confidence": float(one(p, "confidence", 1.0)),
                "observation_uuids": links.get(iri, []), "frame_id": one(p, "frame", "map"),
                "data": {**({} if vacated is None else {"vacated_s": float(vacated)}),
                         **({"same_object_as": same.removeprefix("urn:uuid:")} if same else {})},
                **({"env_uuid": env.removeprefix("urn:uuid:")} if env else {}),
            })
        elif kind == "Analysis":
            out.append({
                "uuid": uuid, "type": "analysis", "kind": one(p, "kind"), "class": one(p, "className"),
                "t_start_s": float(one(p, "tStartS", 0.0)), "t_end_s": float(one(p, "tEndS", 0.0)),
                "values": json.loads(one(p, "valuesJson", "{}")), "created_s": float(one(p, "createdS", 0.0)),
            })
        elif kind == "Environment":
            out.append({"uuid": uuid, "type": "environment", "name": one(p, "name", uuid), "data": {},
                        "env_uuid": uuid})
    order = {"environment": 0, "observation": 1, "instance": 2, "analysis": 3}
    return [(f"node <urn:uuid:{d['uuid']}>", d) for d in sorted(out, key=lambda d: order[d["type"]])]


def _props_from_rdf(path: Path, fmt: str) -> dict[str, dict[str, list[str]]]:
    formats = {"turtle": ox.RdfFormat.TURTLE, "nquads": ox.RdfFormat.N_QUADS, "jsonld": ox.RdfFormat.JSON_LD}
    props: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    try:
        for q in ox.parse(path=str(path), format=formats[fmt]):
            if not isinstance(q.subject, ox.NamedNode):
                continue
            key = _local(q.predicate.value)
            value = q.object.value if isinstance(q.object, ox.NamedNode | ox.Literal) else str(q.object)
            if key in ("type", "layer"):
                value = _local(value)
            props[q.subject.value][key].append(value)
    except (SyntaxError, ValueError, OSError) as err:
        raise DataError(f"{path}: cannot read it as {fmt} ({err}); check the file or pass --format") from err
    return props


def _props_from_graphml(path: Path) -> dict[str, dict[str, list[str]]]:
    import networkx as nx

    try:
        g = nx.read_graphml(str(path))
    except Exception as err:  # networkx raises several parser errors
        raise DataError(f"{path}: cannot read it as GraphML ({err})") from err
    props: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    for n, attrs in g.nodes(data=True):
        for k, v in attrs.items():
            if k != "iri":
                props[str(n)][k].append(str(v))
    for s, o, attrs in g.edges(data=True):
        props[str(s)][str(attrs.get("predicate", "related"))].append(str(o))
    return props


def _check_graph_form(kb: KnowledgeBase, labelled: list[tuple[str, dict[str, Any]]], source: Path) -> None:
    """Build every document's graph node in memory before the first write: what the graph
    sync would fail on refuses the import instead of leaving the two stores apart."""
    for where, doc in labelled:
        try:
            doc_quads(kb.kb_id, doc, kb.config.observation_detail)
            if doc["type"] == "instance":
                Instance.from_dict(doc).box.aabb()
        except (ValueError, TypeError, KeyError, OverflowError, AttributeError) as err:
            raise DataError(f"{source}: {where}: cannot be stored ({type(err).__name__}: "
                            f"{' '.join(str(err).split())[:160]}); nothing was imported") from err


def import_kb(kb: KnowledgeBase, path: Path, fmt: str | None = None) -> dict[str, Any]:
    """Read an export into ``kb`` (documents first, then the graph follows). Every document is
    validated before the first is written; the write is one transaction."""
    fmt = fmt or guess_format(path)
    if not path.is_file():
        raise DataError(f"{path}: no such file; pass a file written by 'hiper export'")
    if fmt == "json":
        labelled = _docs_from_json(read_json_export(path), path)
    elif fmt in ("graphml", "turtle", "nquads", "jsonld"):
        props = _props_from_graphml(path) if fmt == "graphml" else _props_from_rdf(path, fmt)
        try:
            labelled = _docs_from_props(props)
        except (ValueError, TypeError, KeyError) as err:
            raise DataError(f"{path}: a node property does not parse ({err}); nothing was imported") from err
    else:
        raise DataError(f"import format {fmt!r}; expected one of {', '.join(EXPORT_FORMATS)}")
    check_documents(labelled, path)
    check_unique(labelled, path, lambda uuid: (kb.docs.get(uuid) or {}).get("type"))
    _check_graph_form(kb, labelled, path)
    docs = [d for _, d in labelled]
    if kb.read_only:
        raise KnowledgeBaseError(f"{kb.location}: opened read-only; cannot import")
    envs = [d["uuid"] for d in docs if d["type"] == "environment"]
    default_env = envs[0] if len(envs) == 1 else None
    n = kb.put_documents(docs, env_uuid=default_env)
    kb.sync_graph()
    counts: dict[str, int] = defaultdict(int)
    for d in docs:
        counts[d["type"]] += 1
    return {"path": str(path), "format": fmt, "documents": n, "counts": dict(counts), "kb": kb.location}
