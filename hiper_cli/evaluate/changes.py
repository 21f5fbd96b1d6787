"""``hiper eval changes``: a knowledge base of several sessions against the truth of
``hiper sim --sessions N --changes K``.

Figures:

- **changes** per kind (added, removed, moved): precision, recall, F1. A stored change matches
  a true one of its kind, class and session when its positions lie within ``MATCH_M``
  (horizontally) of the true ones (removed: from; added: to; moved: both); one to one, nearest
  first.
- **re-identification precision**: of the instances observed in two or more sessions, the
  share that are one true object: the object of its class nearest its box in the last
  session that saw it (within ``MATCH_M``) stood in the place in every session that saw it.
  A true object is any static thing of the class, of either layer: the simulator's tables are
  background (structure a robot does not move), a table kept as an object is still one table.
- **ghost rate**: of the instances remembered as present that are a true object of some
  session, the share whose object is gone from the last session (removed, or moved away and
  left behind as a stale copy).
- **count error** per class: instances remembered as present against the objects of the last
  session.
- **alignment error** per session: the stored ``T_map_log`` against the true one: its angle,
  and how far it carries a point from where the true one does, at the log frame's origin (the
  simulator's is an arbitrary point metres from the robot), at the log's first pose (a real
  robot's odometry origin, where its pose estimate is exact) and, worst, along the log's true
  path (where what the session stores was seen). Both sessions' poses drift, the map's
  included, so the map frame is true only near the first session's start; the error at the
  start is the one the alignment controls.
"""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.errors import ConfigError

__all__ = ["ChangeReport", "evaluate_changes"]

MATCH_M = 0.75
NOT_OBJECTS = frozenset({"unknown", "person", "cart"})
STRUCTURE = frozenset({"wall", "floor", "ceiling", "stairs", "door", "window"})  # never objects
KINDS = ("added", "removed", "moved")


@dataclass
class ChangeReport:
    per_kind: dict[str, dict[str, float]] = field(default_factory=dict)
    reid_precision: float | None = None
    reid_merged: int = 0
    ghost_rate: float | None = None
    ghosts: int = 0
    present_real: int = 0
    counts: dict[str, dict[str, int]] = field(default_factory=dict)
    alignment: list[dict[str, Any]] = field(default_factory=list)
    stored_changes: list[dict[str, Any]] = field(default_factory=list)
    true_changes: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {"per_kind": self.per_kind, "reid_precision": self.reid_precision,
                "reid_merged": self.reid_merged,
                "ghost_rate": self.ghost_rate, "ghosts": self.ghosts, "present_real": self.present_real,
                "counts": self.counts, "alignment": self.alignment, "stored_changes": self.stored_changes,
                "true_changes": self.true_changes}


def _xy(v: Any) -> np.ndarray:
    return np.asarray(v, dtype=np.float64)[:2]


def _near(a: Any, b: Any) -> float:
    return float(np.linalg.norm(_xy(a) - _xy(b)))


def _change_cost(p: dict[str, Any], t: dict[str, Any]) -> float | None:
    if p["kind"] != t["kind"] or p["class"] != t["class"] or p["truth_session"] != t["session"]:
        return None
    keys = {"removed": ("from_m",), "added": ("to_m",), "moved": ("from_m", "to_m")}[t["kind"]]
    d = [_near(p[k], t[k]) for k in keys]
    return sum(d) if max(d) <= MATCH_M else None


def _score_changes(stored: list[dict[str, Any]], truth: list[dict[str, Any]]) -> dict[str, dict[str, float]]:
    pairs = sorted((c, i, j) for i, p in enumerate(stored) for j, t in enumerate(truth)
                   if (c := _change_cost(p, t)) is not None)
    used_p, used_t = set(), set()
    for _, i, j in pairs:
        if i not in used_p and j not in used_t:
            used_p.add(i)
            used_t.add(j)
    out = {}
    for kind in KINDS:
        n_p = sum(p["kind"] == kind for p in stored)
        n_t = sum(t["kind"] == kind for t in truth)
        hit = sum(stored[i]["kind"] == kind for i in used_p)
        prec = hit / n_p if n_p else (1.0 if n_t == 0 else 0.0)
        rec = hit / n_t if n_t else 1.0
        f1 = 2 * prec * rec / (prec + rec) if prec + rec > 0 else 0.0
        out[kind] = {"stored": n_p, "true": n_t, "matched": hit, "precision": round(prec, 3),
                     "recall": round(rec, 3), "f1": round(f1, 3)}
    return out


def _worlds(root: Path, sessions: list[dict[str, Any]]) -> dict[int, list[dict[str, Any]]]:
    """Per true session: its static objects of either layer (id, class, layer, centre), not
    the structure."""
    out = {}
    for s in sessions:
        doc = json.loads((root / s["log"] / "gt" / "world.json").read_text())
        out[int(s["session"])] = [i for i in doc["instances"] if i["state"] == "static"
                                  and i["class"] not in NOT_OBJECTS | STRUCTURE]
    return out


def _nearest(objects: list[dict[str, Any]], cls: str, centre: Any) -> dict[str, Any] | None:
    near = [(d, o["id"], o) for o in objects if o["class"] == cls
            and (d := _near(o["box"]["center_m"], centre)) <= MATCH_M]
    return min(near, key=lambda c: c[:2])[2] if near else None


def _angle_deg(R: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0))))


def evaluate_changes(kb_path: str | Path, truth_dir: str | Path) -> ChangeReport:
    """Score the knowledge base at ``kb_path`` against ``truth_dir/changes.json``."""
    from hiper_cli.graph import open_kb_for_reading

    root = Path(truth_dir)
    try:
        truth = json.loads((root / "changes.json").read_text())
    except (OSError, ValueError) as err:
        raise ConfigError(f"{root}: no readable changes.json ({err}); pass the folder written by "
                          "'hiper sim --sessions N --changes K'") from err
    by_log = {s["log"]: s for s in truth["sessions"]}
    worlds = _worlds(root, truth["sessions"])
    report = ChangeReport(true_changes=truth["changes"])
    with open_kb_for_reading(kb_path) as kb:
        sessions = kb.session_records()
        kb_to_truth = {s["id"]: int(by_log[Path(s["log_path"]).name]["session"]) for s in sessions
                       if Path(s["log_path"]).name in by_log}
        if not kb_to_truth:
            raise ConfigError(f"{kb_path}: none of its sessions is a log of {root}; perceive "
                              f"{root}/session_1 ... into it first")
        report.alignment = _alignment_errors(sessions, by_log)
        stored = [c | {"truth_session": kb_to_truth.get(int(c["session"]))} for c in kb.changes()]
        report.stored_changes = stored
        report.per_kind = _score_changes(stored, truth["changes"])
        instances = [i for i in kb.instances(layer="foreground")
                     if i.state == "static" and i.class_name not in NOT_OBJECTS]
        seen_in = {i.uuid: sorted({kb_to_truth[s] for s in kb.instance_sessions(i.uuid)
                                   if s in kb_to_truth}) for i in instances}
    last = max(worlds)
    _score_memory(report, instances, seen_in, worlds, last)
    return report


def _alignment_errors(sessions: list[dict[str, Any]], by_log: dict[str, Any]) -> list[dict[str, Any]]:
    """Per session: the stored ``T_map_log`` against the true one (metres at the origin, degrees)."""
    out = []
    for s in sessions:
        true = by_log.get(Path(s["log_path"]).name)
        if true is None or s["alignment"] is None:
            continue
        T_true = np.linalg.inv(np.asarray(true["T_log_map"]))
        D = np.linalg.inv(T_true) @ np.asarray(s["alignment"]["T_map_log"])
        path = _true_path_m(Path(s["log_path"]))
        off = np.linalg.norm(path @ D[:3, :3].T + D[:3, 3] - path, axis=1) if len(path) else np.zeros(1)
        out.append({"session": s["id"], "log": true["log"], "method": s["alignment"]["method"],
                    "fitness": s["alignment"]["fitness"],
                    "error_m": round(float(np.linalg.norm(D[:3, 3])), 4),
                    "error_start_m": round(float(off[0]), 4), "error_path_max_m": round(float(off.max()), 4),
                    "error_deg": round(_angle_deg(D[:3, :3]), 3)})
    return out


def _true_path_m(log: Path) -> np.ndarray:
    """The log's true camera positions in its own frame (``gt/groundtruth.txt`` where the
    sensor's poses drift, else the log's); empty when neither can be read."""
    from hiper_cli.errors import LogError
    from hiper_cli.perceive.logs import read_tum_trajectory

    for path in (log / "gt" / "groundtruth.txt", log / "groundtruth.txt"):
        if path.exists():
            try:
                return read_tum_trajectory(path).positions_m
            except LogError:
                break
    return np.zeros((0, 3))


def _score_memory(report: ChangeReport, instances: list[Any], seen_in: dict[str, list[int]],
                  worlds: dict[int, list[dict[str, Any]]], last: int) -> None:
    merged = correct = 0
    present: Counter[str] = Counter()
    for inst in instances:
        sessions = seen_in[inst.uuid]
        centre = inst.box.center_m
        gone = inst.data.get("vacated_s") is not None
        if len(sessions) >= 2:
            merged += 1
            obj = _nearest(worlds[sessions[-1]], inst.class_name, centre)
            correct += obj is not None and all(any(o["id"] == obj["id"] for o in worlds[s]) for s in sessions)
        if gone:
            continue
        present[inst.class_name] += 1
        real = any(_nearest(w, inst.class_name, centre) is not None for w in worlds.values())
        if real:
            report.present_real += 1
            report.ghosts += _nearest(worlds[last], inst.class_name, centre) is None
    report.reid_merged = merged
    report.reid_precision = round(correct / merged, 3) if merged else None
    report.ghost_rate = round(report.ghosts / report.present_real, 3) if report.present_real else None
    true_counts = Counter(o["class"] for o in worlds[last] if o["layer"] == "foreground")
    report.counts = {cls: {"stored": present.get(cls, 0), "true": true_counts.get(cls, 0),
                           "error": present.get(cls, 0) - true_counts.get(cls, 0)}
                     for cls in sorted(set(true_counts) | set(present))}
