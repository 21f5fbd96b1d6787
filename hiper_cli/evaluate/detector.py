"""The detector's own ceiling: which clearly seen, nameable objects a 2D detector finds at all.

Over the frames with per-pixel truth (``gt/instances/*.png`` of a realistic world, every 5th
frame; ``gt/instance_ids/*.png`` of a ``hiper sim`` log), an object counts as *seen clearly* when
its class or an alt class is one a COCO detector can name and it fills at least
``SEEN_CLEARLY_PX`` pixels with depth in some frame (``max_in_range_pixels`` of
``gt/instances.json``, the reference scorer's rule). It is *found* when, in some labelled
frame, a detection of its class (or alt class) overlaps the box of its visible pixels with IoU
at least ``FOUND_IOU``. A frame *shows* an object when ``SHOWN_PX`` of its pixels are visible
there; ``frames_found / frames_shown`` says how steadily the detector sees it. hiper cannot
keep an object its detector never reports, so this bounds hiper's recall of nameable objects.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.detect import Detector
from hiper_cli.perceive.logs import LogReader
from hiper_cli.types import Detections

__all__ = [
    "COCO_NAMEABLE",
    "FOUND_IOU",
    "SEEN_CLEARLY_PX",
    "SHOWN_PX",
    "DetectorCeiling",
    "detector_ceiling",
    "recall_beside_ceiling",
]

FOUND_IOU = 0.5
SEEN_CLEARLY_PX = 1500
SHOWN_PX = 200
# the classes a COCO detector can name, as the worlds' reference scorer lists them
COCO_NAMEABLE = frozenset({
    "person", "chair", "couch", "bed", "table", "tv", "refrigerator", "bottle", "cup", "book", "bicycle",
    "laptop", "cell phone", "clock", "potted plant", "vase", "sink", "toilet", "microwave", "oven", "bench",
    "backpack", "handbag", "suitcase", "keyboard", "mouse", "remote"})
# COCO names that the truth spells otherwise
COCO_TO_TRUTH = {"dining table": "table"}
_ID_FOLDERS = ("instances", "instance_ids")


@dataclass
class _Object:
    id: int
    class_name: str
    names: frozenset[str]
    frames_shown: int = 0
    frames_found: int = 0
    best_iou: float = 0.0


@dataclass(frozen=True)
class DetectorCeiling:
    """Per class and in total: objects seen clearly, found in some frame, and frame shares."""

    log: str
    detector: str
    frames: int
    objects: list[dict[str, Any]] = field(default_factory=list)

    def per_class(self) -> dict[str, dict[str, Any]]:
        out: dict[str, dict[str, Any]] = {}
        for o in self.objects:
            row = out.setdefault(o["class"], {"seen_clearly": 0, "found": 0, "frames_shown": 0,
                                              "frames_found": 0})
            row["seen_clearly"] += 1
            row["found"] += int(o["found"])
            row["frames_shown"] += o["frames_shown"]
            row["frames_found"] += o["frames_found"]
        for row in out.values():
            shown = row["frames_shown"]
            row["frame_share"] = round(row["frames_found"] / shown, 3) if shown else None
        return dict(sorted(out.items()))

    @property
    def found(self) -> int:
        return sum(int(o["found"]) for o in self.objects)

    def to_dict(self) -> dict[str, Any]:
        shown = sum(o["frames_shown"] for o in self.objects)
        hits = sum(o["frames_found"] for o in self.objects)
        return {"log": self.log, "detector": self.detector, "frames": self.frames,
                "found_iou": FOUND_IOU, "seen_clearly_px": SEEN_CLEARLY_PX,
                "total": {"found": self.found, "seen_clearly": len(self.objects),
                          "frame_share": round(hits / shown, 3) if shown else None},
                "per_class": self.per_class(), "objects": self.objects}


def _objects(gt: Path) -> dict[int, _Object]:
    path = gt / "instances.json"
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError as err:
        raise LogError(f"{path}: not found; hiper eval detector needs a log with per-pixel ground truth "
                       "(a shared world, or a hiper sim log)") from err
    except (OSError, ValueError) as err:
        raise LogError(f"{path}: not readable as JSON ({err})") from err
    out: dict[int, _Object] = {}
    for d in data.get("instances", []):
        names = frozenset({str(d.get("class")), *(str(c) for c in d.get("alt_classes", ()))})
        if not names & COCO_NAMEABLE or int(d.get("max_in_range_pixels") or 0) < SEEN_CLEARLY_PX:
            continue
        if d.get("layer") == "background" and d.get("class") != "table":
            continue
        out[int(d["id"])] = _Object(int(d["id"]), str(d["class"]), names)
    return out


def _iou(box: NDArray[np.float64], boxes: NDArray[np.float64]) -> NDArray[np.float64]:
    x0 = np.maximum(box[0], boxes[:, 0])
    y0 = np.maximum(box[1], boxes[:, 1])
    x1 = np.minimum(box[2], boxes[:, 2])
    y1 = np.minimum(box[3], boxes[:, 3])
    inter = np.clip(x1 - x0, 0, None) * np.clip(y1 - y0, 0, None)
    area = (box[2] - box[0]) * (box[3] - box[1])
    areas = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    return np.asarray(inter / np.maximum(area + areas - inter, 1e-9))


def _score_frame(ids: NDArray[np.uint16], detections: Detections, objects: dict[int, _Object]) -> None:
    present, counts = np.unique(ids[ids > 0], return_counts=True)
    names = [COCO_TO_TRUTH.get(n, n) for n in detections.class_names]
    for inst, count in zip(present.tolist(), counts.tolist(), strict=True):
        obj = objects.get(int(inst))
        if obj is None or count < SHOWN_PX:
            continue
        obj.frames_shown += 1
        rows, cols = np.nonzero(ids == inst)
        box = np.array([cols.min(), rows.min(), cols.max() + 1, rows.max() + 1], dtype=np.float64)
        same = np.array([n in obj.names for n in names], dtype=bool)
        if not same.any():
            continue
        best = float(_iou(box, detections.xyxy[same]).max())
        obj.best_iou = max(obj.best_iou, best)
        obj.frames_found += int(best >= FOUND_IOU)


def _id_image(gt: Path, stamp_s: float) -> Path | None:
    for folder in _ID_FOLDERS:
        path = gt / folder / f"{stamp_s:.6f}.png"
        if path.is_file():
            return path
    return None


def detector_ceiling(log: str | Path, reader: LogReader, detector: Detector, *, max_frames: int = 0,
                     progress: Callable[[int, int], None] | None = None) -> DetectorCeiling:
    """Run ``detector`` on the labelled frames of ``reader`` (the log at ``log``) and score it.

    ``max_frames`` > 0 uses that many labelled frames, spread over the log; ``progress(done, total)``
    is called after each.
    """
    import cv2

    gt = Path(log) / "gt"
    objects = _objects(gt)
    stamps = reader.info().stamps_s
    labelled = [(i, p) for i, s in enumerate(stamps) if (p := _id_image(gt, float(s))) is not None]
    if not labelled:
        raise LogError(f"{gt}: no per-pixel id image (gt/instances/<stamp>.png) matches a frame of the log")
    if 0 < max_frames < len(labelled):
        labelled = [labelled[k] for k in np.linspace(0, len(labelled) - 1, max_frames).round().astype(int)]
    for done, (index, path) in enumerate(labelled, start=1):
        ids = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        if ids is None:
            raise LogError(f"{path}: not a readable 16-bit id image")
        frame = reader.read_frame(index)
        _score_frame(np.asarray(ids, dtype=np.uint16), detector.detect(frame), objects)
        if progress is not None:
            progress(done, len(labelled))
    rows = [{"id": o.id, "class": o.class_name, "found": o.frames_found > 0, "frames_shown": o.frames_shown,
             "frames_found": o.frames_found, "best_iou": round(o.best_iou, 3)}
            for o in sorted(objects.values(), key=lambda o: (o.class_name, o.id))]
    return DetectorCeiling(str(log), getattr(detector, "name", type(detector).__name__), len(labelled), rows)


def recall_beside_ceiling(ceiling: DetectorCeiling, matched_truth_ids: list[int]) -> dict[str, Any]:
    """hiper's recall of the nameable objects seen clearly (matched with the right class by the
    scene scoring), beside how many of them the detector found at all, per class and in total."""
    matched = set(matched_truth_ids)
    per_class: dict[str, dict[str, int]] = {}
    for o in ceiling.objects:
        row = per_class.setdefault(o["class"], {"seen_clearly": 0, "detector_found": 0, "hiper_found": 0})
        row["seen_clearly"] += 1
        row["detector_found"] += int(o["found"])
        row["hiper_found"] += int(o["id"] in matched)
    return {"detector": ceiling.detector, "seen_clearly": len(ceiling.objects),
            "detector_found": ceiling.found,
            "hiper_found": sum(int(o["id"] in matched) for o in ceiling.objects),
            "hiper_found_of_detector_found": sum(int(o["found"] and o["id"] in matched)
                                                 for o in ceiling.objects),
            "per_class": dict(sorted(per_class.items()))}
