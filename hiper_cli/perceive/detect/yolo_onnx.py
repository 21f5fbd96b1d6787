"""Decoding a YOLOv8 / YOLO11 ONNX export (Ultralytics layout ``yolov8``, see ``layouts``).

Input: float32 [1, 3, H, W], RGB scaled to 0..1, letterboxed in the centre on a 114 canvas.
Output: [1, 4 + nc, N]: box centre and size (cx, cy, w, h) in input pixels, then nc class
scores. Class names come from the model's ``names`` metadata when present, else COCO names
when nc is 80, else ``class_<k>``.
"""

from __future__ import annotations

import ast

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect._onnx import COCO_NAMES, letterboxed_boxes

__all__ = ["decode_yolov8", "parse_names"]


def parse_names(metadata: dict[str, str], num_classes: int) -> tuple[str, ...]:
    """Class names from Ultralytics metadata (``names``: a dict literal), or a fallback."""
    raw = metadata.get("names")
    if raw:
        try:
            names = ast.literal_eval(raw)
            if isinstance(names, dict):
                return tuple(str(names.get(k, f"class_{k}")) for k in range(num_classes))
            if isinstance(names, list | tuple):
                return tuple(str(n) for n in names)
        except (ValueError, SyntaxError):
            pass
    if num_classes == len(COCO_NAMES):
        return COCO_NAMES
    return tuple(f"class_{k}" for k in range(num_classes))


def decode_yolov8(
    output: NDArray[np.float32],
    scale: float,
    pad_xy: tuple[float, float],
    *,
    score_threshold: float,
    nms_iou: float,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Boxes (xyxy, original pixels), class ids and scores from a [1, 4 + nc, N] output."""
    out = np.asarray(output, dtype=np.float64)
    if out.ndim != 3 or out.shape[1] < 5:
        raise ConfigError(
            f"ONNX detector output has shape {list(out.shape)}; expected [1, 4 + classes, N] "
            "(a YOLOv8 / YOLO11 detection export)"
        )
    pred = out[0].T  # (N, 4 + nc)
    cls_scores = pred[:, 4:]
    class_ids = np.argmax(cls_scores, axis=1)
    scores = cls_scores[np.arange(len(pred)), class_ids]
    keep = scores >= score_threshold
    return letterboxed_boxes(pred[keep], class_ids[keep], scores[keep], pad_xy, scale, nms_iou)
