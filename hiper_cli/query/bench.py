"""Query benchmark (``hiper query bench``): latency of every query form on a synthetic KB at
scale (default 10 k instances, 1 M observations).

The synthetic building is a 40 m × 40 m floor with a grid of tables (background, tops at
0.75 m) carrying cups, bottles, books and laptops, chairs beside them, walking people (with
trajectories) and other furniture; every instance has ``observations / instances``
observations spread over its sighting window of a 3-hour timeline, and the robot's poses are
recorded along the way. Each query form runs ``queries`` times from random reference poses;
it reports p50/p95/max wall-clock and p95 CPU time (ms) per form, and the one-off cost of
reading the instance index (the first query of a process).
"""

from __future__ import annotations

import math
import os
import random
import statistics
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

__all__ = ["QUERY_FORMS", "QueryBenchConfig", "build_bench_kb", "run_query_bench"]

AREA_M = 40.0
TIMELINE_S = 10_800.0
QUERY_FORMS = (
    "cups in FOV",
    "closest table",
    "people moving in the last 10 minutes",
    "where was the bottle last seen",
    "how many chairs",
    "objects on the closest table",
    "when did a person last pass here",
)


@dataclass(frozen=True)
class QueryBenchConfig:
    instances: int = 10_000
    observations: int = 1_000_000
    queries: int = 50
    seed: int = 0
    obs_per_write: int = 2000


def _percentiles(samples_s: list[float]) -> dict[str, float]:
    xs = sorted(samples_s)
    return {
        "p50_ms": round(1000 * statistics.median(xs), 2),
        "p95_ms": round(1000 * xs[min(len(xs) - 1, math.ceil(0.95 * len(xs)) - 1)], 2),
        "max_ms": round(1000 * xs[-1], 2),
    }


def build_bench_kb(
    path: Path, config: QueryBenchConfig, progress: Callable[[int, int], None] | None = None
) -> None:
    """Fill a fresh knowledge base at ``path`` with the synthetic building."""
    import numpy as np

    from hiper_cli.graph.kb import open_kb
    from hiper_cli.model import Box3D, FrameResult, Instance, Observation

    rng = random.Random(config.seed)
    n_tables = max(1, config.instances // 50)
    side = math.ceil(math.sqrt(n_tables))
    step = AREA_M / side
    tables = [(((k % side) + 0.5) * step, ((k // side) + 0.5) * step) for k in range(n_tables)]
    specs: list[tuple[str, str, str, Any, Any, float]] = []  # layer, class, state, center, extent, speed
    for x, y in tables:
        specs.append(("background", "table", "static", (x, y, 0.74), (1.2, 0.8, 0.02), 0.0))
    while len(specs) < config.instances:
        x, y = rng.choice(tables)
        kind = rng.random()
        if kind < 0.35:  # on a table
            cls = rng.choice(("cup", "bottle", "book", "laptop"))
            h = {"cup": 0.1, "bottle": 0.3, "book": 0.04, "laptop": 0.03}[cls]
            specs.append(
                (
                    "foreground",
                    cls,
                    "static",
                    (x + rng.uniform(-0.5, 0.5), y + rng.uniform(-0.3, 0.3), 0.75 + h / 2),
                    (0.1, 0.1, h),
                    0.0,
                )
            )
        elif kind < 0.6:
            specs.append(
                (
                    "foreground",
                    "chair",
                    "static",
                    (x + rng.choice((-0.9, 0.9)), y + rng.uniform(-0.4, 0.4), 0.46),
                    (0.44, 0.44, 0.92),
                    0.0,
                )
            )
        elif kind < 0.8:
            specs.append(
                (
                    "foreground",
                    "person",
                    "dynamic",
                    (rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), 0.85),
                    (0.6, 0.6, 1.7),
                    rng.uniform(0.3, 1.4),
                )
            )
        else:
            cls = rng.choice(("tv", "couch", "potted plant", "bed", "shelf"))
            specs.append(
                (
                    "foreground",
                    cls,
                    "static",
                    (rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), 0.5),
                    (0.8, 0.5, 1.0),
                    0.0,
                )
            )
    per = max(1, config.observations // len(specs))
    with open_kb(path) as kb:
        env = kb.environment("bench")
        session = kb.start_session(env, "synthetic", ["bench"])
        result, written, pose_id = FrameResult(), 0, 0
        for layer, cls, state, c, e, speed in specs:
            t0 = rng.uniform(0, TIMELINE_S - per * 0.5)
            stamps = [t0 + 0.5 * k for k in range(per)]
            heading = rng.uniform(-math.pi, math.pi)
            v = np.array([math.cos(heading), math.sin(heading), 0.0]) * speed
            centers = [np.array(c) + v * (t - t0) for t in stamps]
            traj = (
                [[t, *p.tolist(), *v.tolist()] for t, p in zip(stamps[::10], centers[::10], strict=True)]
                if state == "dynamic"
                else []
            )
            inst = Instance(
                layer,  # type: ignore[arg-type]
                cls,
                Box3D(centers[-1], np.array(e)),
                stamps[0],
                stamps[-1],
                state=state,  # type: ignore[arg-type]
                confidence=round(rng.uniform(0.5, 1.0), 3),
                data={"trajectory": traj} if traj else {},
            )
            for t, p in zip(stamps, centers, strict=True):
                obs = Observation(
                    layer,  # type: ignore[arg-type]
                    cls,
                    inst.confidence,
                    t,
                    pose_id,
                    Box3D(p, np.array(e)),
                    instance_uuid=inst.uuid,
                )
                inst.observation_uuids.append(obs.uuid)
                result.observations.append(obs)
            result.instances.append(inst)
            if len(result.observations) >= config.obs_per_write:
                T = np.eye(4)
                T[:3, 3] = (rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), 1.2)
                # optical z axis level, looking along a random yaw
                yaw = rng.uniform(-math.pi, math.pi)
                T[:3, :3] = np.array(
                    [[math.sin(yaw), 0, math.cos(yaw)], [-math.cos(yaw), 0, math.sin(yaw)], [0, -1, 0]]
                )
                kb.write_frame(
                    session, result, pose_id=pose_id, stamp_s=TIMELINE_S * pose_id / 500, T_map_cam=T
                )
                written += len(result.observations)
                result, pose_id = FrameResult(), pose_id + 1
                if progress:
                    progress(written, per * len(specs))
        if result.observations:
            kb.write_frame(session, result, pose_id=pose_id, stamp_s=TIMELINE_S, T_map_cam=np.eye(4))
        kb.end_session(session)


def run_query_bench(
    config: QueryBenchConfig,
    *,
    kb_path: Path | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Build (or reuse, when ``kb_path`` holds one) the synthetic KB and time every form."""
    import tempfile

    from hiper_cli.graph.kb import is_knowledge_base, open_kb
    from hiper_cli.query import ask, trajectory, when
    from hiper_cli.query.describe import describe
    from hiper_cli.query.workspace import workspace

    tmp = None
    if kb_path is None:
        tmp = tempfile.TemporaryDirectory(prefix="hiper-query-bench-")
        kb_path = Path(tmp.name) / "bench.hiper"
    build_s = 0.0
    if not is_knowledge_base(kb_path):
        t0 = time.perf_counter()
        build_bench_kb(kb_path, config, progress)
        build_s = time.perf_counter() - t0
    rng = random.Random(config.seed + 1)
    forms: dict[str, dict[str, float]] = {}
    with open_kb(kb_path) as kb:
        counts = {k: v for k, v in kb.info()["totals"].items() if k in ("instance", "observation")}
        people = [i.uuid for i in kb.instances(class_name="person")[:200]]

        def pose() -> tuple[float, float, float, float]:
            return (rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), 1.2, rng.uniform(-math.pi, math.pi))

        def asking(words: str) -> Callable[[], Any]:
            return lambda: ask(kb, words, pose=pose())

        cases: dict[str, Callable[[], Any]] = {q: asking(q) for q in QUERY_FORMS}
        cases["when(uuid)"] = lambda: when(kb, rng.choice(people))
        cases["trajectory(uuid)"] = lambda: trajectory(kb, rng.choice(people))
        cases["workspace 1 m"] = lambda: workspace(kb, pose()[:3], 1.0)
        cases["describe"] = lambda: describe(kb)
        from hiper_cli.query import index as index_module

        index_module._CACHE.clear()
        w0, c0 = time.perf_counter(), time.process_time()
        index_module.instance_index(kb)
        cold = {
            "index_wall_ms": round(1000 * (time.perf_counter() - w0), 1),
            "index_cpu_ms": round(1000 * (time.process_time() - c0), 1),
        }
        for name, fn in cases.items():
            fn()  # warm the stores' caches once per form
            wall, cpu = [], []
            for _ in range(config.queries):
                w0, c0 = time.perf_counter(), time.process_time()
                fn()
                wall.append(time.perf_counter() - w0)
                cpu.append(time.process_time() - c0)
            forms[name] = {**_percentiles(wall), "cpu_p95_ms": _percentiles(cpu)["p95_ms"]}
    if tmp is not None:
        tmp.cleanup()
    return {
        "config": asdict(config),
        "kb": str(kb_path),
        "counts": counts,
        "build_s": round(build_s, 1),
        "cold": cold,
        "load_average": list(os.getloadavg()),
        "forms": forms,
    }
