"""Perception per configuration on one ``hiper sim`` log, scored against its ground truth.

The log has a mapping phase (no people) and long-term operation. Table II (background) is
measured once per world on the mapping phase: C1-C3 share the background stage. Table III
(foreground) is measured per configuration with ``hiper_cli.evaluate.foreground``:

- C2 (and C3, whose perception is the same; C3 differs only in the tasks): background stage
  plus foreground, no learned priors; C2's tracks are what the features are learned on;
- C1: the same with the features learned on C2's tracks fed back (ODS, size, altitude);
- C4: foreground without background filtering (every point is clustered);
- C5: ``baseline.project_detections`` on the truth detector's boxes.

What the tasks read from each configuration's knowledge is kept as ``Knowledge``.
"""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.bench.baseline import BaselineRun, project_detections
from hiper_cli.bench.configs import BenchConfig

__all__ = ["Knowledge", "PerceptionResult", "perceive_configs"]

_PIXEL_STEP = 4  # the foreground stage's default sampling grid

_TABLE_III_KEYS = (
    "frames", "detect_time_s", "frames_per_s", "tp", "fp", "fp_share", "sum_i", "sum_o",
    "localisation_classified_m", "people_dynamic_ratio", "people_speed_mps", "people_speed_ci_mps",
    "points_after_background_mean", "classification",
)


@dataclass
class Knowledge:
    """What a configuration knows after perceiving the log (map frame, metres)."""

    config: str
    person_rows: NDArray[np.float64]  # (M, 7) trajectory rows of person instances
    person_track: NDArray[np.int64]  # (M,) instance index per row
    person_speed_mps: float | None  # the learned mean speed (C1), else None
    bottles: NDArray[np.float64]  # (N, 3) centres of bottle instances the robot may search
    bottle_altitude_m: tuple[float, float] | None  # the learned altitude CI (C1)
    false_people_xy: list[tuple[float, float]]  # static "person" instances that are no person
    false_bottles_xy: list[tuple[float, float]]
    detect_latency_s: float
    workspace_points: float  # points per frame the workspace holds unexplained
    has_background: bool  # background recognition ran (supports are primitives)
    bottle_errors_m: list[tuple[float, float, float]] = field(default_factory=list)  # (x, y, error)
    tables: list[tuple[float, float, float, float]] = field(default_factory=list)  # footprints


@dataclass
class PerceptionResult:
    """Table II (once per world), Table III and ``Knowledge`` per configuration."""

    world: str
    log: str
    table2: dict[str, Any] | None
    table3: dict[str, dict[str, Any]] = field(default_factory=dict)
    knowledge: dict[str, Knowledge] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)


def _knowledge_of_run(
    cfg: BenchConfig, run: Any, truth: Any, scored: dict[str, Any], learned: dict[str, Any] | None
) -> Knowledge:
    from hiper_cli.graph.columns import columns_of_instances

    instances = list(run.world.foreground.values())
    people = [i for i in instances if i.class_name == "person"]
    cols = columns_of_instances(people)
    speed = None
    altitude = None
    if learned is not None:
        speed = (learned.get("person") or {}).get("ods", {}).get("mean_mps")
        alt = (learned.get("bottle") or {}).get("altitude")
        if alt and alt.get("instances", 0) >= 1:
            altitude = (float(alt["lo_m"]) - 0.05, float(alt["hi_m"]) + 0.05)
    false_people: list[tuple[float, float]] = []
    false_bottles: list[tuple[float, float]] = []
    bottles = []
    errors: list[tuple[float, float, float]] = []
    for inst in instances:
        votes = Counter(run.obs_truth_id.get(u) for u in inst.observation_uuids)
        votes.pop(None, None)
        gid = votes.most_common(1)[0][0] if votes else None
        true_class = truth.instances[gid].class_name if gid is not None else None
        xy = (float(inst.box.center_m[0]), float(inst.box.center_m[1]))
        if inst.class_name == "person" and true_class != "person" and inst.state != "dynamic":
            false_people.append(xy)
        if inst.class_name == "bottle":
            bottom = float(inst.box.center_m[2] - inst.box.extent_m[2] / 2)
            if altitude is not None and not altitude[0] <= bottom <= altitude[1]:
                continue  # the learned altitude rules it out
            bottles.append(np.asarray(inst.box.center_m, dtype=np.float64))
            if true_class != "bottle":
                false_bottles.append(xy)
            else:
                err = float(np.linalg.norm(inst.box.center_m - truth.instances[gid].box.center_m))
                errors.append((xy[0], xy[1], err))
    tables = []
    if cfg.background:
        for b in run.world.background.values():
            if b.class_name == "table":
                c, e = b.box.center_m, b.box.extent_m
                tables.append((float(c[0] - e[0] / 2), float(c[1] - e[1] / 2),
                               float(c[0] + e[0] / 2), float(c[1] + e[1] / 2)))
    return Knowledge(
        cfg.name, cols.rows, cols.track, speed,
        np.array(bottles, dtype=np.float64).reshape(-1, 3), altitude, false_people, false_bottles,
        float(scored["detect_time_s"][0] or 0.0), float(scored["points_after_background_mean"]),
        cfg.background, errors, tables,
    )


def _baseline(root: Path, truth: Any) -> tuple[BaselineRun, dict[str, Any], list[int | None]]:
    """C5 over the log, and its Table III rows: each naive instance's truth is the id most of its
    boxes' central pixels show."""
    from hiper_cli.perceive.detect import make_detector
    from hiper_cli.perceive.logs import open_log

    detector = make_detector("truth", log_path=root)
    frames = [(f, detector.detect(f)) for f in open_log(root)]
    start = time.perf_counter()
    run = project_detections(frames)
    wall = time.perf_counter() - start
    labels: list[int | None] = []
    errors: list[float] = []
    for inst in run.instances:
        votes: Counter[int] = Counter()
        for k, box in zip(inst.frames, inst.boxes, strict=True):
            frame = frames[k][0]
            ids = truth.load_instance_ids(frame.source.split(" + ")[0])
            x0, y0, x1, y1 = (int(v) for v in box)
            cx, cy = (x0 + x1) // 2, (y0 + y1) // 2
            patch = ids[max(cy - 2, 0) : cy + 3, max(cx - 2, 0) : cx + 3].ravel()
            votes.update(int(v) for v in patch if int(v) > 0)
        gid = votes.most_common(1)[0][0] if votes else None
        labels.append(gid if gid in truth.instances else None)
        if gid in truth.instances and truth.instances[gid].class_name == inst.class_name:
            for p, stamp in zip(inst.positions_m, inst.stamps_s, strict=True):
                q = truth.position_at(gid, stamp)
                q = truth.instances[gid].box.center_m if q is None else q
                errors.append(float(np.linalg.norm(np.asarray(p) - np.asarray(q))))
    per_class: dict[str, dict[str, int]] = {}
    for inst, gid in zip(run.instances, labels, strict=True):
        ok = gid is not None and truth.instances[gid].class_name == inst.class_name
        per_class.setdefault(inst.class_name, {"tp": 0, "fp": 0})["tp" if ok else "fp"] += 1
    tp = sum(v["tp"] for v in per_class.values())
    fp = sum(v["fp"] for v in per_class.values())
    times = np.asarray(run.times_s)
    h, w = frames[0][0].depth_m.shape if frames else (0, 0)
    table = {
        "frames": len(frames), "detect_time_s": [float(times.mean()), float(times.std())] if times.size else
        [None, None], "frames_per_s": len(frames) / wall if wall > 0 else 0.0, "tp": tp, "fp": fp,
        "fp_share": fp / (tp + fp) if tp + fp else None, "sum_i": len(run.instances),
        "sum_o": run.observations,
        "localisation_classified_m": (
            [float(np.mean(errors)), float(np.std(errors))] if errors else [None, None]
        ),
        "people_dynamic_ratio": None, "people_speed_mps": [None, None], "people_speed_ci_mps": None,
        # every point is an obstacle, sampled like the foreground stage's grid
        "points_after_background_mean": float(h * w) / _PIXEL_STEP**2, "classification": per_class,
    }
    return run, table, labels


def _knowledge_of_baseline(
    run: BaselineRun, labels: list[int | None], truth: Any, table: dict[str, Any]
) -> Knowledge:
    rows, track, bottles = [], [], []
    errors: list[tuple[float, float, float]] = []
    false_people: list[tuple[float, float]] = []
    false_bottles: list[tuple[float, float]] = []
    for k, (inst, gid) in enumerate(zip(run.instances, labels, strict=True)):
        true_class = truth.instances[gid].class_name if gid is not None else None
        xy = (float(inst.center_m[0]), float(inst.center_m[1]))
        if inst.class_name == "person":
            for p, s in zip(inst.positions_m, inst.stamps_s, strict=True):
                rows.append([s, p[0], p[1], p[2], 0.0, 0.0, 0.0])
                track.append(k)
            if true_class != "person":
                false_people.append(xy)
        if inst.class_name == "bottle":
            bottles.append(inst.center_m)
            if true_class != "bottle":
                false_bottles.append(xy)
            elif gid is not None:
                err = float(np.linalg.norm(inst.center_m - truth.instances[gid].box.center_m))
                errors.append((xy[0], xy[1], err))
    return Knowledge(
        "C5", np.array(rows, dtype=np.float64).reshape(-1, 7), np.array(track, dtype=np.int64), None,
        np.array(bottles, dtype=np.float64).reshape(-1, 3), None, false_people, false_bottles,
        float(table["detect_time_s"][0] or 0.0), float(table["points_after_background_mean"]), False,
        errors,
    )


def perceive_configs(log: str | Path, configs: tuple[BenchConfig, ...]) -> PerceptionResult:
    """Tables II and III and the knowledge of every configuration in ``configs`` on ``log``."""
    from hiper_cli.analyze.feedback import learn_priors
    from hiper_cli.evaluate import evaluate_background, perceive_and_score
    from hiper_cli.perceive.logs.truth import load_truth

    root = Path(log)
    truth = load_truth(root)
    names = {c.name for c in configs}
    out = PerceptionResult(truth.world, str(root), None)
    clock = time.perf_counter()
    if names & {"C1", "C2", "C3"}:
        out.table2 = evaluate_background(root).to_dict()
        out.seconds["table2"] = time.perf_counter() - clock
    base: dict[str, Any] = {"detector": "truth"}
    off: dict[str, Any] = {**base, "use_learned_priors": False}
    c2 = None
    for cfg in configs:
        clock = time.perf_counter()
        learned = None
        if cfg.name in ("C1", "C2", "C3"):
            if c2 is None:
                c2 = perceive_and_score(root, background="stage", truth=truth, **off)
            done = c2
            if cfg.name == "C1":
                priors, learned = learn_priors(c2.run.world)
                done = perceive_and_score(root, background="stage", priors=priors, truth=truth, **base)
            scored = done.evaluation.figures
            out.knowledge[cfg.name] = _knowledge_of_run(cfg, done.run, truth, scored, learned)
        elif cfg.name == "C4":
            done = perceive_and_score(root, background="truth", truth=truth, background_filter=False, **off)
            scored = done.evaluation.figures
            out.knowledge[cfg.name] = _knowledge_of_run(cfg, done.run, truth, scored, None)
        else:
            brun, scored, labels = _baseline(root, truth)
            out.knowledge[cfg.name] = _knowledge_of_baseline(brun, labels, truth, scored)
        out.table3[cfg.name] = {k: scored.get(k) for k in _TABLE_III_KEYS}
        out.seconds[cfg.name] = time.perf_counter() - clock
    return out
