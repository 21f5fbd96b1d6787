"""Knowledge-base benchmark at the paper's scale (``hiper kb bench``).

For each size a fresh knowledge base is filled, in a child process (so its peak memory is its
own), with synthetic perception frames: ``obs_per_frame`` foreground observations per frame,
each linked to a short-lived instance (a track of ``track_frames`` frames) that is upserted in
the same per-frame transaction, exactly as ``hiper perceive`` writes. Half of the instances
stand, half walk at up to 1.4 m/s (with 2 cm of jitter per observation) on a 40 m x 40 m floor
(0.2-2.0 m high); the camera pose is random per frame. It reports:

* ingest rate of the documents (observations/s, per-frame transactions, the writer's time),
* graph synchronisation rate (observations/s, the high-water-mark replay), by default in a
  ``GraphFollower`` process beside the writer (``follower=False``: in the writer, every
  ``graph_sync_s``, as ``hiper perceive`` does), and the end-to-end rate: documents and graph
  both up to date (the generator's own time excluded);
* p50/p95 latency of: a document by uuid, observations of one class in a 10 s window,
  the observations of one instance, a 1 m spatial box query (and how many observations it
  returns on average), and a SPARQL query on the graph,
* peak resident memory of the writer (overall, and before the queries and final sync) and of
  the follower.
"""

from __future__ import annotations

import os
import random
import resource
import statistics
import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError
from hiper_cli.files import folder_bytes

__all__ = ["BenchConfig", "parse_sizes", "run_bench", "run_size"]

AREA_M = 40.0  # the synthetic building floor, AREA_M x AREA_M; objects 0.2-2.0 m high
CLASSES = ("person", "chair", "cup", "bottle", "laptop", "book", "tv", "couch", "bed", "dog")


@dataclass(frozen=True)
class BenchConfig:
    obs_per_frame: int = 20
    track_frames: int = 100
    frame_hz: float = 10.0
    queries: int = 200
    instance_updates: bool = True
    seed: int = 0
    observation_detail: str = "batch"
    graph_sync_s: float = 2.0
    follower: bool = True


def _percentiles(samples_s: Sequence[float]) -> dict[str, float]:
    xs = sorted(samples_s)
    if not xs:
        return {"p50_ms": 0.0, "p95_ms": 0.0}
    return {
        "p50_ms": round(1000 * statistics.median(xs), 3),
        "p95_ms": round(1000 * xs[min(len(xs) - 1, int(0.95 * len(xs)))], 3),
    }


def _time(fn: Callable[[], Any], n: int) -> list[float]:
    out = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def run_size(n_obs: int, root: str, config: BenchConfig) -> dict[str, Any]:
    """Fill a fresh knowledge base at ``root`` with ``n_obs`` observations and measure it."""
    import numpy as np

    from hiper_cli.graph.follower import GraphFollower
    from hiper_cli.graph.kb import KbConfig, open_kb
    from hiper_cli.model import Box3D, FrameResult, Instance, Observation

    rng = random.Random(config.seed)
    kb = open_kb(Path(root) / "bench.hiper", config=KbConfig(observation_detail=config.observation_detail))
    env = kb.environment("bench")
    session = kb.start_session(env, "synthetic", ["bench"])
    k = config.obs_per_frame
    tracks: list[Instance] = []
    frames = (n_obs + k - 1) // k
    written = 0
    ingest_s = ingest_cpu_s = 0.0
    sync_s = sync_cpu_s = 0.0
    last_sync = time.perf_counter()
    sample_obs: list[str] = []
    sample_inst: list[str] = []
    T = np.eye(4)
    velocity: dict[str, Any] = {}
    true_map: dict[str, Any] = {}
    dt = 1.0 / config.frame_hz
    inline = not config.follower
    follower = GraphFollower(kb, interval_s=config.graph_sync_s or 1.0).start() if config.follower else None
    for f in range(frames):
        stamp = f / config.frame_hz
        if f % config.track_frames == 0 or not tracks:
            # a new group of objects on the floor; half of them walk (<= 1.4 m/s)
            tracks = [
                Instance("foreground", rng.choice(CLASSES), Box3D(np.array(
                    [rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), rng.uniform(0.2, 2.0)]),
                    np.full(3, 0.3)), stamp, stamp, state="dynamic")
                for _ in range(k)
            ]
            velocity = {t.uuid: np.array([rng.uniform(-1, 1), rng.uniform(-1, 1), 0.0]) * (j % 2)
                        for j, t in enumerate(tracks)}
            true_map = {t.uuid: t.box.center_m for t in tracks}
        T[:3, 3] = (rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), 1.2)  # the camera anywhere
        result = FrameResult()
        for inst in tracks[: min(k, n_obs - written)]:
            true_map[inst.uuid] = true_map[inst.uuid] + velocity[inst.uuid] * dt
            center_map = true_map[inst.uuid] + np.array([rng.gauss(0, 0.02) for _ in "xyz"])
            center = T[:3, :3].T @ (center_map - T[:3, 3])  # in the camera frame
            obs = Observation("foreground", inst.class_name, rng.random(), stamp, f,
                              Box3D(center, np.array([0.3, 0.4, 0.3])), instance_uuid=inst.uuid,
                              data={"image_box_xyxy": [10.0, 20.0, 60.0, 90.0]})
            inst.observation_uuids.append(obs.uuid)
            inst.last_seen_s = stamp
            inst.box = Box3D(center_map, inst.box.extent_m)
            result.observations.append(obs)
            if config.instance_updates:
                result.instances.append(inst)
            if rng.random() < 0.01:
                sample_obs.append(obs.uuid)
                sample_inst.append(inst.uuid)
        t0, c0 = time.perf_counter(), time.process_time()
        kb.write_frame(session, result, pose_id=f, stamp_s=stamp, T_map_cam=T)
        ingest_s += time.perf_counter() - t0
        ingest_cpu_s += time.process_time() - c0
        written += len(result.observations)
        if inline and config.graph_sync_s > 0 and time.perf_counter() - last_sync >= config.graph_sync_s:
            t0, c0 = time.perf_counter(), time.process_time()
            kb.sync_graph()
            sync_s += time.perf_counter() - t0
            sync_cpu_s += time.process_time() - c0
            last_sync = time.perf_counter()
    kb.end_session(session)
    peak_rss_ingest_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    follower_report = None
    if follower is not None:
        follower_report = follower.stop()
        sync_s, sync_cpu_s = follower_report.sync_s, follower_report.cpu_s
        # the two processes work in parallel (the generator's own time excluded): done when
        # the writer is done and the follower has caught up, or when the follower has spent
        # its time syncing, whichever is later
        end_to_end_s = max(ingest_s + follower_report.catch_up_s, follower_report.sync_s)
    else:
        t0, c0 = time.perf_counter(), time.process_time()
        kb.sync_graph()
        sync_s += time.perf_counter() - t0
        sync_cpu_s += time.process_time() - c0
        end_to_end_s = ingest_s + sync_s
    duration = frames / config.frame_hz
    q = config.queries
    docs = kb.docs

    def by_uuid() -> None:
        assert docs.get(rng.choice(sample_obs)) is not None

    def by_class_window() -> None:
        t = rng.uniform(0, max(0.0, duration - 10))
        docs.find(type="observation", class_name=rng.choice(CLASSES), t_start_s=t, t_end_s=t + 10)

    def of_instance() -> None:
        assert docs.observations_of(rng.choice(sample_inst))

    found: list[int] = []

    def spatial() -> None:
        lo = [rng.uniform(0, AREA_M - 1), rng.uniform(0, AREA_M - 1), rng.uniform(0, 2)]
        found.append(len(docs.in_box(lo, [lo[0] + 1, lo[1] + 1, lo[2] + 1], type="observation")))

    def sparql_class() -> None:
        kb.query(f'SELECT ?i WHERE {{ GRAPH ?g {{ ?i hiper:className "{rng.choice(CLASSES)}" ; '
                 f'a hiper:Instance ; hiper:lastSeenS ?t FILTER(?t > {rng.uniform(0, duration):.1f}) }} }} '
                 "LIMIT 50")

    latencies = {
        "by_uuid": _percentiles(_time(by_uuid, q)),
        "class_in_10s_window": _percentiles(_time(by_class_window, q)),
        "observations_of_instance": _percentiles(_time(of_instance, q)),
        "spatial_1m_box": _percentiles(_time(spatial, q)),
        "sparql_instances_of_class": _percentiles(_time(sparql_class, max(10, q // 4))),
    }
    check = kb.check(repair=False)
    size = folder_bytes(Path(root) / "bench.hiper")
    kb.close()
    return {
        "observations": written,
        "frames": frames,
        "ingest_obs_per_s": round(written / ingest_s, 1),
        "graph_sync_obs_per_s": round(written / sync_s, 1) if sync_s > 0 else None,
        "graph": "follower process" if config.follower else "in the writer",
        "end_to_end_obs_per_s": round(written / end_to_end_s, 1),
        "ingest_obs_per_cpu_s": round(written / ingest_cpu_s, 1) if ingest_cpu_s > 0 else None,
        "graph_sync_obs_per_cpu_s": round(written / sync_cpu_s, 1) if sync_cpu_s > 0 else None,
        "load_average_1min": round(os.getloadavg()[0], 2),
        "ingest_s": round(ingest_s, 2),
        "graph_sync_s": round(sync_s, 2),
        "latency": latencies,
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
        "peak_rss_before_final_sync_mb": round(peak_rss_ingest_mb, 1),
        "follower_peak_rss_mb": round(follower_report.peak_rss_mb, 1) if follower_report else None,
        "follower_catch_up_s": round(follower_report.catch_up_s, 2) if follower_report else None,
        "size_on_disk_mb": round(size / 1e6, 1),
        "spatial_1m_box_results_mean": round(statistics.fmean(found), 1) if found else 0.0,
        "consistent": check.ok,
        "config": asdict(config),
    }


def _child(n_obs: int, config: BenchConfig) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="hiper-bench-") as root:
        return run_size(n_obs, root, config)


def parse_sizes(text: str) -> list[int]:
    """``"10000,100000"`` -> ``[10000, 100000]``: the observation counts to measure."""
    try:
        counts = [int(s) for s in text.split(",") if s.strip()]
    except ValueError as err:
        raise ConfigError(f"--sizes {text!r}: expected comma-separated integers, e.g. 10000,100000") from err
    if not counts or min(counts) <= 0:
        raise ConfigError(f"--sizes {text!r}: expected positive observation counts")
    return counts


def run_bench(
    sizes: Sequence[int],
    config: BenchConfig | None = None,
    on_result: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``run_size`` for each size in its own child process (a fresh interpreter)."""
    config = config or BenchConfig()
    results = []
    for n in sizes:
        with ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn")) as pool:
            result = pool.submit(_child, int(n), config).result()
        results.append(result)
        if on_result is not None:
            on_result(result)
    return results
