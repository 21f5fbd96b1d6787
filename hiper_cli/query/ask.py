"""``ask``: answer a plain-words query with a typed ``Answer`` (the engine behind
``hiper query "..."``)."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable

import numpy as np

from hiper_cli.errors import QueryError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query import engine, history
from hiper_cli.query import geometry as geo
from hiper_cli.query.engine import Context, make_context
from hiper_cli.query.grammar import ParsedQuery, parse, with_limit
from hiper_cli.query.results import Answer, AnswerKind, GoalPose, Hit, TimeValue, ago_text
from hiper_cli.query.spec import QueryConfig
from hiper_cli.query.timewords import TimeAnchor, TimeWindow
from hiper_cli.query.verbs import passes, when
from hiper_cli.query.vocabulary import plural

__all__ = ["answer", "ask", "goal_for", "resolve_events"]


def _changed(n: int, names: str, change: str) -> str:
    """A change answer's words: "2 new chairs", "nothing moved", "1 cup gone"."""
    if n == 0 and names in ("instances", "objects"):
        return {"added": "nothing new"}.get(change, f"nothing {_CHANGED[change]}")
    if change == "added":
        return f"{n or 'no'} new {names}"
    return f"{n or 'no'} {names} {_CHANGED[change]}"


_CHANGED = {"added": "new", "removed": "gone", "moved": "moved", "any": "changed"}


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


def _passed(
    ctx: Context, parsed: ParsedQuery, make: Callable[..., Answer], what: Callable[[int], str]
) -> Answer:
    """The answer to "when did X pass|enter|leave Y", "did anyone pass here", "how many
    people passed by": from the observations near the target (``verbs.passes``)."""
    spec, kind = parsed.spec, parsed.answer
    r = spec.near.radius_m if spec.near is not None else ctx.config.pass_radius_m
    place = "here" if spec.near is None or spec.near.target == "me" else f"the {spec.near.target}"
    found = passes(ctx, spec, parsed.time_of)
    if kind == "count":
        return make(count=len(found), text=f"{len(found)} {what(len(found))} within {r:g} m of {place}")
    if not found:
        return make(value=False if kind == "yes_no" else None, count=0 if kind == "list" else None,
                    text=f"no {what(0)} observed within {r:g} m of {place}")
    uuids = [uuid for _stamp, uuid in found][: ctx.config.max_hits]
    hits = engine.hits(ctx, engine.candidates_of(ctx, uuids))
    stamp, hit = found[0][0], hits[0]
    verb = "first came" if parsed.time_of == "first" else "last passed"
    return make(
        hits=tuple(hits) if kind == "list" else (hit,),
        count=len(found) if kind == "list" else None,
        time=TimeValue(stamp, ctx.now_s),
        value=True if kind == "yes_no" else None,
        text=f"{hit.class_name} {verb} within {r:g} m of {place} {ago_text(stamp, ctx.now_s)}",
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
        return _passed(ctx, parsed, make, what)
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
    if spec.change is not None and (kind == "list" or not found_hits):
        text = _changed(total, what(total), spec.change)
        text += (": " + "; ".join(_describe(h, ctx.now_s) for h in found_hits[:3])) if found_hits else ""
        text += f"; +{total - 3} more" if total > 3 else ""
        return make(hits=tuple(found_hits), count=total, text=text)
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
    # Change words read the memory's change events (query/history.py) once it has any; a memory
    # of one log has none, and there they mean what was seen moving, appearing or leaving.
    change = history.match(text)
    if change is not None and (change.intent != "changes" or kb.changes()):
        return history.answer_change(ctx, change, text)
    envs = kb.environments()
    whole = [envs[0].name] if len(envs) == 1 else []  # "in the house": the KB's one place
    parsed = with_limit(parse(text, now_s=ctx.now_s, config=ctx.config, whole_place=whole), limit)
    return answer(ctx, resolve_events(ctx, parsed))


def _event_stamp(ctx: Context, anchor: TimeAnchor) -> float:
    """The stamp of an event: the earliest first sighting or the latest last sighting (up to
    now) of the anchor's class."""
    idx = ctx.index
    rows = np.flatnonzero((idx.classes == anchor.class_name) & (idx.first_s <= ctx.now_s))
    if len(rows) == 0:
        raise QueryError(
            f'no {anchor.class_name} was seen by {ctx.now_s:g} s, so "{anchor.words()}" names no time; '
            "ask without it, or with a clock time such as 'since 10:00'"
        )
    if anchor.sighting == "first":
        return float(idx.first_s[rows].min())
    return float(np.minimum(idx.last_s[rows], ctx.now_s).max())


def resolve_events(ctx: Context, parsed: ParsedQuery) -> ParsedQuery:
    """``parsed`` with its event bounds ("after the person left") turned into stamps."""
    if parsed.since_event is None and parsed.until_event is None:
        return parsed
    window = TimeWindow(parsed.spec.since_s, parsed.spec.until_s)
    if parsed.since_event is not None:
        window = window & TimeWindow(_event_stamp(ctx, parsed.since_event), None)
    if parsed.until_event is not None:
        window = window & TimeWindow(None, _event_stamp(ctx, parsed.until_event))
    if window.since_s is not None and window.until_s is not None and window.since_s > window.until_s:
        raise QueryError(f'"{parsed.text}": the time window starts after it ends; nothing can be in it')
    spec = dataclasses.replace(parsed.spec, since_s=window.since_s, until_s=window.until_s)
    return dataclasses.replace(parsed, spec=spec)
