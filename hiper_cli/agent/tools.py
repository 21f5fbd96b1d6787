"""The agent tool registry: each query verb as a named tool with a strict JSON Schema of its
inputs, a handler that calls the query layer (or ``hiper_cli.analyze``) and the schema of its
typed result. ``hiper mcp`` serves these tools; ``hiper tools`` prints them for agent
frameworks that call functions. Every tool is read-only."""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli.agent import schemas as s
from hiper_cli.agent.times import resolve_span_s, resolve_time
from hiper_cli.errors import HiperError, QueryError
from hiper_cli.graph.kb import KnowledgeBase

__all__ = ["TOOLS", "Tool", "ToolContext", "ToolResult", "call_tool", "tool_named"]

Schema = dict[str, Any]


@dataclass
class ToolContext:
    """What a handler needs beyond its arguments: the knowledge base and where the heatmap
    tool may write its files (a temporary folder unless given)."""

    kb: KnowledgeBase
    out_dir: Path | None = None
    timeout_s: float | None = 30.0  # per SPARQL query

    def output_dir(self) -> Path:
        if self.out_dir is None:
            self.out_dir = Path(tempfile.mkdtemp(prefix="hiper-agent-"))
        return self.out_dir


@dataclass(frozen=True)
class ToolResult:
    """A tool's structured result, and PNG images for clients that show them."""

    data: dict[str, Any]
    images: tuple[bytes, ...] = ()
    is_error: bool = False


@dataclass(frozen=True)
class Tool:
    name: str
    description: str
    input_schema: Schema
    output_schema: Schema
    handler: Callable[[ToolContext, dict[str, Any]], ToolResult] = field(repr=False)


# ---- shared inputs ---------------------------------------------------------------------------

WHAT = {"type": "string", "description": "Class words: 'chair', 'mugs', 'people', 'objects' (any "
        "foreground class); COCO names and hiper's wall, floor, table, door, shelf, ..."}
FRAME_INPUTS: Schema = {
    "pose": s.POSE_INPUT,
    "at": s.time_input("Ask from the robot's pose at this time"),
    "now": s.time_input("The 'now' relative times count back from (default: the KB's last stamp)"),
}
FILTERS: Schema = {
    "near": {"type": "string", "description": "'me' or a class: only instances within radius_m of it."},
    "radius_m": {"type": "number", "minimum": 0, "description": "Radius of 'near' (default 1 m)."},
    "in_fov": {"type": "boolean", "description": "Only instances in the camera's field of view."},
    "on": {"type": "string", "description": "Only objects standing on an instance of this class."},
    "on_closest": {"type": "boolean", "description": "With 'on': only on the closest such support."},
    "since": s.time_input("Seen at or after this time, e.g. 'last 10 minutes'"),
    "until": s.time_input("Seen at or before this time"),
    "state": {"enum": ["static", "dynamic", "moving"]},
    "min_confidence": {"type": "number", "minimum": 0, "maximum": 1},
}
SORT = {"enum": ["distance", "last_seen", "first_seen", "confidence"],
        "description": "Order of hits (default: nearest first)."}
LIMIT = {"type": "integer", "minimum": 1, "maximum": 1000}
UUID = {"type": "string", "description": "An instance uuid from another tool's hits."}
FRAME_RESULT: Schema = {"now": s.TIME_VALUE, "reference": s.REFERENCE, "window": s.WINDOW}
FRAME_REQUIRED = ("now", "reference", "window")


def _base_now(kb: KnowledgeBase) -> float:
    span = kb.stamp_span()
    return span[1] if span else 0.0


def _pose(args: dict[str, Any]) -> tuple[float, float, float, float] | None:
    p = args.get("pose")
    if p is None:
        return None
    return (float(p["x_m"]), float(p["y_m"]), float(p.get("z_m", 1.2)), float(p.get("yaw_rad", 0.0)))


def _frame(ctx: ToolContext, args: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    """The query context (reference pose, now) and the verbs' frame keywords."""
    from hiper_cli.query.engine import make_context

    base = _base_now(ctx.kb)
    now_s = resolve_time(args["now"], base) if "now" in args else None
    at_s = resolve_time(args["at"], base if now_s is None else now_s) if "at" in args else None
    qctx = make_context(ctx.kb, pose=_pose(args), at_s=at_s, now_s=now_s)
    return qctx, {"pose": _pose(args), "at_s": at_s, "now_s": qctx.now_s}


def _filters(args: dict[str, Any], now_s: float, keys: tuple[str, ...]) -> dict[str, Any]:
    out = {k: args[k] for k in keys if k in args and k not in ("since", "until")}
    for key in ("since", "until"):
        if key in args:
            out[f"{key}_s"] = resolve_time(args[key], now_s)
    return out


def _head(qctx: Any, filters: dict[str, Any]) -> dict[str, Any]:
    from hiper_cli.query.results import TimeValue

    def tv(key: str) -> Any:
        v = filters.get(key)
        return None if v is None else TimeValue(v, qctx.now_s).to_dict()

    return {
        "now": TimeValue(qctx.now_s, qctx.now_s).to_dict(),
        "reference": qctx.reference.to_dict(),
        "window": {"since": tv("since_s"), "until": tv("until_s")},
    }


# ---- handlers --------------------------------------------------------------------------------

FIND_KEYS = ("near", "radius_m", "in_fov", "on", "on_closest", "since", "until", "state", "min_confidence")


def _find(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query import find

    qctx, frame = _frame(ctx, args)
    filters = _filters(args, qctx.now_s, (*FIND_KEYS, "sort", "limit"))
    hits = find(ctx.kb, args.get("what"), **frame, **filters)
    found = [h.to_dict(qctx.now_s) for h in hits]
    return ToolResult(_head(qctx, filters) | {"count": len(hits), "hits": found})


def _count(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query import count

    qctx, frame = _frame(ctx, args)
    filters = _filters(args, qctx.now_s, FIND_KEYS)
    return ToolResult(_head(qctx, filters) | {"count": count(ctx.kb, args.get("what"), **frame, **filters)})


def _last_seen(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query import last_seen

    qctx, frame = _frame(ctx, args)
    filters = _filters(args, qctx.now_s, FIND_KEYS)
    hit = last_seen(ctx.kb, args["what"], **frame, **filters)
    return ToolResult(_head(qctx, filters) | {"found": hit is not None,
                                              "hit": None if hit is None else hit.to_dict(qctx.now_s)})


def _when(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query import when

    base = _base_now(ctx.kb)
    now_s = resolve_time(args["now"], base) if "now" in args else None
    return ToolResult(when(ctx.kb, args["uuid"], now_s=now_s).to_dict())


def _trajectory(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query import trajectory

    return ToolResult(trajectory(ctx.kb, args["uuid"]).to_dict())


def _workspace(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query.workspace import workspace

    size = args.get("size_m", 1.0)
    center = tuple(float(v) for v in args["center_m"])
    size_m = float(size) if isinstance(size, int | float) else tuple(float(v) for v in size)
    ws = workspace(ctx.kb, center, size_m, resolution_m=float(args.get("resolution_m", 0.05)))  # type: ignore[arg-type]
    return ToolResult(ws.to_dict())


def _describe(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query.describe import describe

    base = _base_now(ctx.kb)
    now_s = resolve_time(args["now"], base) if "now" in args else None
    recent = resolve_span_s(args.get("recent", 300.0))
    return ToolResult(describe(ctx.kb, now_s=now_s, recent_s=recent).to_dict())


def _window(ctx: ToolContext, args: dict[str, Any]) -> Any:
    from hiper_cli.analyze import TimeWindow, resolve_window

    base = _base_now(ctx.kb)
    if "last" in args:
        if "since" in args or "until" in args:
            raise QueryError("give 'last' alone, without 'since'/'until'")
        span = resolve_span_s(args["last"])
        window = TimeWindow(base - span, base)
    else:
        since = resolve_time(args["since"], base) if "since" in args else None
        until = resolve_time(args["until"], base) if "until" in args else None
        window = TimeWindow(since, until)
    if "daily" in args:
        daily = resolve_window(daily=args["daily"]).daily_s
        window = TimeWindow(window.t_start_s, window.t_end_s, daily)
    return window


def _features(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.analyze import learn_features

    report, _ = learn_features(ctx.kb, args.get("classes") or None, _window(ctx, args), store=False)
    return ToolResult(report.to_dict())


def _heatmap(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.analyze import generate_heatmap

    result = generate_heatmap(
        ctx.kb, args["class"], _window(ctx, args), ctx.output_dir(), inverse=bool(args.get("inverse", False)),
        store=False,
    )
    data = result.to_dict()
    png = Path(data["files"]["png"]).read_bytes()
    return ToolResult(data, images=(png,))


def _sparql(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    body, media = ctx.kb.run_readonly(args["query"], timeout_s=ctx.timeout_s)
    if media.endswith("json"):
        return ToolResult({"media_type": media, "results": json.loads(body)})
    return ToolResult({"media_type": media, "text": body.decode("utf-8")})


def _ask(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query import ask

    _, frame = _frame(ctx, args)
    return ToolResult(ask(ctx.kb, args["question"], **frame, limit=args.get("limit")).to_dict())


def _changes(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query.engine import make_context
    from hiper_cli.query.history import ChangeQuestion, answer_change

    question = ChangeQuestion("changes", args.get("kind"), None, str(args.get("when") or "").strip().lower())
    qctx = make_context(ctx.kb)
    return ToolResult(answer_change(qctx, question, f"changes {question.kind or ''} {question.when}".strip())
                      .to_dict())


def _where_is(ctx: ToolContext, args: dict[str, Any]) -> ToolResult:
    from hiper_cli.query.engine import make_context
    from hiper_cli.query.history import answer_change, match

    text = f"where is the {args['what']} now"
    question = match(text)
    assert question is not None
    return ToolResult(answer_change(make_context(ctx.kb), question, text).to_dict())


# ---- the registry ----------------------------------------------------------------------------

_FIND_INPUT = s.obj({"what": WHAT, **FILTERS, "sort": SORT, "limit": LIMIT, **FRAME_INPUTS})
_COUNT_INPUT = s.obj({"what": WHAT, **FILTERS, **FRAME_INPUTS})
_WINDOW_INPUT: Schema = {
    "since": s.time_input("Window start"),
    "until": s.time_input("Window end"),
    "last": {"type": ["number", "string"], "description": "Only the last span of data: '1 h', '15 min'."},
    "daily": {"type": "string", "description": "Only this time of every day (UTC), 'HH:MM-HH:MM'."},
}
_TRACK = s.obj({"uuid": s.STRING, "class": s.STRING, "columns": {"type": "array"}, "rows": {"type": "array"},
                "length_m": s.NUMBER, "duration_s": s.NUMBER, "mean_speed_mps": s.NULLABLE_NUMBER},
               ("uuid", "class", "rows"))

TOOLS: tuple[Tool, ...] = (
    Tool("find", "List the instances of a class (or any) that match filters (near, in view, on a "
         "support, time window, state), nearest first, with position, times, state and speed.",
         _FIND_INPUT,
         s.obj({**FRAME_RESULT, "count": {"type": "integer"}, "hits": {"type": "array", "items": s.HIT}},
               (*FRAME_REQUIRED, "count", "hits")), _find),
    Tool("count", "How many instances of a class (or any) match the filters.", _COUNT_INPUT,
         s.obj({**FRAME_RESULT, "count": {"type": "integer"}}, (*FRAME_REQUIRED, "count")), _count),
    Tool("last_seen", "The most recently seen instance of a class matching the filters: where and when.",
         s.obj({"what": WHAT, **FILTERS, **FRAME_INPUTS}, ("what",)),
         s.obj({**FRAME_RESULT, "found": {"type": "boolean"}, "hit": {"anyOf": [s.HIT, {"type": "null"}]}},
               (*FRAME_REQUIRED, "found", "hit")), _last_seen),
    Tool("when", "First and last sighting of one instance and its time in view (s).",
         s.obj({"uuid": UUID, "now": FRAME_INPUTS["now"]}, ("uuid",)),
         s.obj({"uuid": s.STRING, "class": s.STRING, "first_seen": s.TIME_VALUE, "last_seen": s.TIME_VALUE,
                "time_in_view_s": s.NUMBER, "observation_count": {"type": "integer"}},
               ("uuid", "class", "first_seen", "last_seen", "time_in_view_s")), _when),
    Tool("trajectory", "The map-frame track of one instance: rows [stamp_s, x, y, z, vx, vy, vz].",
         s.obj({"uuid": UUID}, ("uuid",)), _TRACK, _trajectory),
    Tool("workspace", "What a box of the map holds, for a manipulation planner: background primitives "
         "and a foreground voxel grid with classes and learned dynamics.",
         s.obj({"center_m": s.VEC3,
                "size_m": {"anyOf": [{"type": "number", "exclusiveMinimum": 0}, s.VEC3]},
                "resolution_m": {"type": "number", "minimum": 0.001, "maximum": 10}}, ("center_m",)),
         s.obj({"format": {"const": "hiper-workspace"}}, ("format",), strict=False), _workspace),
    Tool("describe", "A compact summary of the scene: classes per layer, recent movers, learned "
         "features, time span; the 'text' field is sized for a prompt.",
         s.obj({"recent": {"type": ["number", "string"], "description": "Movers seen in this span "
                           "before now: seconds or '5 minutes' (default 300 s)."},
                "now": FRAME_INPUTS["now"]}),
         s.obj({"format": {"const": "hiper-describe"}, "text": s.STRING}, ("format", "text"), strict=False),
         _describe),
    Tool("features", "Learned features per class (paper VI): Object Dynamic Score, box size and "
         "altitude with 95 % intervals, computed without storing them.",
         s.obj({"classes": {"type": "array", "items": s.STRING}, **_WINDOW_INPUT}),
         s.obj({"classes": {"type": "array"}, "window": {"type": "object"}}, ("classes", "window"),
               strict=False), _features),
    Tool("heatmap", "Where a class usually is: the heatmap of its trajectories on the map (a PNG "
         "image) and nav2 costmap-filter masks (file paths).",
         s.obj({"class": s.STRING, **_WINDOW_INPUT, "inverse": {"type": "boolean"}}, ("class",)),
         s.obj({"files": {"type": "object", "additionalProperties": s.STRING}}, ("files",), strict=False),
         _heatmap),
    Tool("sparql", "A read-only SPARQL 1.1 query (SELECT, ASK, CONSTRUCT, DESCRIBE) over the scene "
         "graph; prefixes hiper:, prov:, sosa: predeclared; updates are refused.",
         s.obj({"query": s.STRING}, ("query",)),
         s.obj({"media_type": s.STRING, "results": {"type": "object"}, "text": s.STRING}, ("media_type",)),
         _sparql),
    Tool("ask", "A question in plain words, e.g. 'where was the bottle last seen', 'how many chairs', "
         "'people moving in the last 10 minutes' (hiper's grammar, no language model).",
         s.obj({"question": s.STRING, "limit": LIMIT, **FRAME_INPUTS}, ("question",)),
         s.obj({"format": {"const": "hiper-query-answer"}, "kind": s.STRING, "text": s.STRING},
               ("format", "kind", "text"), strict=False), _ask),
    Tool("changes", "What changed in the place over its sessions: objects added, removed (their place "
         "seen empty) or moved (from, to), each with its session and time; parsed.changes lists them.",
         s.obj({"kind": {"enum": ["added", "removed", "moved"],
                         "description": "Only this kind (default all)."},
                "when": {"type": "string", "description": "A time phrase: 'since 10:00', 'today', "
                         "'since yesterday', 'in the last 5 minutes' (default: ever)."}}),
         s.obj({"format": {"const": "hiper-query-answer"}, "kind": s.STRING, "text": s.STRING},
               ("format", "kind", "text"), strict=False), _changes),
    Tool("where_is", "Where the objects of a class are now (not those whose place was since seen empty), "
         "the session and time each was last seen, and where it moved from.",
         s.obj({"what": WHAT}, ("what",)),
         s.obj({"format": {"const": "hiper-query-answer"}, "kind": s.STRING, "text": s.STRING},
               ("format", "kind", "text"), strict=False), _where_is),
)


def tool_named(name: str) -> Tool:
    for tool in TOOLS:
        if tool.name == name:
            return tool
    raise QueryError(f"no tool {name!r}; expected one of {', '.join(t.name for t in TOOLS)}")


def _error(kind: str, message: str) -> ToolResult:
    return ToolResult({"error": {"type": kind, "message": message}}, is_error=True)


def call_tool(ctx: ToolContext, name: str, arguments: dict[str, Any] | None) -> ToolResult:
    """Validate ``arguments`` against the tool's schema and run it; a bad call or a query
    error comes back as a structured error result, never as an exception."""
    import jsonschema

    try:
        tool = tool_named(name)
        args = dict(arguments or {})
        jsonschema.validate(args, tool.input_schema)
        return tool.handler(ctx, args)
    except jsonschema.ValidationError as err:
        where = "/".join(str(p) for p in err.absolute_path)
        return _error("invalid_arguments", f"{where + ': ' if where else ''}{err.message}")
    except HiperError as err:
        return _error(type(err).__name__, str(err))
    except Exception as err:  # a tool must never bring the server down
        return _error("internal", f"{type(err).__name__}: {err}")
