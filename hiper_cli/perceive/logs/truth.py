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
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.model import Box3D

__all__ = ["Phase", "Truth", "TruthInstance", "load_truth"]


@dataclass(frozen=True)
class TruthInstance:
    id: int
    name: str
    class_name: str
    layer: str
    state: str
    box: Box3D
    plane: tuple[float, float, float, float] | None = None
    speed_mps: float | None = None
    # Other classes a detector may fairly report (a realistic world's ``alt_classes``).
    alt_classes: tuple[str, ...] = ()
    # Whether depth could map it (a realistic world's ``observed``; sim truth lists only these).
    observed: bool = True


@dataclass(frozen=True)
class Phase:
    name: str
    t_start_s: float
    t_end_s: float


@dataclass
class Truth:
    """Everything known about a simulated log."""

    world: str
    seed: int
    instances: dict[int, TruthInstance]
    phases: list[Phase]
    # id -> (T, 7) rows [stamp_s, x, y, z, vx, vy, vz], sorted by stamp
    tracks: dict[int, NDArray[np.float64]] = field(default_factory=dict)
    root: Path = Path(".")
    # Folder of the per-pixel id images under gt/, and the per-frame visibility file (or None).
    ids_dir: str = "instance_ids"
    frames_file: str | None = None

    def phase_at(self, stamp_s: float) -> str:
        for phase in self.phases:
            if phase.t_start_s <= stamp_s <= phase.t_end_s:
                return phase.name
        return "unknown"

    def instance_ids_path(self, rgb_relpath: str) -> Path:
        """The per-pixel id image that belongs to an rgb image path of ``rgb.txt``."""
        return self.root / "gt" / self.ids_dir / (Path(rgb_relpath).stem + ".png")

    def has_instance_ids(self, rgb_relpath: str) -> bool:
        """Whether this frame has an id image (realistic worlds label every 5th frame)."""
        return self.instance_ids_path(rgb_relpath).exists()

    def load_visibility(self, *, in_range: bool = False) -> dict[float, dict[int, int]]:
        """Visible pixels per instance per stamp (``gt/frames.jsonl``, realistic worlds);
        ``in_range``: only those with a depth return, where a record has them."""
        if self.frames_file is None:
            raise LogError(f"{self.root / 'gt'}: this truth has no per-frame visibility file")
        path = self.root / "gt" / self.frames_file
        try:
            lines = path.read_text().splitlines()
        except OSError as err:
            raise LogError(f"{path}: cannot read ({err.strerror})") from err
        out: dict[float, dict[int, int]] = {}
        for lineno, line in enumerate(lines, 1):
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
                counts = rec.get("in_range", rec["visible"]) if in_range else rec["visible"]
                out[float(rec["t"])] = {int(k): int(v) for k, v in counts.items()}
            except (json.JSONDecodeError, KeyError, TypeError, ValueError, AttributeError) as err:
                raise LogError(f"{path}:{lineno}: bad frame record ({err})") from err
        return out

    def load_instance_ids(self, rgb_relpath: str) -> NDArray[np.uint16]:
        import cv2

        path = self.instance_ids_path(rgb_relpath)
        ids = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        if ids is None or ids.dtype != np.uint16:
            raise LogError(f"{path}: missing or not a 16-bit id image; regenerate with hiper sim")
        return np.asarray(ids, dtype=np.uint16)

    def position_at(self, instance_id: int, stamp_s: float) -> NDArray[np.float64] | None:
        """Box centre of a dynamic instance at ``stamp_s`` (linear interpolation), else None."""
        rows = self.tracks.get(instance_id)
        if rows is None or len(rows) == 0 or not rows[0, 0] <= stamp_s <= rows[-1, 0]:
            return None
        return np.array([np.interp(stamp_s, rows[:, 0], rows[:, k]) for k in (1, 2, 3)])

    def load_detections(self) -> dict[float, list[dict[str, Any]]]:
        """Noisy truth detections per stamp (``gt/detections.jsonl``)."""
        path = self.root / "gt" / "detections.jsonl"
        if not path.exists():
            raise LogError(f"{path}: not found; regenerate the log with hiper sim")
        out: dict[float, list[dict[str, Any]]] = {}
        with path.open() as fh:
            for lineno, line in enumerate(fh, 1):
                if not line.strip():
                    continue
                try:
                    rec = json.loads(line)
                    out[float(rec["stamp_s"])] = list(rec["detections"])
                except (json.JSONDecodeError, KeyError, TypeError, ValueError) as err:
                    raise LogError(f"{path}:{lineno}: bad detection record ({err})") from err
        return out


def load_truth(log_dir: str | Path) -> Truth:
    """Read ``LOG/gt`` (``hiper sim`` truth, or a realistic world's ``gt/instances.json``).

    Raises ``LogError`` naming the file when it is missing or malformed.
    """
    root = Path(log_dir)
    world_path = root / "gt" / "world.json"
    if not world_path.exists():
        from .world_truth import WORLD_TRUTH_FILE, load_world_truth

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
