"""Noisy 2D detections derived from the per-pixel truth (the ``truth`` detector).

For every instance of a detectable class whose visible pixels reach ``min_pixels`` (at
640×480; scaled with the image area), the tight box of its visible pixels is reported
unless it is missed (``miss_rate``), with its corners jittered by a Gaussian of
``jitter_frac`` × the box size, a score drawn from ``score_range``, and its class swapped
with ``confusion_rate`` for a similar COCO class. Each image also gets Poisson
``false_positives_per_image`` random boxes (instance_id null), and the people painted on
pictures and TV screens are reported as ``person`` with ``picture_person_rate`` (instance_id
null: the paper's false-positive trap).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError

__all__ = ["CONFUSIONS", "DETECTABLE", "NoiseModel", "detect"]

DETECTABLE = ("person", "chair", "couch", "bed", "bottle", "cup", "tv", "potted plant")
CONFUSIONS: dict[str, tuple[str, ...]] = {
    "chair": ("couch", "bench"),
    "couch": ("chair", "bed"),
    "bed": ("couch",),
    "bottle": ("cup", "vase"),
    "cup": ("bottle", "vase"),
    "tv": ("laptop",),
    "potted plant": ("vase",),
    "person": ("teddy bear",),
}
FP_CLASSES = ("person", "chair", "bottle", "cup", "tv", "potted plant", "book")


MAX_FALSE_POSITIVES_PER_IMAGE = 100.0  # a mean; far beyond it drawing the boxes never ends


@dataclass(frozen=True)
class NoiseModel:
    """Detection noise; ``NoiseModel.perfect()`` gives exact boxes with no misses or extras."""

    miss_rate: float = 0.1
    jitter_frac: float = 0.05
    false_positives_per_image: float = 0.05
    confusion_rate: float = 0.03
    picture_person_rate: float = 0.3
    min_pixels: int = 400
    score_range: tuple[float, float] = (0.5, 0.95)
    fp_score_range: tuple[float, float] = (0.3, 0.6)
    classes: tuple[str, ...] = field(default=DETECTABLE)

    def __post_init__(self) -> None:
        for name in ("miss_rate", "confusion_rate", "picture_person_rate"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise ConfigError(f"noise model: {name}={value}; expected a probability in [0, 1]")
        if not 0 <= self.false_positives_per_image <= MAX_FALSE_POSITIVES_PER_IMAGE:
            raise ConfigError(f"noise model: false_positives_per_image={self.false_positives_per_image}; "
                              f"expected 0 to {MAX_FALSE_POSITIVES_PER_IMAGE} random boxes per image")
        if self.jitter_frac < 0 or self.false_positives_per_image < 0 or self.min_pixels < 1:
            raise ConfigError(
                "noise model: jitter_frac and false_positives_per_image must be >= 0, min_pixels >= 1"
            )

    @classmethod
    def perfect(cls) -> NoiseModel:
        return cls(0.0, 0.0, 0.0, 0.0, 0.0, score_range=(1.0, 1.0))

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["score_range"] = list(self.score_range)
        out["fp_score_range"] = list(self.fp_score_range)
        out["classes"] = list(self.classes)
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> NoiseModel:
        fields = dict(data)
        for key in ("score_range", "fp_score_range", "classes"):
            if key in fields:
                fields[key] = tuple(fields[key])
        try:
            return cls(**fields)
        except TypeError as err:
            raise ConfigError(f"noise model: {err}") from err


def _box(mask_rows: NDArray[np.int64], mask_cols: NDArray[np.int64]) -> list[float]:
    return [
        float(mask_cols.min()),
        float(mask_rows.min()),
        float(mask_cols.max() + 1),
        float(mask_rows.max() + 1),
    ]


def detect(
    ids: NDArray[np.uint16],
    classes: dict[int, str],
    model: NoiseModel,
    rng: np.random.Generator,
    picture_ids: frozenset[int] = frozenset(),
) -> list[dict[str, Any]]:
    """Detections of one image from its instance-id image ``ids`` (0 = nothing).

    ``classes`` maps instance id to class name; ``picture_ids`` are pictures and screens
    that show a person. Returns records ``{"xyxy", "class", "score", "instance_id"}``.
    """
    h, w = ids.shape
    min_px = max(1, round(model.min_pixels * (h * w) / (640 * 480)))
    present, counts = np.unique(ids[ids > 0], return_counts=True)
    out: list[dict[str, Any]] = []
    for inst, count in zip(present.tolist(), counts.tolist(), strict=True):
        name = classes.get(int(inst))
        is_picture = int(inst) in picture_ids
        if name not in model.classes and not is_picture:
            continue
        if count < min_px:
            continue
        rows, cols = np.nonzero(ids == inst)
        box = _box(rows, cols)
        if is_picture:
            if rng.random() < model.picture_person_rate:
                out.append(
                    _record(
                        _jitter(box, 2 * model.jitter_frac, rng, w, h),
                        "person",
                        float(rng.uniform(*model.fp_score_range)),
                        None,
                    )
                )
            if name not in model.classes:
                continue
        if rng.random() < model.miss_rate:
            continue
        label = str(name)
        if label in CONFUSIONS and rng.random() < model.confusion_rate:
            options = CONFUSIONS[label]
            label = options[int(rng.integers(len(options)))]
        out.append(
            _record(
                _jitter(box, model.jitter_frac, rng, w, h),
                label,
                float(rng.uniform(*model.score_range)),
                int(inst),
            )
        )
    for _ in range(int(rng.poisson(model.false_positives_per_image))):
        bw, bh = float(rng.uniform(0.05, 0.3)) * w, float(rng.uniform(0.05, 0.4)) * h
        x0, y0 = float(rng.uniform(0, w - bw)), float(rng.uniform(0, h - bh))
        label = FP_CLASSES[int(rng.integers(len(FP_CLASSES)))]
        out.append(
            _record([x0, y0, x0 + bw, y0 + bh], label, float(rng.uniform(*model.fp_score_range)), None)
        )
    return out


def _jitter(box: list[float], frac: float, rng: np.random.Generator, w: int, h: int) -> list[float]:
    if frac <= 0:
        return box
    bw, bh = box[2] - box[0], box[3] - box[1]
    d = rng.standard_normal(4) * frac * np.array([bw, bh, bw, bh])
    x0, y0, x1, y1 = (np.array(box) + d).tolist()
    x0, x1 = sorted((min(max(x0, 0.0), w), min(max(x1, 0.0), w)))
    y0, y1 = sorted((min(max(y0, 0.0), h), min(max(y1, 0.0), h)))
    return [x0, y0, x1, y1]


def _record(xyxy: list[float], label: str, score: float, instance_id: int | None) -> dict[str, Any]:
    return {
        "xyxy": [round(v, 2) for v in xyxy],
        "class": label,
        "score": round(score, 4),
        "instance_id": instance_id,
    }
