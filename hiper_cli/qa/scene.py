"""What a log's ground truth says the robot saw: per instance the stamps at which it was in
view (enough pixels with a depth return), its position then, and the robot's final pose.
Reads ``hiper sim`` truth (per-frame id images) and a realistic world's ``gt/`` (per-frame
visibility in ``frames.jsonl``), both through ``load_truth``."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.truth import Truth, TruthInstance, load_truth

__all__ = ["BUILDING", "SceneTruth", "load_scene_truth"]

# Building pieces and catch-all classes: no question is asked about them.
BUILDING = frozenset({"wall", "floor", "ceiling", "other", "unknown"})


@dataclass
class SceneTruth:
    """``seen[id]``: sorted stamps (s) at which instance ``id`` covered at least
    ``min_pixels`` pixels with depth; ``pose``: the robot's last camera pose (x, y, z, yaw)."""

    truth: Truth
    stamps: NDArray[np.float64]
    seen: dict[int, NDArray[np.float64]]
    pose: tuple[float, float, float, float]
    min_pixels: int

    @property
    def now_s(self) -> float:
        return float(self.stamps[-1])

    @property
    def start_s(self) -> float:
        return float(self.stamps[0])

    def instances(self, class_name: str) -> list[TruthInstance]:
        return [i for i in self.truth.instances.values() if i.class_name == class_name and i.id in self.seen]

    def classes(self) -> list[str]:
        return sorted({i.class_name for i in self.truth.instances.values()
                       if i.id in self.seen and i.class_name not in BUILDING})

    def position_at(self, inst: TruthInstance, stamp_s: float) -> NDArray[np.float64]:
        """Box centre (map frame) of ``inst`` at ``stamp_s``: its track for a mover."""
        pos = self.truth.position_at(inst.id, stamp_s)
        return np.asarray(inst.box.center_m, dtype=np.float64) if pos is None else pos

    def last_position(self, inst: TruthInstance) -> NDArray[np.float64]:
        return self.position_at(inst, float(self.seen[inst.id][-1]))

    def distance_m(self, inst: TruthInstance) -> float:
        """Horizontal distance from the robot's last position to the box footprint (the query
        layer's distance), the box where it was last seen."""
        c = self.last_position(inst)
        # the footprint of the (possibly rotated) box: its axis-aligned hull
        R = np.asarray(inst.box.R, dtype=np.float64)
        half = np.abs(R[:2, :]) @ (np.asarray(inst.box.extent_m, dtype=np.float64) / 2.0)
        d = np.maximum(np.abs(np.array(self.pose[:2]) - c[:2]) - half, 0.0)
        return float(math.hypot(*d))


def _tum(path: Path) -> list[list[str]]:
    try:
        text = path.read_text()
    except OSError as err:
        raise LogError(f"{path}: cannot read ({err.strerror}); is this a TUM log folder?") from err
    return [ln.split() for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]


def _last_pose(log: Path) -> tuple[float, float, float, float]:
    # a log recorded through a sensor profile keeps its exact trajectory in gt/ (hiper_cli.sensor)
    exact = log / "gt" / "groundtruth.txt"
    rows = _tum(exact if exact.is_file() else log / "groundtruth.txt")
    tx, ty, tz, qx, qy, qz, qw = (float(v) for v in rows[-1][1:8])
    from scipy.spatial.transform import Rotation

    axis = Rotation.from_quat([qx, qy, qz, qw]).as_matrix()[:, 2]  # the optical axis
    return (tx, ty, tz, float(math.atan2(axis[1], axis[0])))


def _id_image_counts(truth: Truth, rgb: list[list[str]]) -> dict[float, dict[int, int]]:
    out: dict[float, dict[int, int]] = {}
    for stamp, rel in ((float(r[0]), r[1]) for r in rgb):
        ids, counts = np.unique(truth.load_instance_ids(rel), return_counts=True)
        out[stamp] = {int(i): int(n) for i, n in zip(ids, counts, strict=True) if i != 0}
    return out


def load_scene_truth(log: str | Path, *, min_pixel_fraction: float = 0.001) -> SceneTruth:
    """The truth of ``log`` as sightings; an instance counts as seen in a frame when it covers
    at least ``min_pixel_fraction`` of the image with depth (0.1 %: 307 px at 640×480)."""
    root = Path(log)
    truth = load_truth(root)
    rgb = _tum(root / "rgb.txt")
    camera = json.loads((root / "camera.json").read_text())
    min_px = max(1, round(min_pixel_fraction * int(camera["width"]) * int(camera["height"])))
    counts = truth.load_visibility(in_range=True) if truth.frames_file else _id_image_counts(truth, rgb)
    stamps = np.array(sorted(counts), dtype=np.float64)
    seen: dict[int, list[float]] = {}
    for stamp in stamps:
        for tid, n in counts[float(stamp)].items():
            if n >= min_px and tid in truth.instances:
                seen.setdefault(tid, []).append(float(stamp))
    return SceneTruth(truth, stamps, {k: np.asarray(v) for k, v in seen.items()}, _last_pose(root), min_px)
