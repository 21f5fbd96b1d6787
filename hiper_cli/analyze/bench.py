"""``hiper analyze bench``: features and a heatmap on a knowledge base of two hours of data.

The knowledge base is filled once (then reused) with synthetic but realistically shaped data:
a 40 m x 40 m floor with walls, 10 frames/s for ``hours``, 14 foreground observations a frame
(> 1 M in 2 h), each linked to its track; tracks of 10 classes, people walking at 0.6-1.2 m/s
with pauses, the rest standing with noise, half of the tracks long enough (> 256 rows) that
their rows live in the trajectories table. Each measurement runs in a fresh process
(``spawn``), so its peak memory is its own; ``seconds`` is the first library call (reading,
computing, writing the files and the analysis documents), ``warm_s`` a second one in the same
process, ``open_call_close_s`` the first call plus opening the knowledge base and closing it
(which brings the scene graph up to date). ``cache`` first brings the trajectory column cache
(``graph.track_cache``) up to date, as the first analysis after a perception run does.
"""

from __future__ import annotations

import resource
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BUDGETS_S", "PEAK_BUDGET_MB", "fill_bench_kb", "run_analyze_bench"]

BUDGETS_S = {"features": 2.0, "heatmap": 1.0}
PEAK_BUDGET_MB = 500.0
AREA_M = 40.0
HZ = 10.0
OBS_PER_FRAME = 14
CLASSES = ("person", "chair", "cup", "bottle", "laptop", "book", "tv", "couch", "bed", "dog")


def _track_rows(rng: np.random.Generator, t0: float, n: int, walker: bool) -> np.ndarray:
    t = t0 + np.arange(n) / HZ
    v = np.zeros((n, 3))
    if walker:
        heading = rng.uniform(0, 2 * np.pi)
        speed = rng.uniform(0.6, 1.2)
        moving = (np.arange(n) // 50) % 3 != 2  # walk 10 s, stand 5 s
        v[:, 0], v[:, 1] = speed * np.cos(heading) * moving, speed * np.sin(heading) * moving
    start = rng.uniform(5, AREA_M - 5, 2)
    xy = start + np.cumsum(v[:, :2], axis=0) / HZ
    xy = np.clip(xy, 0.5, AREA_M - 0.5)
    v[:, :2] += rng.normal(0, 0.03, (n, 2))
    return np.column_stack([t, xy, np.full(n, 0.9), v])


def fill_bench_kb(root: Path, hours: float = 2.0, seed: int = 0) -> dict[str, Any]:
    """Fill a fresh knowledge base at ``root`` (see the module doc); returns its sizes."""
    from hiper_cli.graph.kb import open_kb
    from hiper_cli.model import Box3D, Instance

    t_fill = time.perf_counter()
    rng = np.random.default_rng(seed)
    kb = open_kb(root)
    env = kb.environment("bench")
    walls = [
        Instance(
            "background",
            "floor",
            Box3D(np.array([AREA_M / 2, AREA_M / 2, -0.01]), np.array([AREA_M, AREA_M, 0.02])),
            0,
            0,
        )
    ]
    for cx, cy, ex, ey in (
        (AREA_M / 2, 0, AREA_M, 0.1),
        (AREA_M / 2, AREA_M, AREA_M, 0.1),
        (0, AREA_M / 2, 0.1, AREA_M),
        (AREA_M, AREA_M / 2, 0.1, AREA_M),
    ):
        walls.append(
            Instance("background", "wall", Box3D(np.array([cx, cy, 1.4]), np.array([ex, ey, 2.8])), 0, 0)
        )
    kb.put_documents([w.to_dict() for w in walls], env_uuid=env.uuid)
    frames = int(hours * 3600 * HZ)
    observations = rows_total = instances = 0
    slots: list[tuple[Instance, np.ndarray, int]] = []  # instance, its rows, next row index
    for start in range(0, frames, 600):  # one transaction per minute of data
        items: list[dict[str, Any]] = []
        done: list[Instance] = []
        for f in range(start, min(start + 600, frames)):
            stamp = f / HZ
            while len(slots) < OBS_PER_FRAME:
                name = CLASSES[int(rng.integers(len(CLASSES)))] if rng.random() > 0.4 else "person"
                n = int(rng.choice([60, 400])) if name == "person" else int(rng.choice([60, 300]))
                r = _track_rows(rng, stamp, n, walker=name == "person")
                inst = Instance("foreground", name, Box3D(r[0, 1:4], np.array([0.5, 0.4, 1.7])), stamp, stamp)
                slots.append((inst, r, 0))
            kept = []
            for inst, r, k in slots:
                c = r[k, 1:4]
                box = {"center_m": [0.0, 0.0, 2.0], "extent_m": [0.3, 0.4, 0.3], "R": np.eye(3).tolist()}
                obs: dict[str, Any] = {
                    "uuid": f"o{observations:09d}",
                    "type": "observation",
                    "layer": "foreground",
                    "class": inst.class_name,
                    "confidence": 0.8,
                    "stamp_s": stamp,
                    "pose_id": f,
                    "frame_id": "camera",
                    "box": box,
                    "instance_uuid": inst.uuid,
                    "data": {"center_map": c.tolist(), "image_box_xyxy": [10.0, 20.0, 60.0, 90.0]},
                }
                observations += 1
                inst.observation_uuids.append(str(obs["uuid"]))
                items.append(obs)
                if k + 1 == len(r):
                    inst.box = Box3D(c, inst.box.extent_m)
                    inst.last_seen_s = float(r[-1, 0])
                    inst.data = {"trajectory": r.tolist(), "closed": True}
                    done.append(inst)
                    rows_total += len(r)
                else:
                    kept.append((inst, r, k + 1))
            slots = kept
        kb.put_batch(items, done, env_uuid=env.uuid)
        instances += len(done)
    kb.sync_graph()
    kb.close()
    return {
        "observations": observations,
        "instances": instances,
        "trajectory_rows": rows_total,
        "hours": hours,
        "fill_s": round(time.perf_counter() - t_fill, 1),
    }


def _measure(root: str, what: str) -> dict[str, Any]:
    import tempfile

    import cv2  # noqa: F401  (imports are the interpreter's start-up, not the analysis)

    from hiper_cli.analyze.features import learn_features
    from hiper_cli.analyze.generate import generate_heatmap
    from hiper_cli.graph.kb import open_kb

    t_open = time.perf_counter()
    if what == "cache":
        with open_kb(root) as kb:
            n = len(kb.trajectory_columns().rows)
        return {"seconds": round(time.perf_counter() - t_open, 3), "rows": n}
    with open_kb(root) as kb, tempfile.TemporaryDirectory() as out:
        times = []
        for _ in range(2):  # the first call is what a command pays; the second is warm
            t0 = time.perf_counter()
            if what == "features":
                report, _ = learn_features(kb, None, store=True)
                detail: dict[str, Any] = {
                    "classes": len(report.classes),
                    "rows": sum(c.ods.rows for c in report.classes),
                }
            else:
                result = generate_heatmap(kb, "person", out_dir=out)
                detail = {
                    "rows": result.heatmap.rows,
                    "shape": list(result.heatmap.heat.shape),
                    "files": len(result.files),
                }
            times.append(time.perf_counter() - t0)
    seconds = times[0]
    detail["warm_s"] = round(times[1], 3)
    detail["open_call_close_s"] = round(time.perf_counter() - t_open - times[1], 3)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {
        "seconds": round(seconds, 3),
        "budget_s": BUDGETS_S[what],
        "peak_rss_mb": round(peak, 1),
        "within_budget": seconds <= BUDGETS_S[what] and peak <= PEAK_BUDGET_MB,
    } | detail


def run_analyze_bench(root: str | Path, hours: float = 2.0) -> dict[str, Any]:
    """Fill ``root`` unless it holds a knowledge base, then time features and a heatmap, each
    in a fresh process; returns the sizes and the measurements."""
    path = Path(root)
    from hiper_cli.graph.kb import is_knowledge_base, open_kb

    if is_knowledge_base(path):
        with open_kb(path) as kb:
            held = kb.sizes()
        sizes = {
            "observations": held.documents.get("observation", 0),
            "instances": held.documents.get("instance", 0),
            "trajectory_rows": held.trajectory_rows,
            "hours": None,
            "fill_s": 0.0,
        }
    else:
        sizes = fill_bench_kb(path, hours)
    out: dict[str, Any] = {"kb": sizes, "peak_budget_mb": PEAK_BUDGET_MB}
    for what in ("cache", "features", "heatmap"):
        with ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn")) as pool:
            out[what] = pool.submit(_measure, str(path), what).result()
    return out
