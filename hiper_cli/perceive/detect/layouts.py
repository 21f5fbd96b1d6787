"""The output layouts of the ONNX detectors hiper reads, how to tell them apart, how to decode.

A layout is told from the shapes of the outputs of one inference (``identify_layout``), with
``cells`` = the grid cells of strides 8, 16 and 32 for the model's input (8400 at 640x640):

- ``yolox``: one output [1, cells, 5 + C]: grid offsets (tx, ty, log w, log h), objectness, C
  class probabilities (YOLOX, any size; decoded by ``yolox.decode_yolox``);
- ``yolov5``: one output [1, 3 x cells, 5 + C]: (cx, cy, w, h) in input pixels, objectness,
  C class probabilities (three anchors per cell);
- ``yolov8``: one output [1, 4 + C, cells]: (cx, cy, w, h) in input pixels, C class scores
  (YOLOv8, YOLO11; decoded by ``yolo_onnx.decode_yolov8``);
- ``detr``: one output [1, Q, 4 + C] of (cx, cy, w, h) in 0..1 and class probabilities
  (Ultralytics RT-DETR), or two outputs boxes [1, Q, 4] and class logits [1, Q, C] (RF-DETR,
  DETR-style exports), Q queries and no NMS.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect._onnx import COCO_NAMES, letterboxed_boxes

__all__ = ["LAYOUTS_TEXT", "LAYOUT_NAMES", "class_names", "coco91_names", "decode_detr", "decode_yolov5",
           "grid_cells", "identify_layout"]

LAYOUT_NAMES: tuple[str, ...] = ("yolox", "yolov5", "yolov8", "detr")
LAYOUTS_TEXT = ("yolox [1, cells, 5+C], yolov5 [1, 3*cells, 5+C], yolov8/YOLO11 [1, 4+C, cells], "
                "detr [1, Q, 4+C] or boxes [1, Q, 4] + logits [1, Q, C]")
# COCO category ids that have no class (the 91-id numbering DETR-family models predict in).
_COCO_ID_GAPS = frozenset({0, 12, 26, 29, 30, 45, 66, 68, 69, 71, 83})

Boxes = tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]


def grid_cells(size_hw: tuple[int, int]) -> int:
    """Grid cells of strides 8, 16 and 32 over an input of ``size_hw`` pixels."""
    return sum((size_hw[0] // s) * (size_hw[1] // s) for s in (8, 16, 32))


def _detr_pair(shapes: list[tuple[int, ...]]) -> bool:
    boxes = [s for s in shapes if len(s) == 3 and s[2] == 4]
    return any(len(s) == 3 and s[2] > 4 and s[1] == b[1] for b in boxes for s in shapes)


def identify_layout(shapes: list[tuple[int, ...]], size_hw: tuple[int, int], where: str = "model") -> str:
    """The layout of outputs of these ``shapes`` (one inference at ``size_hw``), or a
    ``ConfigError`` naming the layouts hiper reads."""
    cells = grid_cells(size_hw)
    if len(shapes) >= 2 and _detr_pair(shapes):
        return "detr"
    if len(shapes) >= 1 and len(shapes[0]) == 3 and shapes[0][0] == 1:
        _, a, b = shapes[0]
        if a == cells and b >= 6:
            return "yolox"
        if a == 3 * cells and b >= 6:
            return "yolov5"
        if b == cells and a >= 5:
            return "yolov8"
        if len(shapes) == 1 and b >= 5 and a < cells:
            return "detr"
    got = ", ".join(str(list(s)) for s in shapes)
    raise ConfigError(f"{where}: outputs {got} at input {size_hw[1]}x{size_hw[0]} are not a detector layout "
                      f"hiper reads ({LAYOUTS_TEXT}); export boxes + scores in one of them")


def decode_yolov5(
    output: NDArray[np.float32], scale: float, pad_xy: tuple[float, float], *,
    score_threshold: float, nms_iou: float,
) -> Boxes:
    """Boxes (xyxy, original pixels), class ids and scores from a [1, N, 5 + C] YOLOv5 output."""
    pred = np.asarray(output, dtype=np.float64).reshape(-1, output.shape[-1])
    pred = pred[pred[:, 4] >= score_threshold]
    cls_scores = pred[:, 5:]
    class_ids = np.argmax(cls_scores, axis=1)
    scores = pred[:, 4] * cls_scores[np.arange(len(pred)), class_ids]
    keep = scores >= score_threshold
    return letterboxed_boxes(pred[keep], class_ids[keep], scores[keep], pad_xy, scale, nms_iou)


def decode_detr(
    outputs: list[NDArray[np.float32]], image_wh: tuple[int, int], *, score_threshold: float,
) -> Boxes:
    """Boxes (xyxy, original pixels), class ids and scores from DETR-style outputs: one
    [1, Q, 4 + C] of normalised (cx, cy, w, h) and probabilities, or boxes [1, Q, 4] with class
    logits [1, Q, C] (a sigmoid gives the probabilities). The input was resized, not letterboxed,
    so normalised boxes scale by the image's own width and height."""
    if len(outputs) == 1:
        out = np.asarray(outputs[0], dtype=np.float64)[0]
        boxes, probs = out[:, :4], out[:, 4:]
    else:
        shapes = [np.shape(o) for o in outputs]
        b = next(k for k, s in enumerate(shapes) if len(s) == 3 and s[2] == 4)
        c = next(k for k, s in enumerate(shapes) if len(s) == 3 and s[2] > 4 and s[1] == shapes[b][1])
        boxes = np.asarray(outputs[b], dtype=np.float64)[0]
        probs = 1.0 / (1.0 + np.exp(-np.asarray(outputs[c], dtype=np.float64)[0]))
    class_ids = np.argmax(probs, axis=1)
    scores = probs[np.arange(len(probs)), class_ids]
    keep = scores >= score_threshold
    boxes, class_ids, scores = boxes[keep], class_ids[keep], scores[keep]
    w, h = image_wh
    cxcy, wh = boxes[:, :2], boxes[:, 2:4]
    xyxy = np.concatenate([cxcy - wh / 2.0, cxcy + wh / 2.0], axis=1) * np.array([w, h, w, h], float)
    order = np.argsort(-scores, kind="stable")
    return xyxy[order], class_ids[order], scores[order]


def coco91_names() -> tuple[str, ...]:
    """Names indexed by COCO category id 0..90 ("N/A" at the ids with no class)."""
    names = iter(COCO_NAMES)
    return tuple("N/A" if k in _COCO_ID_GAPS else next(names) for k in range(91))


def _read_labels(path: Path) -> tuple[str, ...]:
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{path}: cannot read the labels file ({err}); one class name a line") from err
    return tuple(line.strip() for line in lines if line.strip())


def labels_file(model: Path) -> Path | None:
    """A labels file beside ``model``: ``<stem>.labels.txt``, else ``labels.txt``."""
    for candidate in (model.with_name(f"{model.stem}.labels.txt"), model.with_name("labels.txt")):
        if candidate.is_file():
            return candidate
    return None


def class_names(
    num_classes: int, metadata_names: tuple[str, ...] | None, labels: Path | None
) -> tuple[str, ...]:
    """The model's class names, in order of preference: a labels file (one name a line), the
    model's ``names`` metadata, COCO when there are 80 classes (91: COCO category ids),
    else ``class_<k>``. A labels file with fewer names than classes is an error."""
    if labels is not None:
        names = _read_labels(labels)
        if len(names) < num_classes:
            raise ConfigError(f"{labels}: {len(names)} names for a model of {num_classes} classes; "
                              "give one name a line for every class")
        return names[:num_classes]
    if metadata_names:
        return metadata_names
    if num_classes == len(COCO_NAMES):
        return COCO_NAMES
    if num_classes == 91:
        return coco91_names()
    return tuple(f"class_{k}" for k in range(num_classes))
