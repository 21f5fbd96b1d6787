"""Ground truth of a log: the ``gt/`` folder written by ``hiper sim`` (a realistic world's
``gt/instances.json`` is read by ``world_truth.py`` into the same ``Truth``).

The layout, beside the TUM RGB-D files of the log (``rgb.txt``, ``depth.txt``,
``groundtruth.txt`` = T_map_cam per stamp, ``camera.json``)::

    gt/world.json           {"world", "seed", "rate_hz", "instances": [...], "phases": [...]}
                            plus, from hiper sim: "bounds_m" [x0, y0, x1, y1], "ceiling_m",
                            "walls_xy" (wall footprints [x0, y0, x1, y1]), "robot" (speed, camera
                            height and pitch); the loader ignores them
    gt/tracks.csv           stamp_s,id,x,y,z,vx,vy,vz  (box centre of every dynamic instance,
                            map frame, at every image stamp while it exists)
    gt/instance_ids/*.png   uint16 per-pixel instance id, same file stem as the rgb image,
                            0 = no return (sky, beyond range)
    gt/detections.jsonl     one line per image: {"stamp_s", "detections": [{"xyxy", "class",
                            "score", "instance_id"}]}; noisy detections derived from the truth
                            (instance_id null for a false positive); the ``truth`` detector
    gt/noise.json           the detection noise model used

An instance in ``world.json``::

    {"id": 7, "name": "person_0", "class": "person", "layer": "foreground",
     "state": "dynamic", "box": {"center_m": [...], "extent_m": [...], "R": [[...]]},
     "plane": [a, b, c, d] | null, "speed_mps": 0.6 | null}

``box`` is in the map frame (for a dynamic instance: its box at the first stamp; its extent
is valid throughout). Background classes are ``wall``, ``floor``, ``ceiling``, ``table``,
``door``; foreground classes use COCO names where one exists (``person``, ``chair``,
``couch``, ``bed``, ``bottle``, ``cup``, ``tv``, ``potted plant``) and plain names otherwise
(``shelf``, ``cart``, ``picture``). Table tops and desks are background ``table`` (COCO's
``dining table`` is not used for them). Phases: ``mapping`` (no people)
then ``operation``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from hiper_cli.errors import LogError
from hiper_cli.model import Box3D
from hiper_cli.perceive.logs.truth_types import Phase, Truth, TruthInstance
from hiper_cli.perceive.logs.world_truth import WORLD_TRUTH_FILE, load_world_truth

__all__ = ["Phase", "Truth", "TruthInstance", "load_truth"]


def load_truth(log_dir: str | Path) -> Truth:
    """Read ``LOG/gt`` (``hiper sim`` truth, or a realistic world's ``gt/instances.json``).

    Raises ``LogError`` naming the file when it is missing or malformed.
    """
    root = Path(log_dir)
    world_path = root / "gt" / "world.json"
    if not world_path.exists():
        if (root / "gt" / WORLD_TRUTH_FILE).exists():
            return load_world_truth(root)
        raise LogError(
            f"{world_path}: not found; ground truth is gt/world.json (hiper sim) or "
            f"gt/{WORLD_TRUTH_FILE} (a realistic world)"
        )
    try:
        world = json.loads(world_path.read_text())
        instances = {
            int(d["id"]): TruthInstance(
                id=int(d["id"]),
                name=str(d.get("name", d["id"])),
                class_name=str(d["class"]),
                layer=str(d["layer"]),
                state=str(d.get("state", "static")),
                box=Box3D.from_dict(d["box"]),
                plane=tuple(d["plane"]) if d.get("plane") else None,
                speed_mps=d.get("speed_mps"),
            )
            for d in world["instances"]
        }
        phases = [Phase(p["name"], float(p["t_start_s"]), float(p["t_end_s"])) for p in world["phases"]]
    except (json.JSONDecodeError, KeyError, TypeError, ValueError) as err:
        raise LogError(f"{world_path}: malformed ground truth ({err})") from err

    tracks: dict[int, list[list[float]]] = {}
    tracks_path = root / "gt" / "tracks.csv"
    if tracks_path.exists():
        with tracks_path.open(newline="") as fh:
            for row in csv.DictReader(fh):
                tracks.setdefault(int(row["id"]), []).append(
                    [float(row[k]) for k in ("stamp_s", "x", "y", "z", "vx", "vy", "vz")]
                )
    return Truth(
        world=str(world.get("world", "")),
        seed=int(world.get("seed", 0)),
        instances=instances,
        phases=phases,
        tracks={k: np.array(sorted(v)) for k, v in tracks.items()},
        root=root,
    )
