"""How a ``QuerySpec`` is answered: the non-spatial filters over the instance summaries that
the named SPARQL query ``queries/instances.rq`` returned (``index.py``, one read per graph
version), then the exact geometry in numpy (``geometry.py``: frustum, distances, support),
then the typed hits with their support and evidence observations (the documents' links).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiper_cli.errors import QueryError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query import geometry as geo
from hiper_cli.query.index import InstanceIndex, instance_index
from hiper_cli.query.results import Hit, ReferencePose, Support
from hiper_cli.query.spec import QueryConfig, QuerySpec

__all__ = ["Candidates", "Context", "candidates_of", "details", "hits", "make_context", "prefilter", "select"]


@dataclass
class Context:
    """One query's surroundings: the KB, ``now`` (s), the reference pose and the config.
    ``index`` holds the KB's instance summaries (``index.py``)."""

    kb: KnowledgeBase
    now_s: float
    reference: ReferencePose
    config: QueryConfig
    index: InstanceIndex

    def row_of(self, uuid: str) -> int | None:
        return self.index.row_numbers.get(uuid)

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
            ref = ReferencePose(
                float(p[0]),
                float(p[1]),
                float(p[2]),
                robot.yaw_rad,
                robot.stamp_s,
                "robot",
                tuple(tuple(r) for r in robot.T_map_cam.tolist()),
            )
    return Context(kb, float(now_s), ref, config or QueryConfig(), instance_index(kb))


@dataclass
class Candidates:
    """A subset of the instance index: row numbers (N,) with their boxes (N, 3) and last
    sightings (N,) at hand for the geometry."""

    index: InstanceIndex
    rows: np.ndarray

    @property
    def centers(self) -> np.ndarray:
        values: np.ndarray = self.index.centers[self.rows]
        return values

    @property
    def extents(self) -> np.ndarray:
        values: np.ndarray = self.index.extents[self.rows]
        return values

    @property
    def last_s(self) -> np.ndarray:
        values: np.ndarray = self.index.last_s[self.rows]
        return values

    @property
    def uuids(self) -> list[str]:
        return [self.index.uuids[k] for k in self.rows]

    def take(self, mask_or_index: Any) -> Candidates:
        return Candidates(self.index, self.rows[np.asarray(mask_or_index)])

    def __len__(self) -> int:
        return len(self.rows)


def prefilter(ctx: Context, spec: QuerySpec) -> Candidates:
    """The instances passing the non-spatial filters of ``spec`` (class, layer, state, time
    window, confidence). An instance whose place a later session saw empty (``vacated_s``)
    was there until then: a window starting (or, without a start, ending) later leaves it out."""
    idx = ctx.index
    mask = _window_mask(ctx, spec) & (idx.confidence >= spec.min_confidence)
    if spec.classes:
        mask &= np.isin(idx.classes, list(spec.classes))
    if spec.layer is not None:
        mask &= idx.layers == spec.layer
    if spec.state is not None:
        mask &= idx.states == spec.state
    return Candidates(idx, np.flatnonzero(mask))


def _window_mask(ctx: Context, spec: QuerySpec) -> np.ndarray:
    """Seen at some time in [since, until] and not vacated by then; for a change, the change
    in the window: first seen in it ("added"), vacated in it ("removed"), moving while seen
    in it ("moved"), or any of these ("any")."""
    idx = ctx.index
    until = spec.until_s if spec.until_s is not None else ctx.now_s
    since = spec.since_s if spec.since_s is not None else -np.inf
    removed = (idx.vacated_s >= since) & (idx.vacated_s <= until) & (idx.first_s <= until)
    if spec.change == "removed":
        return removed
    mask = (idx.first_s <= until) & (idx.last_s >= since)
    mask &= idx.vacated_s > (spec.since_s if spec.since_s is not None else until)
    added, moved = mask & (idx.first_s >= since), mask & (idx.states == "dynamic")
    masks: dict[str, np.ndarray] = {"added": added, "moved": moved, "any": added | moved | removed}
    return masks.get(spec.change or "", mask)


def details(ctx: Context, uuid: str) -> dict[str, Any] | None:
    """The summary of one instance (None when the graph has no such instance)."""
    k = ctx.row_of(uuid)
    return None if k is None else ctx.index.row(k)


def supports(ctx: Context, class_name: str) -> Candidates:
    """Every instance of a support class (e.g. the tables), seen at any time."""
    return Candidates(ctx.index, np.flatnonzero(ctx.index.classes == class_name))


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
            centers, extents = cands.centers, cands.extents
            for k, row in enumerate(others.rows):
                gap = geo.box_gap_m(centers, extents, others.centers[k], others.extents[k])
                near |= (gap <= spec.near.radius_m) & (cands.rows != row)
            mask &= near
    if spec.on is not None:
        on = np.zeros(len(cands), dtype=bool)
        sup = _support_targets(ctx, spec)
        centers, extents = cands.centers, cands.extents
        for k in range(len(sup)):
            on |= geo.standing_on(
                centers,
                extents,
                sup.centers[k],
                sup.extents[k],
                ctx.config.support_gap_m,
                ctx.config.support_margin_m,
            )
        mask &= on & ~np.isin(cands.rows, sup.rows)
    return mask


def select(ctx: Context, spec: QuerySpec) -> Candidates:
    """The instances answering ``spec``, sorted (nearest first unless ``spec.sort`` says
    otherwise) and limited."""
    cands = prefilter(ctx, spec)
    cands = cands.take(_spatial_mask(ctx, spec, cands))
    idx = ctx.index
    # Ties (two cups last seen in one frame) go to the nearer, then the later seen, never to
    # the index's order (uuids): the same question gets the same answer in every run.
    if spec.rank_from is not None:
        cands, distance_m = _distances_from(ctx, cands, spec.rank_from)
    else:
        distance_m = geo.footprint_distance_m(ctx.xy, cands.centers, cands.extents)
    if spec.sort in (None, "distance"):
        order = np.lexsort((-cands.last_s, distance_m))
    elif spec.sort == "last_seen":
        order = np.lexsort((distance_m, -cands.last_s))
    elif spec.sort == "first_seen":
        order = np.lexsort((distance_m, idx.first_s[cands.rows]))
    else:
        order = np.lexsort((distance_m, -idx.confidence[cands.rows]))
    cands = cands.take(order)
    if spec.limit is not None:
        cands = cands.take(np.arange(min(spec.limit, len(cands))))
    return cands


def _distances_from(ctx: Context, cands: Candidates, class_name: str) -> tuple[Candidates, np.ndarray]:
    """The candidates other than the instances of ``class_name``, and each one's horizontal
    gap (m) to the nearest of those instances (inf when there is none)."""
    targets = supports(ctx, class_name)
    cands = cands.take(~np.isin(cands.rows, targets.rows))
    gap_m = np.full(len(cands), np.inf)
    for k in range(len(targets)):
        lo, hi = cands.centers[:, :2], targets.centers[k, :2]
        gap = np.maximum(np.abs(lo - hi) - (cands.extents[:, :2] + targets.extents[k, :2]) / 2.0, 0.0)
        gap_m = np.minimum(gap_m, np.linalg.norm(gap, axis=1))
    return cands, gap_m


def supports_of(ctx: Context, cands: Candidates) -> list[Support | None]:
    """What each candidate stands on: a support instance (``config.support_classes``), else
    the floor when its bottom is near the floor's top, else None."""
    cfg, idx = ctx.config, ctx.index
    out: list[Support | None] = [None] * len(cands)
    centers, extents = cands.centers, cands.extents
    for class_name in cfg.support_classes:
        sup = supports(ctx, class_name)
        on = geo.standing_on_any(
            centers, extents, sup.centers, sup.extents, cfg.support_gap_m, cfg.support_margin_m
        ) & (cands.rows[:, None] != sup.rows[None, :])
        for n, s in zip(*np.nonzero(on), strict=True):
            if out[n] is None:
                out[n] = Support(class_name, idx.uuids[sup.rows[s]])
    floors = supports(ctx, "floor")
    floor_top = float((floors.centers[:, 2] + floors.extents[:, 2] / 2).max()) if len(floors) else 0.0
    bottoms = centers[:, 2] - extents[:, 2] / 2.0 if len(cands) else np.zeros(0)
    for n in range(len(cands)):
        if (
            out[n] is None
            and abs(bottoms[n] - floor_top) <= cfg.support_gap_m
            and cands.rows[n] not in floors.rows
        ):
            out[n] = Support("floor", idx.uuids[floors.rows[0]] if len(floors) else None)
    return out


def hits(ctx: Context, cands: Candidates, *, evidence: bool = True) -> list[Hit]:
    """Typed hits with summary, distance, support and (``evidence``) observation uuids."""
    links = ctx.kb.observation_uuids_of(cands.uuids) if evidence and len(cands) else {}
    dists = geo.footprint_distance_m(ctx.xy, cands.centers, cands.extents)
    layers = ctx.index.layers[cands.rows]
    fg = np.flatnonzero(layers == "foreground")
    support: list[Support | None] = [None] * len(cands)
    for n, s in zip(fg.tolist(), supports_of(ctx, cands.take(fg)), strict=True):
        support[n] = s
    out = []
    for n, (row, dist) in enumerate(zip(cands.rows.tolist(), dists.tolist(), strict=True)):
        r = ctx.index.row(row)
        out.append(
            Hit(
                uuid=r["uuid"],
                class_name=r["class"],
                layer=r["layer"],
                center_map_m=r["center"],
                extent_m=r["extent"],
                first_seen_s=r["first"],
                last_seen_s=r["last"],
                observation_count=r["count"],
                confidence=r["confidence"],
                state=r["state"],
                speed_mps=r["speed"],
                distance_m=round(dist, 4),
                support=support[n],
                evidence_uuids=tuple(links.get(r["uuid"], ())),
            )
        )
    return out


def candidates_of(ctx: Context, uuids: list[str]) -> Candidates:
    """The candidates for known instance uuids (unknown ones dropped)."""
    rows = [k for u in uuids if (k := ctx.row_of(u)) is not None]
    return Candidates(ctx.index, np.array(rows, dtype=np.int64))
