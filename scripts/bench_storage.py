"""Storage figures of issue 55: knowledge-base bytes per log, per session and per minute, and
the time ``hiper kb compact`` takes on a knowledge base of many observations.

  bench_storage.py size KB...            bytes of each knowledge base folder and what holds them
  bench_storage.py fill KB N             a synthetic KB of N observations of still objects
  bench_storage.py compact KB            time compaction of KB (a copy is compacted: KB.compacted)
  bench_storage.py prefix LOG SECONDS OUT   the first SECONDS of a TUM log folder as folder OUT
                                         (links to its images and truth, its lists cut)

``size`` prints the folder's bytes (documents, graph), per table and per document kind; the
perceive runs that make the knowledge bases are in docs/results/2026-12-07-bounded-storage.md.
"""

from __future__ import annotations

import json
import random
import shutil
import sqlite3
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from hiper_cli.graph import open_kb
from hiper_cli.graph.compact import compact
from hiper_cli.model import Box3D, FrameResult, Instance, Observation

AREA_M = 40.0  # still objects spread on a floor this wide
PER_FRAME = 1000  # observations a frame
OBJECTS = 2000  # still objects; a frame sees half of them
HZ = 10.0


def folder_bytes(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def size(kb: Path) -> dict[str, object]:
    """Bytes of a knowledge base: the folder, the documents file, the graph, per table, per kind."""
    db = sqlite3.connect(f"file:{kb / 'documents.sqlite'}?mode=ro", uri=True)
    try:
        tables = dict(db.execute("SELECT name, SUM(pgsize) FROM dbstat GROUP BY name ORDER BY 2 DESC"))
        kinds = [(t, layer, cls, n, b) for t, layer, cls, n, b in db.execute(
            "SELECT type, layer, class, COUNT(*), SUM(LENGTH(body)) FROM docs GROUP BY 1, 2, 3 "
            "ORDER BY 5 DESC")]
        sessions = [s for (s,) in db.execute("SELECT id FROM sessions ORDER BY id")]
    finally:
        db.close()
    graph = folder_bytes(kb / "graph")
    return {"kb": str(kb), "bytes": folder_bytes(kb), "documents_bytes": folder_bytes(kb) - graph,
            "graph_bytes": graph, "sessions": len(sessions),
            "observations": sum(n for t, _, _, n, _ in kinds if t == "observation"),
            "tables": {k: v for k, v in tables.items() if v > 16384}, "largest_kinds": kinds[:8]}


def _frames(n_obs: int, seed: int = 0) -> Iterator[tuple[int, float, FrameResult]]:
    """Frames of still objects (2 cm jitter), ``PER_FRAME`` observations each, ``HZ``."""
    rng = random.Random(seed)
    objects = [Instance("foreground", rng.choice(("chair", "cup", "bottle", "tv", "book")), Box3D(
        np.array([rng.uniform(0, AREA_M), rng.uniform(0, AREA_M), rng.uniform(0.2, 2.0)]), np.full(3, 0.3)),
        0.0, 0.0) for _ in range(OBJECTS)]
    f = 0
    written = 0
    while written < n_obs:
        stamp = f / HZ
        result = FrameResult()
        start = (f * PER_FRAME // 2) % OBJECTS
        for inst in [objects[(start + k) % OBJECTS] for k in range(min(PER_FRAME, n_obs - written))]:
            center = inst.box.center_m + np.array([rng.gauss(0, 0.02) for _ in "xyz"])
            obs = Observation("foreground", inst.class_name, 0.8, stamp, f, Box3D(center, np.full(3, 0.3)),
                              instance_uuid=inst.uuid, data={"image_box_xyxy": [10.0, 20.0, 60.0, 90.0]})
            inst.observation_uuids.append(obs.uuid)
            if not inst.first_seen_s and not f:
                inst.first_seen_s = stamp
            inst.last_seen_s = stamp
            result.observations.append(obs)
            if len(inst.observation_uuids) == 1:
                result.instances.append(inst)
        written += len(result.observations)
        yield f, stamp, result
        f += 1
    last = FrameResult()
    last.instances = [i for i in objects if i.observation_uuids]
    yield -1, 0.0, last


def fill(kb_path: Path, n_obs: int) -> None:
    started = time.perf_counter()
    with open_kb(kb_path) as kb:
        env = kb.environment("synthetic")
        session = kb.start_session(env, "synthetic", ["foreground"])
        for f, stamp, result in _frames(n_obs):
            if f < 0:
                kb.write_frame(session, result)
            else:
                kb.write_frame(session, result, pose_id=f, stamp_s=stamp, T_map_cam=np.eye(4))
        kb.end_session(session)
        kb.sync_graph()
        n = kb.docs.count(type="observation")
    seconds = round(time.perf_counter() - started, 1)
    print(json.dumps({"filled": str(kb_path), "observations": n, "seconds": seconds,
                      "bytes": folder_bytes(kb_path)}))


def compact_timed(kb_path: Path) -> None:
    copy = kb_path.with_name(kb_path.name + ".compacted")
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(kb_path, copy)
    with open_kb(copy) as kb:
        report = compact(kb)
    print(json.dumps({"kb": str(copy), **report.to_dict()}))


def prefix(log: Path, seconds: float, out: Path) -> None:
    """The frames of ``log`` stamped before its first stamp + ``seconds``, as a log folder."""
    out.mkdir(parents=True, exist_ok=False)
    first = None
    for entry in sorted(log.iterdir()):
        if entry.suffix != ".txt":
            (out / entry.name).symlink_to(entry.resolve())
            continue
        lines = []
        for line in entry.read_text().splitlines():
            if not line.strip() or line.startswith("#"):
                lines.append(line)
                continue
            stamp = float(line.split()[0])
            first = stamp if first is None else min(first, stamp)
            if stamp < first + seconds:
                lines.append(line)
        (out / entry.name).write_text("\n".join(lines) + "\n")
    print(json.dumps({"prefix": str(out), "seconds": seconds}))


def main(argv: list[str]) -> None:
    if len(argv) >= 2 and argv[0] == "size":
        for kb in argv[1:]:
            print(json.dumps(size(Path(kb))))
    elif len(argv) == 3 and argv[0] == "fill":
        fill(Path(argv[1]), int(float(argv[2])))
    elif len(argv) == 2 and argv[0] == "compact":
        compact_timed(Path(argv[1]))
    elif len(argv) == 4 and argv[0] == "prefix":
        prefix(Path(argv[1]), float(argv[2]), Path(argv[3]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
