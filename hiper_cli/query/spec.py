"""A query as typed data: what the plain-words grammar produces and the verbs consume.

``QuerySpec`` says which instances (classes, layer, state, time window, confidence, space);
``QueryConfig`` holds the constants of the geometry (field of view, default radii, support
tolerances, goal standoff) with their defaults.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Literal

from hiper_cli.errors import QueryError
from hiper_cli.query.geometry import Frustum

__all__ = ["CHANGES", "SORTS", "STATES", "Near", "On", "QueryConfig", "QuerySpec"]

Sort = Literal["distance", "last_seen", "first_seen", "confidence"]
SORTS: tuple[str, ...] = ("distance", "last_seen", "first_seen", "confidence")
STATES: tuple[str, ...] = ("static", "dynamic")
# What changed about an instance in the time window: first seen in it ("added"), its place seen
# empty in it ("removed", ``vacated_s``), it moved while seen in it ("moved": dynamic), or any.
CHANGES: tuple[str, ...] = ("added", "removed", "moved", "any")


@dataclass(frozen=True)
class QueryConfig:
    """``near_radius_m``: "near X" without a radius; ``pass_radius_m``: how close "passed
    here" is; ``support_gap_m``/``support_margin_m``: an object stands on a support when its
    bottom is that close to the support's top and its centre inside the support's footprint
    grown by the margin; ``goal_standoff_m``: a goal pose's distance from the object's
    footprint; ``now_window_s``: "now" means seen within this long before now;
    ``view_gap_s``: observations further apart end a stretch of "time in view";
    ``max_hits``: a list answer without a limit details at most this many hits (its
    ``count`` still counts all)."""

    frustum: Frustum = field(default_factory=Frustum)
    near_radius_m: float = 1.0
    pass_radius_m: float = 1.0
    support_gap_m: float = 0.12
    support_margin_m: float = 0.05
    support_classes: tuple[str, ...] = ("table",)
    goal_standoff_m: float = 0.6
    now_window_s: float = 2.0
    recent_s: float = 600.0
    view_gap_s: float = 1.0
    max_hits: int = 50


@dataclass(frozen=True)
class Near:
    """Within ``radius_m`` of the reference pose (``target`` "me") or of any instance of the
    class ``target``."""

    target: str
    radius_m: float

    def __post_init__(self) -> None:
        if not self.radius_m >= 0:
            raise QueryError(f"radius {self.radius_m} m: must be zero or positive")


@dataclass(frozen=True)
class On:
    """Standing on an instance of ``class_name``; only the closest one when ``closest``."""

    class_name: str
    closest: bool = False


@dataclass(frozen=True)
class QuerySpec:
    """Which instances a query selects. Empty ``classes`` = any class (of ``layer`` if set).
    Times are stamps (s): an instance passes when it was seen at some time in [since, until];
    with ``change`` (``CHANGES``) when that change happened in [since, until] instead.
    ``rank_from``: a class; sort "distance" then measures from the nearest instance of it
    ("the chair closest to the door"), not from the reference pose."""

    classes: tuple[str, ...] = ()
    layer: str | None = None
    state: str | None = None
    since_s: float | None = None
    until_s: float | None = None
    min_confidence: float = 0.0
    in_fov: bool = False
    near: Near | None = None
    on: On | None = None
    passed_here: bool = False
    change: str | None = None
    sort: str | None = None
    rank_from: str | None = None
    limit: int | None = None

    def __post_init__(self) -> None:
        if self.state is not None and self.state not in STATES:
            raise QueryError(f"state {self.state!r}: expected one of {', '.join(STATES)}")
        if self.change is not None and self.change not in CHANGES:
            raise QueryError(f"change {self.change!r}: expected one of {', '.join(CHANGES)}")
        if self.sort is not None and self.sort not in SORTS:
            raise QueryError(f"sort {self.sort!r}: expected one of {', '.join(SORTS)}")
        if self.layer is not None and self.layer not in ("background", "foreground"):
            raise QueryError(f"layer {self.layer!r}: expected background or foreground")
        if self.limit is not None and self.limit < 1:
            raise QueryError(f"limit {self.limit}: must be at least 1")
        if self.since_s is not None and self.until_s is not None and self.since_s > self.until_s:
            raise QueryError(f"time window {self.since_s} .. {self.until_s} s: starts after it ends")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)
