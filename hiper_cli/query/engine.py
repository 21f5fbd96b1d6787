"""How a ``QuerySpec`` is answered: a SPARQL prefilter (``queries/candidates.rq``, bound
values only) or, for a spatial query over every class, the documents' R*Tree; then the exact
geometry in numpy (``geometry.py``); then the details of the survivors (``instance.rq``),
their support and their evidence observations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pyoxigraph as ox

from hiper_cli.errors import QueryError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.graph.ontology import HIPER
from hiper_cli.query import geometry as geo
from hiper_cli.query.results import Hit, ReferencePose, Support
from hiper_cli.query.spec import QueryConfig, QuerySpec
from hiper_cli.query.templates import template

__all__ = ["Candidates", "Context", "make_context", "select"]

_FAR_S = 1.0e18


@dataclass
class Context:
    """One query's surroundings: the KB, ``now`` (s), the reference pose and the config.
    Caches instance details and support instances for the duration of one query."""

    kb: KnowledgeBase
    now_s: float
    reference: ReferencePose
    config: QueryConfig
    _details: dict[str, dict[str, Any]] = field(default_factory=dict)
    _supports: dict[str, Candidates] = field(default_factory=dict)

    @property
    def T_map_cam(self) -> np.ndarray:
        return np.asarray(self.reference.T_map_cam, dtype=np.float64)

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.reference.x_m, self.reference.y_m])

    @property
    def graph_prefix(self) -> str:
        return f"urn:hiper:kb:{self.kb.kb_id}:"


def make_context(
    kb: KnowledgeBase,
    *,
    pose: tuple[float, float, float, float] | None = None,
    at_s: float | None = None,
    now_s: float | None = None,
    config: QueryConfig | None = None,
) -> Context:
    """The reference pose is ``pose`` (x, y, z, yaw) when given, else the robot's last
    recorded pose at or before ``at_s`` (default: the last one). ``now`` defaults to
    ``at_s``, else the KB's last stamp."""
    span = kb.stamp_span()
    if now_s is None:
        now_s = at_s if at_s is not None else (span[1] if span else 0.0)
    if pose is not None:
        if len(pose) != 4 or not all(math.isfinite(v) for v in pose):
            raise QueryError(f"--pose {pose}: expected four finite numbers x,y,z,yaw (m, m, m, rad)")
        x, y, z, yaw = (float(v) for v in pose)
        T = geo.camera_from_yaw(x, y, z, yaw)
        ref = ReferencePose(x, y, z, yaw, at_s, "given", tuple(tuple(r) for r in T.tolist()))
    else:
        robot = kb.robot_pose(at_s if at_s is not None else None)
        if robot is None:
            T = geo.camera_from_yaw(0.0, 0.0, 0.0, 0.0)
            ref = ReferencePose(0.0, 0.0, 0.0, 0.0, None, "origin", tuple(tuple(r) for r in T.tolist()))
        else:
            p = robot.position_map_m
            ref = ReferencePose(float(p[0]), float(p[1]), float(p[2]), robot.yaw_rad, robot.stamp_s, "robot",
                                tuple(tuple(r) for r in robot.T_map_cam.tolist()))
    return Context(kb, float(now_s), ref, config or QueryConfig())


@dataclass
class Candidates:
    """Instances as arrays: node IRIs (N,), box centres and extents (N, 3), last seen (N,)."""

    iris: list[str]
    centers: np.ndarray
    extents: np.ndarray
    last_s: np.ndarray

    @classmethod
    def empty(cls) -> Candidates:
        return cls([], np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0))

    def take(self, mask_or_index: Any) -> Candidates:
        idx = np.flatnonzero(mask_or_index) if np.asarray(mask_or_index).dtype == bool else mask_or_index
        return Candidates([self.iris[k] for k in idx], self.centers[idx], self.extents[idx], self.last_s[idx])

    def __len__(self) -> int:
        return len(self.iris)


def _bindings(ctx: Context, spec: QuerySpec, class_name: str | None) -> dict[str, Any]:
    until = spec.until_s if spec.until_s is not None else ctx.now_s
    b: dict[str, Any] = {
        "graphPrefix": ctx.graph_prefix,
        "since": float(spec.since_s) if spec.since_s is not None else -_FAR_S,
        "until": float(until),
        "minConfidence": float(spec.min_confidence),
    }
    if class_name is not None:
        b["class"] = class_name
    if spec.layer is not None:
        b["layer"] = ox.NamedNode(HIPER + spec.layer)
    if spec.state is not None:
        b["state"] = spec.state
    return b


def _rows_to_candidates(rows: list[dict[str, Any]]) -> Candidates:
    if not rows:
        return Candidates.empty()
    centers = np.array([geo.parse_vector(r["center"].value) for r in rows])
    extents = np.array([geo.parse_vector(r["extent"].value) for r in rows])
    last = np.array([float(r["last"].value) for r in rows])
    return Candidates([r["i"].value for r in rows], centers, extents, last)


def prefilter(ctx: Context, spec: QuerySpec, box: tuple[np.ndarray, np.ndarray] | None = None) -> Candidates:
    """The instances passing the non-spatial filters. With no class but a bounding ``box``
    (lo, hi), the documents' R*Tree picks the candidates and their graph nodes are checked."""
    sparql = template("candidates")
    if spec.classes:
        rows = [r for c in spec.classes for r in ctx.kb.query_bound(sparql, _bindings(ctx, spec, c))]
        return _rows_to_candidates(rows)
    if box is None:
        return _rows_to_candidates(ctx.kb.query_bound(sparql, _bindings(ctx, spec, None)))
    uuids = ctx.kb.instance_uuids_in(box[0], box[1])
    keep = []
    for uuid in uuids:
        d = details(ctx, f"urn:uuid:{uuid}")
        if d is not None and _passes(ctx, spec, d):
            keep.append(d)
    if not keep:
        return Candidates.empty()
    return Candidates([d["iri"] for d in keep], np.array([d["center"] for d in keep]),
                      np.array([d["extent"] for d in keep]), np.array([d["last"] for d in keep]))


def _passes(ctx: Context, spec: QuerySpec, d: dict[str, Any]) -> bool:
    until = spec.until_s if spec.until_s is not None else ctx.now_s
    return ((spec.layer is None or d["layer"] == spec.layer) and (spec.state is None or d["state"] == spec.state)
            and (spec.since_s is None or d["last"] >= spec.since_s) and d["first"] <= until
            and d["confidence"] >= spec.min_confidence)


def details(ctx: Context, iri: str) -> dict[str, Any] | None:
    """The graph's record of one instance node (cached per query), None if it has none."""
    if iri in ctx._details:
        return ctx._details[iri]
    rows = ctx.kb.query_bound(template("instance"), {"i": ox.NamedNode(iri)})
    if not rows:
        return None
    r = rows[0]
    d = {
        "iri": iri, "uuid": r["uuid"].value, "class": r["class"].value,
        "layer": r["layer"].value.rsplit("#", 1)[-1],
        "first": float(r["first"].value), "last": float(r["last"].value), "state": r["state"].value,
        "confidence": float(r["confidence"].value), "center": geo.parse_vector(r["center"].value),
        "extent": geo.parse_vector(r["extent"].value), "count": int(r["count"].value),
        "speed": float(r["speed"].value) if "speed" in r else None,
    }
    ctx._details[iri] = d
    return d


def supports(ctx: Context, class_name: str) -> Candidates:
    """Every instance of a support class (e.g. the tables), cached per query."""
    if class_name not in ctx._supports:
        spec = QuerySpec(classes=(class_name,), until_s=_FAR_S)
        ctx._supports[class_name] = prefilter(ctx, spec)
    return ctx._supports[class_name]


def _spatial_box(ctx: Context, spec: QuerySpec) -> tuple[np.ndarray, np.ndarray] | None:
    """An axis-aligned map box that holds every possible answer of a spatial query."""
    p = np.array([ctx.reference.x_m, ctx.reference.y_m, ctx.reference.z_m])
    big = 1.0e6
    if spec.near is not None and spec.near.target == "me":
        r = spec.near.radius_m
        return np.array([p[0] - r, p[1] - r, -big]), np.array([p[0] + r, p[1] + r, big])
    if spec.in_fov:
        r = ctx.config.frustum.range_m
        return p - r, p + r
    if spec.on is not None:
        sup = _support_targets(ctx, spec)
        if len(sup) == 0:
            return np.zeros(3), np.zeros(3) - 1.0  # empty box
        lo = (sup.centers - sup.extents / 2.0).min(axis=0)
        hi = (sup.centers + sup.extents / 2.0).max(axis=0)
        return lo - [0.1, 0.1, 0.0], hi + [0.1, 0.1, 2.5]
    return None


def _support_targets(ctx: Context, spec: QuerySpec) -> Candidates:
    assert spec.on is not None
    sup = supports(ctx, spec.on.class_name)
    if spec.on.closest and len(sup):
        d = geo.footprint_distance_m(ctx.xy, sup.centers, sup.extents)
        sup = sup.take([int(np.argmin(d))])
    return sup


def _spatial_mask(ctx: Context, spec: QuerySpec, cands: Candidates) -> np.ndarray:
    mask = np.ones(len(cands), dtype=bool)
    if spec.in_fov:
        mask &= geo.in_frustum(ctx.T_map_cam, cands.centers, ctx.config.frustum)
    if spec.near is not None:
        if spec.near.target == "me":
            mask &= geo.footprint_distance_m(ctx.xy, cands.centers, cands.extents) <= spec.near.radius_m
        else:
            others = supports(ctx, spec.near.target)
            near = np.zeros(len(cands), dtype=bool)
            for k in range(len(others)):
                gap = geo.box_gap_m(cands.centers, cands.extents, others.centers[k], others.extents[k])
                near |= (gap <= spec.near.radius_m) & (np.array(cands.iris) != others.iris[k])
            mask &= near
    if spec.on is not None:
        on = np.zeros(len(cands), dtype=bool)
        sup = _support_targets(ctx, spec)
        for k in range(len(sup)):
            on |= geo.standing_on(cands.centers, cands.extents, sup.centers[k], sup.extents[k],
                                  ctx.config.support_gap_m, ctx.config.support_margin_m)
        mask &= on
    return mask


def select(ctx: Context, spec: QuerySpec) -> Candidates:
    """The instances answering ``spec``, sorted and limited (no details fetched yet)."""
    box = _spatial_box(ctx, spec) if not spec.classes else None
    cands = prefilter(ctx, spec, box)
    cands = cands.take(_spatial_mask(ctx, spec, cands))
    order = np.arange(len(cands))
    if spec.sort in (None, "distance"):
        order = np.argsort(geo.footprint_distance_m(ctx.xy, cands.centers, cands.extents), kind="stable")
    elif spec.sort == "last_seen":
        order = np.argsort(-cands.last_s, kind="stable")
    cands = cands.take(order)
    if spec.sort in ("first_seen", "confidence"):
        key = "first" if spec.sort == "first_seen" else "confidence"
        rows = [details(ctx, i) for i in cands.iris]
        index = sorted(range(len(rows)), key=lambda k: (rows[k] or {}).get(key, 0.0),
                       reverse=spec.sort == "confidence")
        cands = cands.take(np.array(index, dtype=int))
    if spec.limit is not None:
        cands = cands.take(np.arange(min(spec.limit, len(cands))))
    return cands


def support_of(ctx: Context, center: np.ndarray, extent: np.ndarray, own_iri: str) -> Support | None:
    """The support instance an object stands on, else the floor when its bottom is near the
    floor's top, else None."""
    cfg = ctx.config
    for class_name in cfg.support_classes:
        sup = supports(ctx, class_name)
        for k in range(len(sup)):
            if sup.iris[k] != own_iri and geo.standing_on(center[None], extent[None], sup.centers[k],
                                                         sup.extents[k], cfg.support_gap_m,
                                                         cfg.support_margin_m)[0]:
                return Support(class_name, sup.iris[k].removeprefix("urn:uuid:"))
    floors = supports(ctx, "floor")
    floor_top = float((floors.centers[:, 2] + floors.extents[:, 2] / 2).max()) if len(floors) else 0.0
    if abs(center[2] - extent[2] / 2.0 - floor_top) <= cfg.support_gap_m and own_iri not in floors.iris:
        uuid = floors.iris[0].removeprefix("urn:uuid:") if len(floors) else None
        return Support("floor", uuid)
    return None


def hits(ctx: Context, cands: Candidates, *, evidence: bool = True) -> list[Hit]:
    """Typed hits with details, distance, support and (``evidence``) observation uuids."""
    rows = [details(ctx, iri) for iri in cands.iris]
    found = [r for r in rows if r is not None]
    links = ctx.kb.observation_uuids_of([r["uuid"] for r in found]) if evidence and found else {}
    out = []
    for r in found:
        c, e = np.array(r["center"]), np.array(r["extent"])
        dist = float(geo.footprint_distance_m(ctx.xy, c[None], e[None])[0])
        out.append(Hit(
            uuid=r["uuid"], class_name=r["class"], layer=r["layer"], center_map_m=r["center"],
            extent_m=r["extent"], first_seen_s=r["first"], last_seen_s=r["last"],
            observation_count=r["count"], confidence=r["confidence"], state=r["state"],
            speed_mps=r["speed"], distance_m=round(dist, 4),
            support=support_of(ctx, c, e, r["iri"]) if r["layer"] == "foreground" else None,
            evidence_uuids=tuple(links.get(r["uuid"], ())),
        ))
    return out
