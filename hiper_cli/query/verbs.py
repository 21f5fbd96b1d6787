"""The query verbs of the library, the same ones the CLI, the grammar and (later) the MCP tools
use: ``find``, ``count``, ``last_seen``, ``when``, ``passes``/``passed_here``, ``trajectory``.

Each takes the knowledge base, what to look for (a class name or words such as "mugs",
"people", "objects"), filters, and where the query is asked from (``pose`` x, y, z, yaw, or
the robot's pose at ``at_s``; ``now_s`` defaults to the KB's last stamp).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from hiper_cli.errors import QueryError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query import engine
from hiper_cli.query.engine import Context, make_context
from hiper_cli.query.results import Hit, Sighting, Trajectory
from hiper_cli.query.spec import Near, On, QueryConfig, QuerySpec
from hiper_cli.query.vocabulary import ANY_FOREGROUND, CLASS_NAMES, resolve_class

__all__ = ["count", "find", "last_seen", "passed_here", "passes", "spec_for", "trajectory", "when"]

Pose = tuple[float, float, float, float]


def _classes(what: str | None) -> tuple[tuple[str, ...], str | None]:
    """(classes, layer) for a class name or words; () = any class."""
    if what is None:
        return (), None
    name = resolve_class(what)
    if name is None:
        raise QueryError(
            f"unknown class {what!r}; expected a COCO or hiper class such as "
            f"{', '.join(CLASS_NAMES[:6])}, ... (plurals and synonyms like 'mugs' work)"
        )
    return ((), "foreground") if name == ANY_FOREGROUND else ((name,), None)


def spec_for(
    what: str | None = None,
    *,
    near: str | None = None,
    radius_m: float | None = None,
    in_fov: bool = False,
    on: str | None = None,
    on_closest: bool = False,
    since_s: float | None = None,
    until_s: float | None = None,
    state: str | None = None,
    min_confidence: float = 0.0,
    sort: str | None = None,
    limit: int | None = None,
    config: QueryConfig | None = None,
) -> QuerySpec:
    """The ``QuerySpec`` of the verbs' keyword arguments (``near`` "me" or class words)."""
    cfg = config or QueryConfig()
    classes, layer = _classes(what)
    near_spec = None
    if near is not None or radius_m is not None:
        target = "me" if near in (None, "me", "here") else _classes(near)[0]
        if not isinstance(target, str) and not target:
            raise QueryError(f"near {near!r}: name one class (e.g. 'table') or 'me'")
        near_spec = Near(
            target if isinstance(target, str) else target[0],
            cfg.near_radius_m if radius_m is None else float(radius_m),
        )
    on_spec = None
    if on is not None:
        on_classes = _classes(on)[0]
        if len(on_classes) != 1:
            raise QueryError(f"on {on!r}: name one support class, e.g. 'table'")
        on_spec = On(on_classes[0], on_closest)
    if state == "moving":
        state = "dynamic"
    return QuerySpec(
        classes=classes,
        layer=layer,
        state=state,
        since_s=since_s,
        until_s=until_s,
        min_confidence=min_confidence,
        in_fov=in_fov,
        near=near_spec,
        on=on_spec,
        sort=sort,
        limit=limit,
    )


def _context(
    kb: KnowledgeBase, pose: Pose | None, at_s: float | None, now_s: float | None, config: QueryConfig | None
) -> Context:
    return make_context(kb, pose=pose, at_s=at_s, now_s=now_s, config=config)


def find(
    kb: KnowledgeBase,
    what: str | None = None,
    *,
    pose: Pose | None = None,
    at_s: float | None = None,
    now_s: float | None = None,
    config: QueryConfig | None = None,
    evidence: bool = True,
    **filters: Any,
) -> list[Hit]:
    """The instances matching ``what`` and the filters of ``spec_for`` (near, radius_m,
    in_fov, on, on_closest, since_s, until_s, state, min_confidence, sort, limit), nearest
    first unless ``sort`` says otherwise."""
    ctx = _context(kb, pose, at_s, now_s, config)
    spec = spec_for(what, config=ctx.config, **filters)
    return engine.hits(ctx, engine.select(ctx, spec), evidence=evidence)


def count(
    kb: KnowledgeBase,
    what: str | None = None,
    *,
    pose: Pose | None = None,
    at_s: float | None = None,
    now_s: float | None = None,
    config: QueryConfig | None = None,
    **filters: Any,
) -> int:
    """How many instances ``find`` would return (without fetching their details)."""
    ctx = _context(kb, pose, at_s, now_s, config)
    return len(engine.select(ctx, spec_for(what, config=ctx.config, **filters)))


def last_seen(
    kb: KnowledgeBase,
    what: str,
    *,
    pose: Pose | None = None,
    at_s: float | None = None,
    now_s: float | None = None,
    config: QueryConfig | None = None,
    **filters: Any,
) -> Hit | None:
    """The most recently seen instance of ``what`` (None when there is none)."""
    found = find(
        kb,
        what,
        pose=pose,
        at_s=at_s,
        now_s=now_s,
        config=config,
        **{**filters, "sort": "last_seen", "limit": 1},
    )
    return found[0] if found else None


def _in_view_s(stamps: list[float], gap_s: float) -> float:
    if len(stamps) < 2:
        return 0.0
    dt = np.diff(np.asarray(stamps))
    return float(dt[dt <= gap_s].sum())


def when(
    kb: KnowledgeBase, uuid: str, *, now_s: float | None = None, config: QueryConfig | None = None
) -> Sighting:
    """First and last sighting and time in view of one instance."""
    ctx = _context(kb, None, None, now_s, config)
    d = engine.details(ctx, uuid)
    if d is None:
        raise QueryError(
            f"no instance {uuid!r} in {kb.location}; list them with 'hiper query objects --json'"
        )
    stamps = kb.observation_stamps_of(uuid)
    return Sighting(
        uuid,
        d["class"],
        d["first"],
        d["last"],
        _in_view_s(stamps, ctx.config.view_gap_s),
        d["count"],
        ctx.now_s,
    )


def passes(ctx: Context, spec: QuerySpec, sighting: str = "last") -> list[tuple[float, str]]:
    """The instances of ``spec`` observed within ``spec.near`` (default: the config's
    ``pass_radius_m`` of the reference position) horizontally, in ``spec``'s time window: near
    the reference position when the target is "me", else near the footprint of any instance of
    the target class (the target's own observations aside). One (stamp, uuid) per instance,
    its last time there (``sighting`` "first": its first), latest (earliest) first."""
    r = spec.near.radius_m if spec.near is not None else ctx.config.pass_radius_m
    target = spec.near.target if spec.near is not None else "me"
    if target == "me":
        places = [(np.array([ctx.reference.x_m, ctx.reference.y_m]), np.zeros(2))]
        own: set[str] = set()
    else:
        sup = engine.supports(ctx, target)
        places = [(sup.centers[k, :2], sup.extents[k, :2]) for k in range(len(sup))]
        own = set(sup.uuids)
    unwindowed = replace(spec, since_s=None, until_s=None, change=None, near=None, passed_here=False)
    allowed = set(engine.prefilter(ctx, unwindowed).uuids) - own
    until = spec.until_s if spec.until_s is not None else ctx.now_s
    since = spec.since_s if spec.since_s is not None else -np.inf
    best: dict[str, float] = {}
    for center, extent in places:
        lo, hi = center - extent / 2.0 - r, center + extent / 2.0 + r
        for class_name in spec.classes or (None,):
            for p in ctx.kb.observations_near((lo[0], lo[1], -1e6), (hi[0], hi[1], 1e6), class_name):
                if p.instance_uuid not in allowed or not since <= p.stamp_s <= until:
                    continue
                gap = np.maximum(np.abs(np.asarray(p.center_map_m[:2]) - center) - extent / 2.0, 0.0)
                if float(np.hypot(*gap)) > r:
                    continue
                held = best.get(p.instance_uuid)
                if held is None or (p.stamp_s > held if sighting == "last" else p.stamp_s < held):
                    best[p.instance_uuid] = p.stamp_s
    found = sorted(((stamp, uuid) for uuid, stamp in best.items()), reverse=sighting == "last")
    return found


def passed_here(ctx: Context, spec: QuerySpec, sighting: str = "last") -> tuple[float, Hit] | None:
    """The latest (``sighting`` "first": the earliest) of ``passes``, with its instance."""
    found = passes(ctx, spec, sighting)
    if not found:
        return None
    hits = engine.hits(ctx, engine.candidates_of(ctx, [found[0][1]]))
    return (found[0][0], hits[0]) if hits else None


def trajectory(kb: KnowledgeBase, uuid: str) -> Trajectory:
    """The map-frame track of one instance (empty for background instances)."""
    inst = kb.instance(uuid)
    if inst is None:
        raise QueryError(
            f"no instance {uuid!r} in {kb.location}; list them with 'hiper query objects --json'"
        )
    rows = inst.data.get("trajectory") or []
    return Trajectory(uuid, inst.class_name, tuple(tuple(float(v) for v in row) for row in rows))
