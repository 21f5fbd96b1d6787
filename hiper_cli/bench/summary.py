"""Numbers of a benchmark run: task times and success rates per world, configuration and task,
the change of C3 (no heatmaps) against C1 beside the paper's, and the perceptual tables."""

from __future__ import annotations

from typing import Any

import numpy as np

from hiper_cli.bench.run import BenchResult
from hiper_cli.bench.tasks import TASKS

__all__ = ["PAPER_C3_VS_C1", "summarize"]

# Section VII-C, C3: task time without heatmaps relative to the entire model (+: slower).
PAPER_C3_VS_C1: dict[str, dict[str, float]] = {
    "T1": {"house": -0.05, "hospital": 15.35, "office": 0.47},
    "T2": {"house": 3.98, "hospital": 1.75, "office": 2.75},
    "T4": {"hospital": 0.27},
}
_TABLE_II_ROWS = ("time_mean_s", "instances", "observations", "static_precision", "semantic_precision",
                  "walls_tp", "walls_fp", "tables_tp", "tables_fp", "furniture_fp", "door_fp",
                  "foreground_fp", "distance_mean_m")


def _cell(times: list[float], ok: list[bool]) -> dict[str, Any]:
    t = np.asarray(times, dtype=np.float64)
    return {
        "runs": len(ok), "successes": int(sum(ok)), "success_rate": float(np.mean(ok)) if ok else None,
        "median_time_s": float(np.median(t)) if t.size else None,
        "mean_time_s": float(t.mean()) if t.size else None, "times_s": [round(float(v), 2) for v in t],
    }


def summarize(result: BenchResult) -> dict[str, Any]:
    """The ``--json`` form of a run (also what the report renders)."""
    tasks: dict[str, dict[str, dict[str, Any]]] = {}
    reasons: dict[str, dict[str, dict[str, dict[str, int]]]] = {}
    for w in result.settings.worlds:
        tasks[w], reasons[w] = {}, {}
        for cfg in result.settings.configs:
            tasks[w][cfg.name], reasons[w][cfg.name] = {}, {}
            for task in TASKS:
                rs = [r for r in result.tasks if r.world == w and r.config == cfg.name and r.task == task]
                tasks[w][cfg.name][task] = _cell([r.time_s for r in rs], [r.success for r in rs])
                counts: dict[str, int] = {}
                for r in rs:
                    counts[r.reason] = counts.get(r.reason, 0) + 1
                reasons[w][cfg.name][task] = counts
    c3: dict[str, dict[str, Any]] = {}
    for task in ("T1", "T2", "T4"):
        c3[task] = {}
        for w in result.settings.worlds:
            a = tasks[w].get("C1", {}).get(task, {}).get("mean_time_s")
            b = tasks[w].get("C3", {}).get(task, {}).get("mean_time_s")
            c3[task][w] = {"ours": (b / a - 1.0) if a and b is not None else None,
                           "paper": PAPER_C3_VS_C1.get(task, {}).get(w)}
    t3_extra: dict[str, dict[str, Any]] = {}
    for w in result.settings.worlds:
        t3_extra[w] = {}
        for cfg in result.settings.configs:
            rs = [r for r in result.tasks if r.world == w and r.config == cfg.name and r.task == "T3"]
            errs = [r.extra["error_m"] for r in rs if r.extra.get("error_m") is not None]
            t3_extra[w][cfg.name] = {
                "support_known": float(np.mean([r.extra["support_known"] for r in rs])) if rs else None,
                "movers_tracked": bool(cfg.foreground),
                "movers_near_mean": float(np.mean([r.extra["movers_near"] for r in rs])) if rs else None,
                "plan_s": rs[0].extra["plan_s"] if rs else None,
                "error_m_median": float(np.median(errs)) if errs else None,
            }
    t4_extra = {
        w: {
            cfg.name: {
                "close_encounters_mean": (
                    float(np.mean([r.extra["close_encounters"] for r in rs])) if rs else None
                ),
                "waited_s_mean": float(np.mean([r.extra["waited_s"] for r in rs])) if rs else None,
                "path_m_mean": float(np.mean([r.extra["path_m"] for r in rs])) if rs else None,
            }
            for cfg in result.settings.configs
            for rs in [[r for r in result.tasks if r.world == w and r.config == cfg.name and r.task == "T4"]]
        }
        for w in result.settings.worlds
    }
    perception = {}
    for w, p in result.perception.items():
        t2 = None if p.table2 is None else {
            "ours": {k: p.table2.get(k) for k in _TABLE_II_ROWS}, "paper": p.table2.get("paper"),
            "note": "measured once: C1-C3 share the background stage; C4-C5 have none",
        }
        perception[w] = {"table2": t2, "table3": p.table3, "seconds": p.seconds}
    return {
        "settings": result.settings.to_dict(),
        "tasks": tasks,
        "reasons": reasons,
        "c3_vs_c1": c3,
        "t3": t3_extra,
        "t4": t4_extra,
        "perception": perception,
        "seconds": {k: round(v, 2) for k, v in result.seconds.items()},
    }
