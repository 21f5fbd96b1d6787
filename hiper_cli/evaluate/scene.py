"""A knowledge base's instances scored against a realistic world's ground truth (Table II / III).

The definitions follow the worlds' reference scorer (``gt/README.md`` of each world):

- background: each instance is sampled at its centre and on a 5 × 5 grid over ±0.8 of the
  half-extents of its box's two largest axes, moved onto its plane; a sample takes the class
  of the nearest true surface within ``SURFACE_TOL_M`` (a window is wall). Semantic precision
  = share of instances (on labelled geometry) whose class is their samples' majority class;
  static/dynamic precision = share whose near samples lie mostly on static surfaces; distance
  error = the centre's distance to the nearest surface; coverage = share of the observed
  building pieces of at least 1 m² (not the pooled ``*_misc``) that some sample lies on;
- foreground: an instance matches a true object of its class (or an alt class) whose centre is
  within ``MATCH_M`` or whose axis-aligned box IoU exceeds ``MATCH_IOU`` (a walking person: the
  median distance at the instance's trajectory stamps, else the closest approach to the true
  path); greedy one-to-one by distance. TP / FP per class, FN = observed objects unmatched;
  classified precision leaves ``unknown`` out (the paper's Table III). Each unmatched instance
  is put down to the class of the nearest true object it would match but for its class, or to
  ``nothing`` (``unmatched``; ``unknown_on_nothing`` is the share of unknown instances that lie
  on no real object); ``persons_per_person`` = person instances per true person observed;
  ``state_accuracy`` = share of matched instances whose state (static or dynamic) is their true
  object's (a walker that stood still at the end is still a dynamic object);
- localisation: centre error of matched static objects; person speed: of each person matched
  to a walker, the median filtered speed at its stamps where the walker walked, against the
  median true speed there (the worlds' walkers keep one speed; a simulated one stops for
  others, and a filter cannot tell a stop from a slow walk by its median).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.evaluate.surfaces import SurfaceTruth
from hiper_cli.learned import typical_speed_mps
from hiper_cli.model import Instance
from hiper_cli.perceive.logs.truth import Truth, TruthInstance

__all__ = ["MATCH_IOU", "MATCH_M", "SURFACE_TOL_M", "score_scene"]

SURFACE_TOL_M = 0.10
MATCH_M = 0.5
MATCH_IOU = 0.25
GRID = np.linspace(-0.8, 0.8, 5)
MIN_PIECE_M2 = 1.0
WALKING_MPS = 0.1  # a walker this fast (truth) walks; slower, it stands
FOUND_BOTH_WAYS = frozenset({"table"})  # background classes the foreground may also find

FloatArray = NDArray[np.float64]


def _samples(inst: Instance) -> FloatArray:
    """The centre and a 5 × 5 grid on the box's two largest axes, on the instance's plane."""
    box = inst.box
    c = np.asarray(box.center_m, np.float64)
    half = np.asarray(box.extent_m, np.float64) / 2.0
    thin = int(np.argmin(half))
    a, b = (k for k in range(3) if k != thin)
    grid = [c]
    for u in GRID:
        for v in GRID:
            local = np.zeros(3)
            local[a], local[b] = u * half[a], v * half[b]
            grid.append(c + box.R @ local)
    pts = np.array(grid)
    plane = inst.data.get("plane_map")
    if plane is not None:
        n = np.asarray(plane[:3], np.float64)
        if np.linalg.norm(n) > 0:
            n = n / np.linalg.norm(n)
            pts = pts - ((pts - c) @ n)[:, None] * n
    return pts


def _surface_class(truth: Truth, tid: int) -> str:
    """The class a background plane on true surface ``tid`` should have (a window: wall)."""
    inst = truth.instances.get(tid)
    if tid == 0 or inst is None:
        return "unlabelled"
    if inst.class_name == "other" and "window" in inst.name.lower():
        return "wall"
    return inst.class_name


def _ratio(num: int, den: int) -> float | None:
    return num / den if den else None


@dataclass(frozen=True)
class _Row:
    """One background instance: its class, the class it lies on, static, centre distance."""

    cls: str
    on: str
    static: bool
    centre_m: float


def score_background(truth: Truth, surfaces: SurfaceTruth, instances: Iterable[Instance]) -> dict[str, Any]:
    """Table II style figures of the background ``instances``."""
    rows: list[_Row] = []
    covered: set[int] = set()
    for inst in instances:
        dist, ids, static = surfaces.nearest(_samples(inst))
        near = dist <= SURFACE_TOL_M
        classes = Counter(_surface_class(truth, int(i)) for i in ids[near])
        on = classes.most_common(1)[0][0] if classes else "none"
        covered.update(int(i) for i in ids[near & static])
        rows.append(_Row(inst.class_name, on, bool(near.any() and static[near].mean() > 0.5), float(dist[0])))
    scored = [r for r in rows if r.on != "unlabelled"]
    pieces = [t for t in truth.instances.values() if t.layer == "background" and t.class_name != "table"
              and t.observed and surfaces.piece_area_m2.get(t.id, MIN_PIECE_M2) >= MIN_PIECE_M2
              and not t.name.endswith("_misc")]
    centre = [r.centre_m for r in rows if np.isfinite(r.centre_m)]
    return {
        "instances": len(rows),
        "on_unlabelled": len(rows) - len(scored),
        "off_surface": sum(r.on == "none" for r in rows),
        "semantic_precision": _ratio(sum(r.cls == r.on for r in scored), len(scored)),
        "static_precision": _ratio(sum(r.static for r in rows), len(rows)),
        "distance_centre_mean_m": float(np.mean(centre)) if centre else None,
        "distance_centre_median_m": float(np.median(centre)) if centre else None,
        "pieces": len(pieces),
        "pieces_covered": sum(t.id in covered for t in pieces),
        "coverage": _ratio(sum(t.id in covered for t in pieces), len(pieces)),
        "uncovered": sorted(t.name for t in pieces if t.id not in covered),
        "confusion": dict(sorted(Counter(f"{r.cls}->{r.on}" for r in rows).items())),
    }


def _aabb_iou(inst: Instance, t: TruthInstance) -> float:
    lo_a, hi_a = inst.box.aabb()
    lo_b, hi_b = t.box.aabb()
    inter = float(np.prod(np.clip(np.minimum(hi_a, hi_b) - np.maximum(lo_a, lo_b), 0, None)))
    union = float(np.prod(hi_a - lo_a) + np.prod(hi_b - lo_b)) - inter
    return inter / union if union > 0 else 0.0


def _distance(inst: Instance, t: TruthInstance, truth: Truth) -> float:
    """Centre distance; for a walking person at the instance's stamps along the true walk."""
    centre = np.asarray(inst.box.center_m, np.float64)
    track = truth.tracks.get(t.id)
    if t.state != "dynamic" or track is None or len(track) == 0:
        return float(np.linalg.norm(centre - np.asarray(t.box.center_m)))
    rows = np.asarray(inst.data.get("trajectory") or [], np.float64).reshape(-1, 7)
    dists = []
    for row in rows:
        true = truth.position_at(t.id, float(row[0]))
        if true is not None:
            dists.append(float(np.linalg.norm(row[1:4] - true)))
    if dists:
        return float(np.median(dists))
    return float(np.min(np.linalg.norm(track[:, 1:4] - centre, axis=1)))


def _nearest_class(inst: Instance, gt: list[TruthInstance], truth: Truth) -> str:
    """The class of the nearest true object ``inst`` lies on (by the match rule, any class), or
    ``nothing``."""
    best: tuple[float, str] | None = None
    for t in gt:
        dist = _distance(inst, t, truth)
        if (dist <= MATCH_M or _aabb_iou(inst, t) > MATCH_IOU) and (best is None or dist < best[0]):
            best = (dist, t.class_name)
    return best[1] if best else "nothing"


def _walking_speeds(truth: Truth, t: TruthInstance, rows: list[list[float]]) -> tuple[float, float] | None:
    """(predicted, true) speed of a walker while it walked and the instance saw it: at the
    instance's trajectory stamps where the truth walked (``WALKING_MPS``), the median of the
    instance's filtered speed and of the true one (a simulated walker stops for others; the
    worlds' keep walking). None where the truth has no velocities there."""
    track = truth.tracks.get(t.id)
    arr = np.asarray([r[:7] for r in rows], np.float64).reshape(-1, 7)
    if track is None or len(track) < 2 or len(arr) == 0 or not np.any(arr[:, 4:7]):
        return None
    stamps = arr[:, 0]
    true = np.hypot(np.interp(stamps, track[:, 0], track[:, 4]), np.interp(stamps, track[:, 0], track[:, 5]))
    walking = (stamps >= track[0, 0]) & (stamps <= track[-1, 0]) & (true > WALKING_MPS)
    if not walking.any():
        return None
    return float(np.median(np.linalg.norm(arr[walking, 4:7], axis=1))), float(np.median(true[walking]))


def _match(
    truth: Truth, preds: list[Instance], gt: list[TruthInstance]
) -> tuple[dict[int, tuple[int, float]], set[int]]:
    """Greedy one-to-one matching, nearest first: prediction index -> (truth id, distance m)."""
    cand = []
    for pi, p in enumerate(preds):
        for t in gt:
            if p.class_name != t.class_name and p.class_name not in t.alt_classes:
                continue
            dist, iou = _distance(p, t, truth), _aabb_iou(p, t)
            if dist <= MATCH_M or iou > MATCH_IOU:
                cand.append((dist, -iou, pi, t.id))
    matched: dict[int, tuple[int, float]] = {}
    used: set[int] = set()
    for dist, _, pi, tid in sorted(cand):
        if pi not in matched and tid not in used:
            matched[pi] = (tid, dist)
            used.add(tid)
    return matched, used


def _walker_speeds(
    truth: Truth, preds: list[Instance], matched: dict[int, tuple[int, float]]
) -> list[tuple[float, float]]:
    """(our speed, true speed) in m/s of each matched walker, while it truly walks."""
    speeds = []
    for pi, (tid, _) in matched.items():
        t = truth.instances[tid]
        if t.state == "dynamic" and t.speed_mps is not None:
            rows = preds[pi].data.get("trajectory") or []
            walked = _walking_speeds(truth, t, rows)
            speed = typical_speed_mps(rows)
            if walked is not None:
                speeds.append(walked)
            elif speed is not None:
                speeds.append((speed, t.speed_mps))
    return speeds


def score_foreground(truth: Truth, instances: Iterable[Instance]) -> dict[str, Any]:
    """Table III style figures of the foreground ``instances``."""
    preds = list(instances)
    # Tables are background surfaces to hiper, found as planes; a table the foreground found
    # (``unmapped_tables``) on a true table is right, and one it did not find is no miss.
    gt = [t for t in truth.instances.values() if t.layer == "foreground" or t.class_name in FOUND_BOTH_WAYS]
    matched, used = _match(truth, preds, gt)
    per_class: dict[str, dict[str, int]] = {}
    for pi, p in enumerate(preds):
        per_class.setdefault(p.class_name, {"tp": 0, "fp": 0, "fn": 0})["tp" if pi in matched else "fp"] += 1
    for t in gt:
        if t.observed and t.id not in used and t.layer == "foreground":
            per_class.setdefault(t.class_name, {"tp": 0, "fp": 0, "fn": 0})["fn"] += 1
    unmatched: Counter[str] = Counter()
    for pi, p in enumerate(preds):
        if pi not in matched:
            unmatched[f"{p.class_name}->{_nearest_class(p, gt, truth)}"] += 1
    tp = len(matched)
    known = [pi for pi, p in enumerate(preds) if p.class_name != "unknown"]
    known_tp = sum(pi in matched for pi in known)
    errors = [d for pi, (tid, d) in matched.items() if truth.instances[tid].state != "dynamic"]
    same_state = [preds[pi].state == truth.instances[tid].state for pi, (tid, _) in matched.items()]
    speeds = _walker_speeds(truth, preds, matched)
    return {
        "instances": len(preds),
        "tp": tp,
        "fp": len(preds) - tp,
        "fn_observed": sum(c["fn"] for c in per_class.values()),
        "precision": _ratio(tp, len(preds)),
        "classified_tp": known_tp,
        "classified_fp": len(known) - known_tp,
        "classified_precision": _ratio(known_tp, len(known)),
        "unknown": len(preds) - len(known),
        "unknown_on_nothing": _ratio(unmatched["unknown->nothing"], len(preds) - len(known)),
        "persons_per_person": _ratio(sum(p.class_name == "person" for p in preds),
                                     sum(t.class_name == "person" and t.observed for t in gt)),
        "state_accuracy": _ratio(sum(same_state), len(same_state)),
        "dynamic_instances": sum(p.state == "dynamic" for p in preds),
        "per_class": dict(sorted(per_class.items())),
        "unmatched": dict(sorted(unmatched.items())),
        "centre_error_mean_m": float(np.mean(errors)) if errors else None,
        "centre_error_median_m": float(np.median(errors)) if errors else None,
        "walkers_matched": len(speeds),
        "walker_speed_mean_mps": float(np.mean([s for s, _ in speeds])) if speeds else None,
        "walker_speed_error_mps": float(np.mean([abs(s - v) for s, v in speeds])) if speeds else None,
        "matched_truth_ids": sorted(used),
    }


def score_scene(truth: Truth, surfaces: SurfaceTruth, instances: Iterable[Instance]) -> dict[str, Any]:
    """Both tables for a knowledge base's instances (map frame = the log's world frame)."""
    insts = list(instances)
    return {
        "world": truth.world,
        "background": score_background(truth, surfaces, [i for i in insts if i.layer == "background"]),
        "foreground": score_foreground(truth, [i for i in insts if i.layer == "foreground"]),
    }
