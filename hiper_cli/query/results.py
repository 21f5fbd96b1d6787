"""Typed answers of the query layer, each with ``to_dict`` in the versioned JSON form that
``hiper query --json`` prints (schema: ``hiper_cli/query/schema.json``, docs/query.md).

Units: metres and seconds, map frame (z up); yaw in radians, counter-clockwise from +x.
Times are given three ways: stamp (s), ISO 8601 (UTC; null for a log's own clock that is not
wall-clock time, as a simulated log's, see ``hiper_cli.clock``) and "N min ago" relative to the
query's ``now``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any, Literal

from hiper_cli.clock import iso_utc

__all__ = [
    "ANSWER_KINDS",
    "SCHEMA_VERSION",
    "Answer",
    "AnswerKind",
    "GoalPose",
    "Hit",
    "ReferencePose",
    "Sighting",
    "Support",
    "TimeValue",
    "Trajectory",
    "ago_text",
    "iso_time",
    "short_uuid",
]

SCHEMA_VERSION = 1
AnswerKind = Literal["list", "count", "yes_no", "time", "duration", "location", "goal"]
ANSWER_KINDS: tuple[str, ...] = ("list", "count", "yes_no", "time", "duration", "location", "goal")


def iso_time(stamp_s: float) -> str:
    """The stamp as ISO 8601 UTC (a simulated log's stamps start at 1970-01-01T00:00:00Z)."""
    return datetime.fromtimestamp(stamp_s, UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")


def short_uuid(uuid: str) -> str:
    """The last 8 hex digits of an instance's uuid, to tell instances apart in a table: a uuid7
    begins with its creation time, the same for every instance of one run."""
    return uuid.replace("-", "")[-8:]


def ago_text(stamp_s: float, now_s: float) -> str:
    """How long before ``now_s``: "just now", "42 s ago", "12 min ago", "3.5 h ago", "2 d ago"."""
    dt = now_s - stamp_s
    if dt < 0:
        return f"in {ago_text(now_s, stamp_s).removesuffix(' ago')}"
    if dt < 1:
        return "just now"
    if dt < 60:
        return f"{dt:.0f} s ago"
    if dt < 3600:
        return f"{dt / 60:.0f} min ago"
    if dt < 86400:
        return f"{dt / 3600:.1f} h ago"
    return f"{dt / 86400:.0f} d ago"


@dataclass(frozen=True)
class TimeValue:
    stamp_s: float
    now_s: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "stamp_s": self.stamp_s,
            "iso": iso_utc(self.stamp_s),  # None for a log's own clock (a sim log): no date
            "ago": ago_text(self.stamp_s, self.now_s),
        }


@dataclass(frozen=True)
class ReferencePose:
    """Where a query is asked from: position (m) and heading (rad) in the map frame, and the
    camera pose ``T_map_cam`` (4×4 nested lists) for the field of view."""

    x_m: float
    y_m: float
    z_m: float
    yaw_rad: float
    stamp_s: float | None
    source: str  # "robot" (a recorded pose), "given" (--pose) or "origin" (empty KB)
    T_map_cam: tuple[tuple[float, ...], ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "x_m": self.x_m,
            "y_m": self.y_m,
            "z_m": self.z_m,
            "yaw_rad": self.yaw_rad,
            "stamp_s": self.stamp_s,
            "source": self.source,
        }


@dataclass(frozen=True)
class GoalPose:
    """A navigation goal in front of an object, facing it (nav2 ``geometry_msgs/PoseStamped``)."""

    x_m: float
    y_m: float
    yaw_rad: float
    target_uuid: str
    frame_id: str = "map"

    def to_dict(self) -> dict[str, Any]:
        half = self.yaw_rad / 2.0
        return {
            "x_m": self.x_m,
            "y_m": self.y_m,
            "yaw_rad": self.yaw_rad,
            "target_uuid": self.target_uuid,
            "pose_stamped": {
                "header": {"frame_id": self.frame_id},
                "pose": {
                    "position": {"x": self.x_m, "y": self.y_m, "z": 0.0},
                    "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(half), "w": math.cos(half)},
                },
            },
        }


@dataclass(frozen=True)
class Support:
    """What an object stands on: a table (or other support instance) or the floor."""

    class_name: str
    uuid: str | None

    def to_dict(self) -> dict[str, Any]:
        return {"class": self.class_name, "uuid": self.uuid}


@dataclass(frozen=True)
class Hit:
    """One instance that answers a query; box is axis-aligned in the map frame (m)."""

    uuid: str
    class_name: str
    layer: str
    center_map_m: tuple[float, float, float]
    extent_m: tuple[float, float, float]
    first_seen_s: float
    last_seen_s: float
    observation_count: int
    confidence: float
    state: str
    speed_mps: float | None
    distance_m: float
    support: Support | None = None
    evidence_uuids: tuple[str, ...] = ()

    def to_dict(self, now_s: float) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "class": self.class_name,
            "layer": self.layer,
            "position_m": list(self.center_map_m),
            "box": {"center_m": list(self.center_map_m), "extent_m": list(self.extent_m), "frame": "map"},
            "first_seen": TimeValue(self.first_seen_s, now_s).to_dict(),
            "last_seen": TimeValue(self.last_seen_s, now_s).to_dict(),
            "observation_count": self.observation_count,
            "confidence": self.confidence,
            "state": self.state,
            "speed_mps": self.speed_mps,
            "distance_m": self.distance_m,
            "support": None if self.support is None else self.support.to_dict(),
            "evidence_uuids": list(self.evidence_uuids),
        }


@dataclass(frozen=True)
class Answer:
    """The answer to one query. ``kind`` says which field carries it: ``hits`` (list,
    location, goal), ``count``, ``value`` (yes_no), ``time`` or ``duration_s``; ``hits``
    always lists the instances the answer is about."""

    kind: AnswerKind
    query: str
    now_s: float
    reference: ReferencePose
    hits: tuple[Hit, ...] = ()
    count: int | None = None
    value: bool | None = None
    time: TimeValue | None = None
    duration_s: float | None = None
    goal: GoalPose | None = None
    text: str = ""
    parsed: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": "hiper-query-answer",
            "version": SCHEMA_VERSION,
            "kind": self.kind,
            "query": self.query,
            "text": self.text,
            "parsed": self.parsed,
            "now": TimeValue(self.now_s, self.now_s).to_dict(),
            "reference": self.reference.to_dict(),
            "count": self.count,
            "value": self.value,
            "time": None if self.time is None else self.time.to_dict(),
            "duration_s": self.duration_s,
            "goal": None if self.goal is None else self.goal.to_dict(),
            "hits": [h.to_dict(self.now_s) for h in self.hits],
        }


@dataclass(frozen=True)
class Sighting:
    """When an instance was seen: first and last sighting and the time in view (s), the sum
    of the stretches of observations no further apart than the config's ``view_gap_s``."""

    uuid: str
    class_name: str
    first_seen_s: float
    last_seen_s: float
    time_in_view_s: float
    observation_count: int
    now_s: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "class": self.class_name,
            "first_seen": TimeValue(self.first_seen_s, self.now_s).to_dict(),
            "last_seen": TimeValue(self.last_seen_s, self.now_s).to_dict(),
            "time_in_view_s": self.time_in_view_s,
            "observation_count": self.observation_count,
        }


@dataclass(frozen=True)
class Trajectory:
    """An instance's track in the map frame: rows [stamp_s, x, y, z, vx, vy, vz] (m, m/s)."""

    uuid: str
    class_name: str
    rows: tuple[tuple[float, ...], ...]

    @property
    def length_m(self) -> float:
        return float(sum(math.dist(a[1:4], b[1:4]) for a, b in zip(self.rows, self.rows[1:], strict=False)))

    @property
    def duration_s(self) -> float:
        return float(self.rows[-1][0] - self.rows[0][0]) if len(self.rows) > 1 else 0.0

    @property
    def mean_speed_mps(self) -> float | None:
        return self.length_m / self.duration_s if self.duration_s > 0 else None

    def to_dict(self) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "class": self.class_name,
            "columns": ["stamp_s", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps"],
            "rows": [list(r) for r in self.rows],
            "length_m": self.length_m,
            "duration_s": self.duration_s,
            "mean_speed_mps": self.mean_speed_mps,
        }
