"""What a log's ground truth holds, whichever file it came from (``truth.load_truth``: a
``hiper sim`` log's ``gt/world.json``; ``world_truth.py``: a realistic world's
``gt/instances.json``): instances, phases, walkers' tracks and the per-frame files beside them."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.model import Box3D

__all__ = ["Phase", "Truth", "TruthInstance"]


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
