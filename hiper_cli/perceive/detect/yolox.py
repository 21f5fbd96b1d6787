"""The ``yolox`` detector: Megvii's COCO YOLOX-Nano as ONNX, run with onnxruntime on the CPU.

The model is never part of hiper: ``hiper models fetch yolox`` downloads the asset
``yolox_nano.onnx`` of release 0.1.1rc0 of github.com/Megvii-BaseDetection/YOLOX into the user
cache, and ``find_yolox_model`` looks there and in the other models folders (``catalog``).

Interface: input ``images`` float32 [1, 3, 416, 416], BGR, raw 0..255, letterboxed at the top
left on a 114 canvas; output [1, 3549, 85] = grids of strides 8, 16, 32, columns
[tx, ty, tw, th, obj, cls0..cls79] with obj and cls already sigmoid.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect._onnx import COCO_NAMES, clip_boxes, letterbox, nms, open_session
from hiper_cli.perceive.detect.catalog import locate, models_dir
from hiper_cli.types import Detections, Frame

__all__ = ["YOLOX_DOWNLOAD", "YoloxDetector", "decode_yolox", "find_yolox_model"]

YOLOX_DOWNLOAD = (
    "https://github.com/Megvii-BaseDetection/YOLOX/releases/download/0.1.1rc0/yolox_nano.onnx"
)
_STRIDES = (8, 16, 32)


def find_yolox_model(
    model_path: str | Path | None = None, search_roots: Sequence[Path] | None = None
) -> Path:
    """Where the YOLOX-Nano model is; ``ConfigError`` saying how to fetch it when absent.

    ``model_path`` first, then the models folders of ``catalog.search_dirs`` (``$HIPER_MODELS``,
    the user cache that ``hiper models fetch`` fills, ``shared/models`` and ``models`` above
    ``search_roots``, default the repository and the working directory).
    """
    if model_path is not None and Path(model_path).is_file():
        return Path(model_path)
    found = locate("yolox_nano", roots=search_roots)
    if found is not None:
        return found
    raise ConfigError(
        f"YOLOX-Nano model not found (looked at model_path and in {models_dir()}, $HIPER_MODELS and "
        "shared/models); run 'hiper models fetch yolox', or on a machine with network download "
        f"{YOLOX_DOWNLOAD} and run 'hiper models add yolox_nano.onnx'"
    )


@lru_cache(maxsize=4)
def _grids(size_hw: tuple[int, int]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Grid cell offsets (N, 2) and strides (N, 1) in the model's output order."""
    cells, strides = [], []
    for s in _STRIDES:
        gh, gw = size_hw[0] // s, size_hw[1] // s
        gy, gx = np.meshgrid(np.arange(gh), np.arange(gw), indexing="ij")
        cells.append(np.stack([gx.ravel(), gy.ravel()], axis=1))
        strides.append(np.full((gh * gw, 1), s))
    return np.concatenate(cells).astype(np.float64), np.concatenate(strides).astype(np.float64)


def decode_yolox(
    output: NDArray[np.float32],
    size_hw: tuple[int, int],
    scale: float,
    *,
    score_threshold: float,
    nms_iou: float,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Boxes (xyxy in original image pixels), class ids and scores from a raw YOLOX output."""
    raw = np.asarray(output).reshape(-1, output.shape[-1])
    cells, strides = _grids(size_hw)
    if len(cells) != len(raw):
        raise ConfigError(
            f"YOLOX output has {len(raw)} rows but a {size_hw[1]}x{size_hw[0]} input has "
            f"{len(cells)} grid cells; is this a YOLOX model?"
        )
    # score = objectness x class probability <= objectness: rows below the threshold cannot
    # pass, so only the few others are decoded (most of the 3549 rows of a 416x416 input).
    rows = np.flatnonzero(raw[:, 4] >= score_threshold)
    pred = raw[rows].astype(np.float64)
    cells, strides = cells[rows], strides[rows]
    cls_scores = pred[:, 5:]
    class_ids = np.argmax(cls_scores, axis=1)
    scores = pred[:, 4] * cls_scores[np.arange(len(pred)), class_ids]
    keep = scores >= score_threshold
    pred, cells, strides = pred[keep], cells[keep], strides[keep]
    class_ids, scores = class_ids[keep], scores[keep]
    centre = (pred[:, :2] + cells) * strides
    wh = np.exp(np.clip(pred[:, 2:4], -10.0, 10.0)) * strides
    xyxy = np.concatenate([centre - wh / 2.0, centre + wh / 2.0], axis=1) / scale
    kept = nms(xyxy, scores, class_ids, nms_iou)
    return xyxy[kept], class_ids[kept], scores[kept]


class YoloxDetector:
    """COCO YOLOX-Nano with one intra-op thread (the other core does the point-cloud work)."""

    name = "yolox"

    def __init__(
        self,
        model_path: str | Path | None = None,
        score_threshold: float = 0.3,
        nms_iou: float = 0.45,
        threads: int = 1,
    ) -> None:
        self.model_path = find_yolox_model(model_path)
        self.session = open_session(self.model_path, threads)
        shape = self.session.get_inputs()[0].shape
        self.input_name = self.session.get_inputs()[0].name
        self.size_hw = (int(shape[2]), int(shape[3])) if isinstance(shape[2], int) else (416, 416)
        self.score_threshold = float(score_threshold)
        self.nms_iou = float(nms_iou)
        self.class_names = COCO_NAMES

    def detect(self, frame: Frame) -> Detections:
        canvas, r, _ = letterbox(frame.rgb, self.size_hw, centre=False)
        # YOLOX takes BGR, channels first, float pixel values: one plane copy per channel.
        blob = np.empty((1, 3, *canvas.shape[:2]), dtype=np.float32)
        for k in range(3):
            blob[0, k] = canvas[:, :, 2 - k]
        (output,) = self.session.run(None, {self.input_name: blob})
        xyxy, class_ids, scores = decode_yolox(
            output, self.size_hw, r, score_threshold=self.score_threshold, nms_iou=self.nms_iou
        )
        xyxy = clip_boxes(xyxy, frame.width, frame.height)
        return Detections(xyxy, tuple(COCO_NAMES[int(c)] for c in class_ids), scores)
