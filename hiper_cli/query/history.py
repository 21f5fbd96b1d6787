"""Questions about change, answered from the change events and the instances' validity
(``graph/history.py``): "what changed since 10:00", "what moved today", "what is missing",
"what is new", "where is the cup now", "when was the bottle last seen".

``match(text)`` tells whether a question is one of these (``ask`` tries it before the general
grammar); ``answer_change`` answers it. Every answer names the session (its id and log) and
the time of what it reports. Time phrases ("since 10:00", "today", "since yesterday", "in the
last 5 minutes") are read by the general grammar, so both understand the same words. Stamps
are the logs' own: a log stamped from 0 gives "at 12.3 s of its log".
"""

from __future__ import annotations

import datetime
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hiper_cli.errors import QueryError
from hiper_cli.graph.compact import summarised_count
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query.engine import Context
from hiper_cli.query.results import Answer, Hit, TimeValue
from hiper_cli.query.vocabulary import resolve_class

__all__ = ["ChangeQuestion", "answer_change", "match"]

_WHEN = r"(?P<when>(?:\s+.*)?)"
_PATTERNS: tuple[tuple[re.Pattern[str], str, str | None], ...] = (
    (re.compile(r"(?:what|which objects?|anything)\s+(?:has\s+|have\s+)?changed" + _WHEN), "changes", None),
    (re.compile(r"what\s+(?:has\s+|was\s+|got\s+|have\s+)?(?:been\s+)?moved" + _WHEN), "changes", "moved"),
    (re.compile(r"what(?:'s|\s+is|\s+was|\s+has\s+been|\s+went|\s+are)?\s+(?:missing|gone|removed)" + _WHEN),
     "changes", "removed"),
    (re.compile(r"what(?:'s|\s+is|\s+was|\s+has\s+been)?\s+(?:new|added)" + _WHEN), "changes", "added"),
    (re.compile(r"where\s+(?:is|are)\s+(?:the\s+|my\s+|a\s+)?(?P<what>.+?)\s+now"), "where_is", None),
    (re.compile(r"when\s+(?:was|were)\s+(?:the\s+|my\s+|a\s+)?(?P<what>.+?)\s+last\s+seen"),
     "last_seen", None),
)
ABSOLUTE_S = 1e9  # stamps beyond this are Unix times; smaller ones count from a log's start


@dataclass(frozen=True)
class ChangeQuestion:
    intent: str  # changes | where_is | last_seen
    kind: str | None = None  # added | removed | moved (changes); None = every kind
    class_name: str | None = None
    when: str = ""


def match(text: str) -> ChangeQuestion | None:
    """The change question ``text`` asks, or None when it is none of them."""
    t = " ".join(text.strip().lower().rstrip("?!.").split())
    for pattern, intent, kind in _PATTERNS:
        m = pattern.fullmatch(t)
        if m is None:
            continue
        groups = m.groupdict()
        cls = None
        if groups.get("what"):
            cls = resolve_class(groups["what"])
            if cls is None:
                raise QueryError(f"{text!r}: no class {groups['what']!r}; name one such as cup, chair, "
                                 "bottle")
        return ChangeQuestion(intent, kind, cls, (groups.get("when") or "").strip())
    return None


def _since_s(when: str, now_s: float) -> tuple[float | None, float | None]:
    """(since, until) of a time phrase, read by the general grammar."""
    if not when:
        return None, None
    from hiper_cli.query.grammar import parse

    if when in ("since yesterday", "since today"):  # from the start of that day on
        return parse(f"objects {when.removeprefix('since ')}", now_s=now_s).spec.since_s, None
    spec = parse(f"objects {when}", now_s=now_s).spec
    return spec.since_s, spec.until_s


def _clock(stamp_s: float) -> str:
    if stamp_s >= ABSOLUTE_S:
        return datetime.datetime.fromtimestamp(stamp_s, datetime.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    return f"{stamp_s:.1f} s into its log"


def _xyz(v: Any) -> str:
    return "(" + ", ".join(f"{float(c):.2f}" for c in v[:3]) + ")"


class _Sessions:
    """Session names, and wall-clock times for logs stamped from 0 (the session's start plus the
    stamp's offset in its log)."""

    def __init__(self, kb: KnowledgeBase) -> None:
        records = kb.session_records()
        self.logs = {s["id"]: Path(s["log_path"]).name for s in records}
        self.start = {s["id"]: (s["started_s"], s["first_stamp_s"] or 0.0) for s in records}
        ends = [max(s["ended_s"] or s["started_s"], self.time_s(s["id"], s["last_stamp_s"] or 0.0))
                for s in records]
        self.now_s = max(ends) if ends else 0.0

    def name(self, session_id: int) -> str:
        return f"session {session_id} ({self.logs.get(session_id, '?')})"

    def time_s(self, session_id: int, stamp_s: float) -> float:
        if stamp_s >= ABSOLUTE_S or session_id not in self.start:
            return stamp_s
        started, first = self.start[session_id]
        return float(started + (stamp_s - first))

    def when(self, session_id: int, stamp_s: float) -> str:
        if stamp_s >= ABSOLUTE_S:
            return _clock(stamp_s)
        return f"{_clock(stamp_s)} ({_clock(self.time_s(session_id, stamp_s))})"


def _hit(ctx: Context, uuid: str) -> Hit | None:
    inst = ctx.kb.instance(uuid)
    if inst is None:
        return None
    c = [round(float(v), 4) for v in inst.box.center_m]
    dist = float(((c[0] - ctx.xy[0]) ** 2 + (c[1] - ctx.xy[1]) ** 2) ** 0.5)
    return Hit(uuid=inst.uuid, class_name=inst.class_name, layer=inst.layer, center_map_m=(c[0], c[1], c[2]),
               extent_m=tuple(float(v) for v in inst.box.extent_m),  # type: ignore[arg-type]
               first_seen_s=inst.first_seen_s, last_seen_s=inst.last_seen_s,
               observation_count=len(inst.observation_uuids) + summarised_count(inst.to_dict()),
               confidence=inst.confidence, state=inst.state,
               speed_mps=None, distance_m=round(dist, 4))


def _change_text(c: dict[str, Any], sessions: _Sessions) -> str:
    where = {"moved": f"from {_xyz(c['from_m'] or [])} to {_xyz(c['to_m'] or [])}",
             "removed": f"from {_xyz(c['from_m'] or [])}", "added": f"at {_xyz(c['to_m'] or [])}"}[c["kind"]]
    session = int(c["session"])
    at = sessions.when(session, c["stamp_s"])
    return f"{c['class']} {c['kind']} {where} m in {sessions.name(session)} at {at}"


def _changes(ctx: Context, q: ChangeQuestion, query: str) -> Answer:
    sessions = _Sessions(ctx.kb)
    now_s = ctx.now_s if ctx.now_s >= ABSOLUTE_S else sessions.now_s  # logs from 0: the clock of the runs
    since, until = _since_s(q.when, now_s)
    found = []
    for c in sorted(ctx.kb.changes(), key=lambda c: (c["session"], c["stamp_s"])):
        t = sessions.time_s(int(c["session"]), c["stamp_s"])
        in_window = (since is None or t >= since) and (until is None or t <= until)
        if (q.kind is None or c["kind"] == q.kind) and in_window:
            found.append(c | {"time_s": t})
    if q.kind == "removed":  # missing now: not found again since
        found = [c for c in found if (inst := ctx.kb.instance(c["instance_uuid"])) is not None
                 and inst.data.get("vacated_s") is not None]
    hits = [h for c in found if (h := _hit(ctx, c["instance_uuid"])) is not None]
    what = {"moved": "moved", "removed": "missing", "added": "new", None: "changed"}[q.kind]
    if not found:
        words = f"nothing {what}" + (f" {q.when}" if q.when else "")
        return _make(ctx, query, q, count=0, text=words, changes=[])
    body = "; ".join(_change_text(c, sessions) for c in found[:5])
    more = f"; +{len(found) - 5} more" if len(found) > 5 else ""
    return _make(ctx, query, q, count=len(found), hits=tuple(hits),
                 text=f"{len(found)} {what}: {body}{more}", changes=found)


def _present(ctx: Context, cls: str) -> list[Any]:
    items = ctx.kb.instances(layer="foreground", class_name=cls)
    return sorted(items, key=lambda i: -i.last_seen_s)


def _where_is(ctx: Context, q: ChangeQuestion, query: str) -> Answer:
    assert q.class_name is not None
    sessions = _Sessions(ctx.kb)
    items = _present(ctx, q.class_name)
    here = [i for i in items if i.data.get("vacated_s") is None]
    if not here:
        gone = f" ({len(items)} seen before, their places since seen empty)" if items else ""
        return _make(ctx, query, q, count=0, text=f"no {q.class_name} is known to be anywhere now{gone}")
    moved = {c["instance_uuid"]: c for c in ctx.kb.changes() if c["kind"] == "moved"}
    parts = []
    for inst in here[:3]:
        last = ctx.kb.instance_sessions(inst.uuid)
        seen = (f"last seen in {sessions.name(last[-1])} at {sessions.when(last[-1], inst.last_seen_s)}"
                if last else f"last seen at {_clock(inst.last_seen_s)}")
        part = f"{inst.class_name} at {_xyz(inst.box.center_m)} m, {seen}"
        if inst.uuid in moved:
            part += f" (moved there from {_xyz(moved[inst.uuid]['from_m'])} in " \
                    f"{sessions.name(int(moved[inst.uuid]['session']))})"
        parts.append(part)
    more = f"; +{len(here) - 3} more" if len(here) > 3 else ""
    hits = tuple(h for i in here if (h := _hit(ctx, i.uuid)) is not None)
    return _make(ctx, query, q, count=len(here), hits=hits, kind="location", text="; ".join(parts) + more)


def _last_seen(ctx: Context, q: ChangeQuestion, query: str) -> Answer:
    assert q.class_name is not None
    items = _present(ctx, q.class_name)
    if not items:
        return _make(ctx, query, q, count=0, text=f"no {q.class_name} was ever seen")
    inst = items[0]
    sessions = ctx.kb.instance_sessions(inst.uuid)
    names = _Sessions(ctx.kb)
    where = f" in {names.name(sessions[-1])}" if sessions else ""
    at = names.when(sessions[-1], inst.last_seen_s) if sessions else _clock(inst.last_seen_s)
    gone = inst.data.get("vacated_s")
    note = f"; its place was seen empty at {_clock(gone)}" if gone is not None else ""
    hit = _hit(ctx, inst.uuid)
    return _make(ctx, query, q, kind="time", hits=() if hit is None else (hit,),
                 time=TimeValue(inst.last_seen_s, ctx.now_s),
                 text=f"{inst.class_name} last seen{where} at {at}, at "
                      f"{_xyz(inst.box.center_m)} m{note}")


def _make(ctx: Context, query: str, q: ChangeQuestion, *, kind: str = "list",
          changes: list[Any] | None = None, **fields: Any) -> Answer:
    parsed: dict[str, Any] = {"intent": q.intent, "change_kind": q.kind, "class": q.class_name,
                              "when": q.when or None}
    if changes is not None:
        parsed["changes"] = changes
    return Answer(kind, query, ctx.now_s, ctx.reference, parsed=parsed, **fields)  # type: ignore[arg-type]


def answer_change(ctx: Context, q: ChangeQuestion, text: str) -> Answer:
    """The answer to a change question (see the module docstring)."""
    if q.intent == "changes":
        return _changes(ctx, q, text)
    if q.intent == "where_is":
        return _where_is(ctx, q, text)
    return _last_seen(ctx, q, text)
