"""``ask``: answer a plain-words query with a typed ``Answer`` (the engine behind
``hiper query "..."``)."""

from __future__ import annotations

import functools

import numpy as np

from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query import engine, history
from hiper_cli.query import geometry as geo
from hiper_cli.query.engine import Context, make_context
from hiper_cli.query.grammar import ParsedQuery, parse, with_limit
from hiper_cli.query.results import Answer, AnswerKind, GoalPose, Hit, TimeValue, ago_text
from hiper_cli.query.spec import QueryConfig
from hiper_cli.query.verbs import passed_here, when
from hiper_cli.query.vocabulary import plural

__all__ = ["answer", "ask", "goal_for"]


def goal_for(ctx: Context, hit: Hit) -> GoalPose:
    """A nav2 goal ``goal_standoff_m`` in front of the hit, on the side of the reference
    pose, facing the hit."""
    x, y, yaw = geo.goal_in_front(
        np.array(hit.center_map_m), np.array(hit.extent_m), ctx.xy, ctx.config.goal_standoff_m
    )
    return GoalPose(round(x, 4), round(y, 4), round(yaw, 4), hit.uuid)


def _describe(hit: Hit, now_s: float) -> str:
    x, y, z = hit.center_map_m
    return (
        f"{hit.class_name} at ({x:.2f}, {y:.2f}, {z:.2f}) m, {hit.distance_m:.1f} m away, "
        f"last seen {ago_text(hit.last_seen_s, now_s)}"
    )


def answer(ctx: Context, parsed: ParsedQuery) -> Answer:
    """The answer to a parsed query in a context (reference pose, now)."""
    spec = parsed.spec
    kind: AnswerKind = parsed.answer  # type: ignore[assignment]
    make = functools.partial(Answer, kind, parsed.text, ctx.now_s, ctx.reference, parsed=parsed.to_dict())
    def what(n: int) -> str:
        """The classes asked about, in words for ``n`` of them: "cup", "cups, bottles"."""
        names = list(spec.classes) or ["object" if spec.layer == "foreground" else "instance"]
        return ", ".join(c if n == 1 else plural(c) for c in names)

    if spec.passed_here:
        found = passed_here(ctx, spec)
        r = spec.near.radius_m if spec.near is not None else ctx.config.pass_radius_m
        if found is None:
            return make(value=False if kind == "yes_no" else None,
                        text=f"no {what(0)} observed within {r:g} m of here")
        stamp, hit = found
        return make(
            hits=(hit,),
            time=TimeValue(stamp, ctx.now_s),
            value=True if kind == "yes_no" else None,
            text=f"{hit.class_name} last passed within {r:g} m of here {ago_text(stamp, ctx.now_s)}",
        )
    cands = engine.select(ctx, spec)
    if kind == "count":
        return make(count=len(cands), text=f"{len(cands)} {what(len(cands))}")
    if kind == "yes_no":
        shown = engine.hits(ctx, cands.take(np.arange(min(5, len(cands)))))
        return make(
            value=len(cands) > 0,
            hits=tuple(shown),
            text=("yes: " + "; ".join(_describe(h, ctx.now_s) for h in shown)) if shown else "no",
        )
    total = len(cands)
    found_hits = engine.hits(ctx, cands.take(np.arange(min(total, ctx.config.max_hits))))
    if not found_hits:
        return make(count=0, text=f"no {what(0)} found")
    first = found_hits[0]
    if kind == "time":
        stamp = first.first_seen_s if parsed.time_of == "first" else first.last_seen_s
        return make(
            hits=tuple(found_hits),
            time=TimeValue(stamp, ctx.now_s),
            text=f"{first.class_name} {parsed.time_of} seen {ago_text(stamp, ctx.now_s)}",
        )
    if kind == "duration":
        seen = when(ctx.kb, first.uuid, now_s=ctx.now_s, config=ctx.config)
        return make(
            hits=tuple(found_hits),
            duration_s=seen.time_in_view_s,
            text=f"{first.class_name} in view for {seen.time_in_view_s:.1f} s",
        )
    if kind in ("location", "goal"):
        goal = goal_for(ctx, first)
        text = (
            _describe(first, ctx.now_s) + f"; goal ({goal.x_m:.2f}, {goal.y_m:.2f}, yaw {goal.yaw_rad:.2f})"
        )
        return make(hits=tuple(found_hits), goal=goal, text=text)
    text = f"{total} {what(total)}: " + "; ".join(_describe(h, ctx.now_s) for h in found_hits[:3])
    if total > 3:
        text += f"; +{total - 3} more" + (f" ({len(found_hits)} listed)" if total > len(found_hits) else "")
    nearest = goal_for(ctx, first) if spec.sort == "distance" and spec.limit == 1 else None
    return make(hits=tuple(found_hits), count=total, goal=nearest, text=text)


def ask(
    kb: KnowledgeBase,
    text: str,
    *,
    pose: tuple[float, float, float, float] | None = None,
    at_s: float | None = None,
    now_s: float | None = None,
    limit: int | None = None,
    config: QueryConfig | None = None,
) -> Answer:
    """Parse ``text`` and answer it from ``pose`` (x, y, z, yaw) or the robot's pose at
    ``at_s`` (default: its last); relative times count back from ``now_s`` (default: ``at_s``,
    else the KB's last stamp)."""
    ctx = make_context(kb, pose=pose, at_s=at_s, now_s=now_s, config=config)
    change = history.match(text)  # questions about change: query/history.py
    if change is not None:
        return history.answer_change(ctx, change, text)
    return answer(ctx, with_limit(parse(text, now_s=ctx.now_s, config=ctx.config), limit))
