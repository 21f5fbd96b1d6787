"""How documents become RDF: IRIs, the four layer graphs of a knowledge base, and node triples.

Nodes are ``<urn:uuid:UUID>``. Each knowledge base (id ``KB``) writes four named graphs
``<urn:hiper:kb:KB:LAYER>`` (environment, background, foreground, map) plus a meta graph
holding the high-water mark, so several robots' knowledge bases can share one SPARQL endpoint.
The vocabulary is ``hiper.ttl`` beside this file (SOSA/SSN for observations, PROV-O for the
instance -> observation provenance).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from importlib import resources
from typing import Any

import pyoxigraph as ox

from hiper_cli.learned import typical_speed_mps

__all__ = [
    "HIPER",
    "LAYER_OF_TYPE",
    "OBSERVATION_BATCH_S",
    "OBSERVATION_DETAIL",
    "PROV",
    "SOSA",
    "batch_node",
    "batch_quads",
    "doc_quads",
    "layer_graph",
    "link_nquads",
    "link_quad",
    "meta_graph",
    "node",
    "observation_nquads",
    "ontology_turtle",
    "session_node",
    "session_quads",
]

HIPER = "https://w3id.org/hiper#"
SOSA = "http://www.w3.org/ns/sosa/"
PROV = "http://www.w3.org/ns/prov#"
RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
XSD = "http://www.w3.org/2001/XMLSchema#"
_DOUBLE = ox.NamedNode(XSD + "double")
_INTEGER = ox.NamedNode(XSD + "integer")

# Observations in the graph (``KbConfig.observation_detail``, fixed when a KB is created):
# "batch" (default): no node per observation; each instance is derived from observation
#   batches, one node per instance, session and ``OBSERVATION_BATCH_S`` window with the number
#   of observations and their first and last stamps (the paper's "links to a batch of
#   time-continuous child observations"); the observations themselves stay in the documents.
#   The graph then grows with instances, not observations: the on-disk store's memory grows
#   with the quads it holds (about 100 MB at 400 k quads: scripts/bench_graph_store.py).
# "summary": a node per observation (its type) and the provenance link from its instance
#   (bulk-loaded: ~70 k observations/s with 2 quads each, ~45 k/s with 4);
# "full": also class, stamp, pose id, frame, confidence and the camera-frame box.
OBSERVATION_DETAIL = ("batch", "summary", "full")
OBSERVATION_BATCH_S = 60.0

# Which layer graph holds which document type when the document has no layer of its own.
LAYER_OF_TYPE = {"environment": "environment", "session": "environment", "analysis": "map"}

WAS_DERIVED_FROM = ox.NamedNode(PROV + "wasDerivedFrom")
PROV_USED = ox.NamedNode(PROV + "used")
_OBSERVATION = ox.NamedNode(HIPER + "Observation")


def h(name: str) -> ox.NamedNode:
    return ox.NamedNode(HIPER + name)


def node(uuid: str) -> ox.NamedNode:
    return ox.NamedNode(f"urn:uuid:{uuid}")


def layer_graph(kb_id: str, layer: str) -> ox.NamedNode:
    return ox.NamedNode(f"urn:hiper:kb:{kb_id}:{layer}")


def meta_graph(kb_id: str) -> ox.NamedNode:
    return ox.NamedNode(f"urn:hiper:kb:{kb_id}:meta")


def session_node(kb_id: str, session_id: int) -> ox.NamedNode:
    return ox.NamedNode(f"urn:hiper:kb:{kb_id}:session:{session_id}")


def ontology_turtle() -> str:
    """The ontology shipped with the package (``hiper_cli/graph/hiper.ttl``)."""
    return resources.files("hiper_cli.graph").joinpath("hiper.ttl").read_text(encoding="utf-8")


def _dbl(value: Any) -> ox.Literal:
    v = float(value)
    return ox.Literal(repr(v) if math.isfinite(v) else "NaN", datatype=_DOUBLE)


def _int(value: Any) -> ox.Literal:
    return ox.Literal(str(int(value)), datatype=_INTEGER)


def _vec(values: Sequence[float]) -> ox.Literal:
    return ox.Literal(" ".join(f"{float(v):.6g}" for v in values))


def speed_mps(doc: dict[str, Any]) -> float | None:
    """Speed of an instance (``typical_speed_mps``) from its ``data.trajectory`` rows, if any
    (a document whose long trajectory is stored apart carries it as ``trajectory_speed_mps``)."""
    data = doc.get("data") or {}
    if "trajectory_speed_mps" in data and "trajectory" not in data:
        speed = data["trajectory_speed_mps"]
        return None if speed is None else float(speed)
    return typical_speed_mps(data.get("trajectory") or [])


def doc_quads(kb_id: str, doc: dict[str, Any], detail: str = "summary") -> list[ox.Quad]:
    """The graph node of one document (without its provenance links, see ``link_quad``)."""
    kind = doc["type"]
    layer = doc.get("layer") or LAYER_OF_TYPE.get(kind, "map")
    g = layer_graph(kb_id, layer)
    s = node(doc["uuid"])
    t: list[tuple[ox.NamedNode, ox.NamedNode | ox.Literal]] = []
    if kind == "observation":
        if detail == "batch":
            return []
        t.append((RDF_TYPE, _OBSERVATION))
        if detail == "full":
            box = doc["box"]
            t += [(h("className"), ox.Literal(doc["class"])), (h("stampS"), _dbl(doc["stamp_s"])),
                  (h("layer"), h(layer)), (h("poseId"), _int(doc["pose_id"])),
                  (h("frame"), ox.Literal(doc.get("frame_id", "camera"))),
                  (h("confidence"), _dbl(doc["confidence"])),
                  (h("boxCenterM"), _vec(box["center_m"])), (h("boxExtentM"), _vec(box["extent_m"]))]
    elif kind == "instance":
        box = doc["box"]
        t += [(RDF_TYPE, h("Instance")), (h("uuid"), ox.Literal(doc["uuid"])), (h("layer"), h(layer)),
              (h("className"), ox.Literal(doc["class"])),
              (h("frame"), ox.Literal(doc.get("frame_id", "map"))),
              (h("firstSeenS"), _dbl(doc["first_seen_s"])), (h("lastSeenS"), _dbl(doc["last_seen_s"])),
              (h("state"), ox.Literal(doc.get("state", "static"))),
              (h("confidence"), _dbl(doc.get("confidence", 1.0))),
              (h("boxCenterM"), _vec(box["center_m"])), (h("boxExtentM"), _vec(box["extent_m"])),
              (h("observationCount"),
               _int(doc.get("observation_count", len(doc.get("observation_uuids", [])))))]
        speed = speed_mps(doc)
        if speed is not None:
            t.append((h("speedMps"), _dbl(speed)))
        vacated = (doc.get("data") or {}).get("vacated_s")
        if vacated is not None:
            t.append((h("vacatedS"), _dbl(vacated)))
            t.append((h("validToS"), _dbl(vacated)))
        t += [(h("validFromS"), _dbl(doc["first_seen_s"])),
              (h("presence"), ox.Literal("present" if vacated is None else "removed"))]
        same = (doc.get("data") or {}).get("same_object_as")
        if same:  # the other layer's instance of this real object (a mapped table's body: its top)
            t.append((h("sameObjectAs"), node(str(same))))
        if doc.get("env_uuid"):
            t.append((h("inEnvironment"), node(doc["env_uuid"])))
    elif kind == "change":  # an event (``history.py``): PROV-O activity over the instance
        t += [(RDF_TYPE, h("Change")), (h("uuid"), ox.Literal(doc["uuid"])),
              (h("changeKind"), ox.Literal(doc["kind"])), (h("className"), ox.Literal(doc["class"])),
              (PROV_USED, node(doc["instance_uuid"])),
              (h("inSession"), session_node(kb_id, int(doc["session"]))),
              (h("stampS"), _dbl(doc["stamp_s"]))]
        for name, key in (("fromM", "from_m"), ("toM", "to_m")):
            if doc.get(key) is not None:
                t.append((h(name), _vec(doc[key])))
    elif kind == "analysis":
        t += [(RDF_TYPE, h("Analysis")), (h("uuid"), ox.Literal(doc["uuid"])), (h("layer"), h(layer)),
              (h("kind"), ox.Literal(doc["kind"])), (h("className"), ox.Literal(doc["class"])),
              (h("tStartS"), _dbl(doc["t_start_s"])), (h("tEndS"), _dbl(doc["t_end_s"])),
              (h("createdS"), _dbl(doc["created_s"])),
              (h("valuesJson"), ox.Literal(json.dumps(doc["values"], sort_keys=True, default=str)))]
    elif kind == "environment":
        t += [(RDF_TYPE, h("Environment")), (h("uuid"), ox.Literal(doc["uuid"])), (h("layer"), h(layer)),
              (h("name"), ox.Literal(doc["name"]))]
    else:
        t += [(RDF_TYPE, h(kind.capitalize())), (h("uuid"), ox.Literal(doc["uuid"]))]
    return [ox.Quad(s, p, o, g) for p, o in t]


def observation_nquads(kb_id: str, uuid: str, layer: str) -> str:
    """The "summary" node of an observation as one N-Quads line (what ``doc_quads`` gives for
    it, written directly: the graph sync's hot path)."""
    return f"<urn:uuid:{uuid}> <{RDF_TYPE.value}> <{_OBSERVATION.value}> <urn:hiper:kb:{kb_id}:{layer}> .\n"


def link_nquads(kb_id: str, instance_uuid: str, observation_uuid: str, layer: str) -> str:
    """``link_quad`` as one N-Quads line."""
    return (f"<urn:uuid:{instance_uuid}> <{WAS_DERIVED_FROM.value}> <urn:uuid:{observation_uuid}> "
            f"<urn:hiper:kb:{kb_id}:{layer}> .\n")


def batch_node(instance_uuid: str, session_id: int | None, window: int) -> ox.NamedNode:
    session = "none" if session_id is None else str(session_id)
    return ox.NamedNode(f"urn:hiper:batch:{instance_uuid}:{session}:{window}")


def batch_quads(
    kb_id: str, layer: str, instance_uuid: str, session_id: int | None, window: int,
    count: int, first_s: float, last_s: float,
) -> list[ox.Quad]:
    """The node of one observation batch and the provenance link of its instance to it."""
    g = layer_graph(kb_id, layer)
    b = batch_node(instance_uuid, session_id, window)
    t: list[tuple[ox.NamedNode, ox.NamedNode | ox.Literal]] = [
        (RDF_TYPE, h("ObservationBatch")), (h("observationCount"), _int(count)),
        (h("firstStampS"), _dbl(first_s)), (h("lastStampS"), _dbl(last_s)),
    ]
    if session_id is not None:
        t.append((h("inSession"), session_node(kb_id, session_id)))
    return [ox.Quad(b, p, o, g) for p, o in t] + [ox.Quad(node(instance_uuid), WAS_DERIVED_FROM, b, g)]


def link_quad(kb_id: str, instance_uuid: str, observation_uuid: str, layer: str) -> ox.Quad:
    """``instance prov:wasDerivedFrom observation`` in the instance's layer graph."""
    return ox.Quad(node(instance_uuid), WAS_DERIVED_FROM, node(observation_uuid), layer_graph(kb_id, layer))


def session_quads(kb_id: str, session: dict[str, Any]) -> list[ox.Quad]:
    g = layer_graph(kb_id, "environment")
    s = session_node(kb_id, int(session["id"]))
    t: list[tuple[ox.NamedNode, ox.NamedNode | ox.Literal]] = [
        (RDF_TYPE, h("Session")), (h("logPath"), ox.Literal(session["log_path"])),
        (h("startedS"), _dbl(session["started_s"])), (h("frames"), _int(session["frames"])),
        (h("inEnvironment"), node(session["env_uuid"])),
    ]
    if session.get("ended_s") is not None:
        t.append((h("endedS"), _dbl(session["ended_s"])))
    if session.get("alignment") is not None:  # the transform into the place's map frame
        align = session["alignment"]
        t += [(h("alignmentJson"), ox.Literal(json.dumps(align["T_map_log"]))),
              (h("alignmentMethod"), ox.Literal(align["method"])),
              (h("alignmentFitness"), _dbl(align["fitness"]))]
    return [ox.Quad(s, p, o, g) for p, o in t]
