"""Ground truth of a realistic development log (``gt/instances.json``), read into ``Truth``.

The layout (documented in full by the log's own ``gt/README.md``)::

    gt/instances.json     {"log", "t0", "rate_hz", "seed", "instances": [...]}: every instance
                          seen, with "class", "alt_classes", "layer", "static", "aabb_min",
                          "aabb_max", "plane" (building pieces), "observed", and for walking
                          people "speed_mps", "active_from_t" and "trajectory" ([t, x, y, z]
                          body-box centre per frame)
    gt/frames.jsonl       per frame: {"i", "t", "visible": {id: pixels}, "in_range": {...}}
    gt/instances/*.png    uint16 per-pixel ids, named like the rgb image, every 5th frame

Differences to ``hiper sim`` truth are mapped onto hiper's conventions: a table is a
background class (the paper's and the simulator's), a walking person is ``dynamic`` with a
track whose velocity is the time derivative of its trajectory, and the mapping phase ends
when the first person starts walking. Boxes are axis-aligned (a walker's: its body at its first
stamp, as in ``hiper sim`` truth); there are no recorded detections, so the ``truth`` detector does not apply.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.model import Box3D
from hiper_cli.perceive.logs.truth_types import Phase, Truth, TruthInstance

__all__ = ["WORLD_TRUTH_FILE", "load_world_truth"]

WORLD_TRUTH_FILE = "instances.json"
# Classes hiper recognises as background surfaces; the worlds put tables in the foreground.
_BACKGROUND_CLASSES = frozenset({"wall", "floor", "ceiling", "table"})


def load_world_truth(root: Path) -> Truth:
    """Read ``ROOT/gt/instances.json``; raise ``LogError`` naming the file when malformed."""
    path = root / "gt" / WORLD_TRUTH_FILE
    try:
        doc = json.loads(path.read_text())
        records = list(doc["instances"])
        instances = {int(d["id"]): _instance(d) for d in records}
        tracks = {
            int(d["id"]): _track(d["trajectory"]) for d in records if d.get("trajectory")
        }
        t0 = float(doc.get("t0", 0.0))
        t_end = t0 + float(doc.get("duration_s", 0.0))
    except (OSError, json.JSONDecodeError, KeyError, TypeError, ValueError, IndexError) as err:
        raise LogError(f"{path}: malformed ground truth ({err})") from err
    return Truth(
        world=str(doc.get("log", root.name)),
        seed=int(doc.get("seed", 0)),
        instances=instances,
        phases=_phases(records, t0, t_end),
        tracks=tracks,
        root=root,
        ids_dir="instances",
        frames_file="frames.jsonl",
    )


def _instance(d: dict[str, Any]) -> TruthInstance:
    lo = np.asarray(d["aabb_min"], dtype=np.float64)
    hi = np.asarray(d["aabb_max"], dtype=np.float64)
    class_name = str(d["class"])
    static = bool(d.get("static", True))
    layer = "background" if class_name in _BACKGROUND_CLASSES else str(d.get("layer", "foreground"))
    box = Box3D((lo + hi) / 2.0, hi - lo)
    body = _triple(d.get("body_size"))
    if body is not None and d.get("trajectory"):
        # Like hiper sim truth: a walker's box at its first stamp, with its body's extent.
        box = Box3D(np.asarray(d["trajectory"][0][1:4], dtype=np.float64), np.asarray(body))
    return TruthInstance(
        id=int(d["id"]),
        name=str(d.get("name", d["id"])),
        class_name=class_name,
        layer=layer,
        state="static" if static else "dynamic",
        box=box,
        plane=_plane(d.get("plane")),
        speed_mps=float(d["speed_mps"]) if d.get("speed_mps") is not None else None,
        alt_classes=tuple(str(c) for c in d.get("alt_classes", ())),
        observed=bool(d.get("observed", True)),
    )


def _plane(values: Any) -> tuple[float, float, float, float] | None:
    if not values:
        return None
    a, b, c, d = (float(v) for v in values)
    return (a, b, c, d)


def _triple(values: Any) -> tuple[float, float, float] | None:
    if not values:
        return None
    x, y, z = (float(v) for v in values)
    return (x, y, z)


def _track(rows: list[list[float]]) -> NDArray[np.float64]:
    """[t, x, y, z] rows -> [t, x, y, z, vx, vy, vz] rows, velocity by central differences."""
    txyz = np.asarray(rows, dtype=np.float64).reshape(-1, 4)
    txyz = txyz[np.argsort(txyz[:, 0], kind="stable")]
    if len(txyz) < 2:
        return np.hstack([txyz, np.zeros((len(txyz), 3))])
    vel = np.gradient(txyz[:, 1:4], txyz[:, 0], axis=0)
    return np.hstack([txyz, vel])


def _phases(records: list[dict[str, Any]], t0: float, t_end: float) -> list[Phase]:
    starts = [float(d["active_from_t"]) for d in records if d.get("active_from_t") is not None]
    if not starts:
        return [Phase("mapping", t0, t_end)]
    first = min(starts)
    return [Phase("mapping", t0, first), Phase("operation", first, max(t_end, first))]
