"""``simulate_sessions``: several logs of one place, with objects moved, removed and added between
them, each log in its own odometry frame, and the true list of changes.

A robot meets its place again every day: each session starts in a new odometry frame (turned
by tens of degrees, shifted by metres), and between sessions someone moves a chair, takes a
plant away or brings a new one. Output ``OUT``::

    OUT/session_1 ... OUT/session_N   TUM logs (poses in the session's frame), each with gt/ in
                                      the world's map frame (the first session's frame)
    OUT/changes.json                  the sessions' frames (``T_log_map``) and the true changes

A change is ``{"kind": moved|removed|added, "class", "object_id", "session" (1-based: the first
session that shows it), "from_m", "to_m"}`` with map-frame centres (null where they don't
apply). The objects that change stand on the floor (chairs, plants): things a robot's camera
sees from the side, so their place can be seen empty.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.errors import ConfigError
from hiper_cli.sim import furniture as fu
from hiper_cli.sim.meshes import rot_z
from hiper_cli.sim.worlds import Rect, SimObject, World, make_world
from hiper_cli.sim.writer import SimConfig, SimResult, simulate

__all__ = ["CHANGE_KINDS", "SessionsResult", "simulate_sessions"]

CHANGE_KINDS = ("moved", "removed", "added")
MOVABLE = ("chair", "potted plant")
CLEAR_M = 0.45  # a changed object's centre stays this far from furniture and walls
ROUTE_CLEAR_M = 0.9  # ... and from the robot's waypoints
APART_M = 3.5  # where an object of a class was taken away (removed, or moved from) and where one of
# it was put (added, or moved to) stay this far apart, whichever came first (closer, a removal and
# an addition are a move to anyone who cannot tell two chairs apart)
MOVE_M = (1.2, 3.0)  # how far a moved object goes


@dataclass(frozen=True)
class SessionsResult:
    out: Path
    sessions: list[SimResult]
    changes: list[dict[str, Any]]

    def to_dict(self) -> dict[str, Any]:
        return {"out": str(self.out), "sessions": [s.to_dict() for s in self.sessions],
                "changes": self.changes}


def session_frame(rng: np.random.Generator) -> np.ndarray:
    """A session's odometry frame: ``T_log_map`` turned by 15-40° and shifted by 1-3 m."""
    yaw = math.radians(float(rng.uniform(15.0, 40.0))) * (1 if rng.random() < 0.5 else -1)
    angle = float(rng.uniform(0.0, 2 * math.pi))
    shift = float(rng.uniform(1.0, 3.0))
    return rot_z(yaw, (shift * math.cos(angle), shift * math.sin(angle), 0.0))


def _clearance(p: tuple[float, float], rects: list[Rect]) -> float:
    out = math.inf
    for x0, y0, x1, y1 in rects:
        dx = max(x0 - p[0], p[0] - x1, 0.0)
        dy = max(y0 - p[1], p[1] - y1, 0.0)
        out = min(out, math.hypot(dx, dy))
    return out


def _footprint(obj: SimObject) -> Rect:
    lo, hi = obj.mesh.bounds()
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


class _Place:
    """The world as it stands in one session, and the free floor left for changes."""

    def __init__(self, world: World, rng: np.random.Generator) -> None:
        self.w = world
        self.rng = rng
        self.taken: list[tuple[float, float]] = []  # spots changed already: keep changes apart
        self.gone: list[tuple[str, tuple[float, float]]] = []  # (class, spot) of objects taken away
        self.placed: list[tuple[str, tuple[float, float]]] = []  # (class, spot) of objects put down

    def free_spot(self, cls: str, near: tuple[float, float] | None = None) -> tuple[float, float] | None:
        for _ in range(400):
            x0, y0, x1, y1 = self.w.walkable[int(self.rng.integers(len(self.w.walkable)))]
            p = (float(self.rng.uniform(x0, x1)), float(self.rng.uniform(y0, y1)))
            if near is not None and not MOVE_M[0] <= math.dist(p, near) <= MOVE_M[1]:
                continue
            if (_clearance(p, self.w.obstacles) >= CLEAR_M
                    and all(math.dist(p, q) >= ROUTE_CLEAR_M for q in self.w.waypoints)
                    and all(math.dist(p, q) >= 1.0 for q in self.taken)
                    and all(math.dist(p, q) >= APART_M for c, q in self.gone if c == cls)):
                self.taken.append(p)
                self.placed.append((cls, p))
                return p
        return None

    def movable(self, changed: set[int]) -> list[SimObject]:
        """Objects that may be taken away: of a movable class, not changed yet, and ``APART_M``
        from where one of their class was put."""
        return [o for o in self.w.objects if o.class_name in MOVABLE and o.id not in changed
                and all(math.dist(o.box.center_m[:2], q) >= APART_M
                        for c, q in self.placed if c == o.class_name)]

    def remove(self, obj: SimObject) -> None:
        self.w.objects.remove(obj)
        foot = _footprint(obj)
        self.w.obstacles = [r for r in self.w.obstacles if r != foot]

    def put(self, obj: SimObject) -> None:
        self.w.objects.append(obj)
        self.w.obstacles.append(_footprint(obj))


def _centre(obj: SimObject) -> list[float]:
    return [round(float(v), 3) for v in obj.box.center_m]


def _change(place: _Place, kind: str, changed: set[int]) -> dict[str, Any] | None:
    """Apply one change of ``kind`` to the place; its truth record, or None if none fits."""
    rng = place.rng
    if kind == "added":
        cls = MOVABLE[int(rng.integers(len(MOVABLE)))]
        spot = place.free_spot(cls)
        if spot is None:
            return None
        mesh = (fu.chair((0.2, 0.5, 0.3), (0.3, 0.2, 0.1)) if cls == "chair"
                else fu.plant((0.6, 0.3, 0.2)))
        mesh = mesh.transformed(rot_z(float(rng.uniform(0, 2 * math.pi)), (spot[0], spot[1], 0.0)))
        obj = SimObject(place.w.new_id(), f"{cls}_added_{len(changed)}", cls, "foreground", mesh)
        place.put(obj)
        changed.add(obj.id)
        return {"kind": kind, "class": cls, "object_id": obj.id, "from_m": None, "to_m": _centre(obj)}
    candidates = place.movable(changed)
    rng.shuffle(candidates)
    for obj in candidates:
        c = obj.box.center_m
        if kind == "removed":
            place.remove(obj)
            place.gone.append((obj.class_name, (float(c[0]), float(c[1]))))
            place.taken.append((float(c[0]), float(c[1])))
            changed.add(obj.id)
            return {"kind": kind, "class": obj.class_name, "object_id": obj.id, "from_m": _centre(obj),
                    "to_m": None}
        place.remove(obj)  # its own footprint does not block where it goes
        spot = place.free_spot(obj.class_name, near=(float(c[0]), float(c[1])))
        if spot is None:
            place.put(obj)
            continue
        place.gone.append((obj.class_name, (float(c[0]), float(c[1]))))
        moved = replace(obj, mesh=obj.mesh.translated((spot[0] - c[0], spot[1] - c[1], 0.0)))
        place.put(moved)
        changed.add(obj.id)
        return {"kind": kind, "class": obj.class_name, "object_id": obj.id, "from_m": _centre(obj),
                "to_m": _centre(moved)}
    return None


def simulate_sessions(
    world: str,
    sessions: int,
    changes: int,
    seconds: float,
    seed: int,
    out: str | Path,
    config: SimConfig | None = None,
    *,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> SessionsResult:
    """Write ``sessions`` logs of one place with ``changes`` changes spread over the gaps
    between them (kinds in turn: moved, removed, added), and ``OUT/changes.json``."""
    if sessions < 1:
        raise ConfigError(f"--sessions {sessions}: expected 1 or more")
    if changes < 0 or (changes and sessions < 2):
        raise ConfigError(f"--changes {changes}: changes happen between sessions; expected 0, or "
                          "--sessions 2 or more")
    rng = np.random.default_rng([seed, 55])
    place = _Place(make_world(world, seed), rng)
    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)
    per_gap = [len(range(g, changes, sessions - 1)) for g in range(sessions - 1)]
    changed: set[int] = set()
    truth: list[dict[str, Any]] = []
    frames: list[dict[str, Any]] = []
    results: list[SimResult] = []
    kind_turn = 0
    for s in range(1, sessions + 1):
        if s > 1:
            for _ in range(per_gap[s - 2]):
                record = None
                for attempt in range(len(CHANGE_KINDS)):
                    record = _change(place, CHANGE_KINDS[(kind_turn + attempt) % 3], changed)
                    if record is not None:
                        break
                kind_turn += 1
                if record is None:
                    raise ConfigError(f"--changes {changes}: the {world} has room for only {len(truth)}")
                truth.append({**record, "session": s})
        T_log_map = np.eye(4) if s == 1 else session_frame(rng)
        name = f"session_{s}"
        results.append(simulate(place.w, seconds, seed * 1000 + s, root / name, config, overwrite=overwrite,
                                progress=progress, T_log_map=T_log_map))
        frames.append({"session": s, "log": name, "T_log_map": np.round(T_log_map, 9).tolist()})
    final: dict[str, int] = {}
    for o in place.w.objects:
        if o.layer == "foreground":
            final[o.class_name] = final.get(o.class_name, 0) + 1
    doc = {"world": world, "seed": seed, "sessions": frames, "changes": truth, "final_counts": final}
    (root / "changes.json").write_text(json.dumps(doc, indent=1) + "\n")
    return SessionsResult(root, results, truth)
