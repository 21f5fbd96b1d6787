"""Shared pieces of the ONNX detectors: sessions, letterbox, NMS, COCO names."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError

COCO_NAMES: tuple[str, ...] = (
    "person", "bicycle", "car", "motorcycle", "airplane", "bus", "train", "truck", "boat",
    "traffic light", "fire hydrant", "stop sign", "parking meter", "bench", "bird", "cat", "dog",
    "horse", "sheep", "cow", "elephant", "bear", "zebra", "giraffe", "backpack", "umbrella",
    "handbag", "tie", "suitcase", "frisbee", "skis", "snowboard", "sports ball", "kite",
    "baseball bat", "baseball glove", "skateboard", "surfboard", "tennis racket", "bottle",
    "wine glass", "cup", "fork", "knife", "spoon", "bowl", "banana", "apple", "sandwich", "orange",
    "broccoli", "carrot", "hot dog", "pizza", "donut", "cake", "chair", "couch", "potted plant",
    "bed", "dining table", "toilet", "tv", "laptop", "mouse", "remote", "keyboard", "cell phone",
    "microwave", "oven", "toaster", "sink", "refrigerator", "book", "clock", "vase", "scissors",
    "teddy bear", "hair drier", "toothbrush",
)  # fmt: skip


def open_session(path: Path, threads: int = 1) -> Any:
    """An onnxruntime session on the CPU with ``threads`` intra-op threads."""
    import onnxruntime as ort

    if not path.is_file():
        raise ConfigError(f"{path}: ONNX model not found; check the path")
    options = ort.SessionOptions()
    options.intra_op_num_threads = int(threads)
    options.inter_op_num_threads = 1
    options.log_severity_level = 3
    try:
        return ort.InferenceSession(str(path), sess_options=options, providers=["CPUExecutionProvider"])
    except Exception as err:  # onnxruntime raises its own exception types
        raise ConfigError(f"{path}: cannot load the ONNX model ({err})") from err


def letterbox(
    rgb: NDArray[np.uint8], size_hw: tuple[int, int], *, centre: bool, fill: int = 114
) -> tuple[NDArray[np.uint8], float, tuple[float, float]]:
    """Resize keeping the aspect ratio into a ``size_hw`` canvas filled with ``fill``.

    Returns the canvas, the scale ``r`` and the (x, y) pad offset, so that an input pixel
    ``p`` maps to ``p * r + pad``. ``centre=False`` pastes at the top-left (YOLOX),
    ``centre=True`` in the middle (Ultralytics).
    """
    import cv2

    h, w = rgb.shape[:2]
    H, W = size_hw
    r = min(H / h, W / w)
    nw, nh = int(w * r), int(h * r)
    canvas = np.full((H, W, 3), fill, dtype=np.uint8)
    resized = cv2.resize(rgb, (nw, nh), interpolation=cv2.INTER_LINEAR) if (nw, nh) != (w, h) else rgb
    ox, oy = ((W - nw) // 2, (H - nh) // 2) if centre else (0, 0)
    canvas[oy : oy + nh, ox : ox + nw] = resized
    return canvas, r, (float(ox), float(oy))


def nms(
    xyxy: NDArray[np.float64], scores: NDArray[np.float64], classes: NDArray[np.int64], iou: float
) -> NDArray[np.int64]:
    """Indices kept by class-wise non-maximum suppression at ``iou``, best score first."""
    if len(xyxy) == 0:
        return np.zeros(0, dtype=np.int64)
    # Offset boxes per class so that boxes of different classes never overlap.
    offset = classes.astype(np.float64)[:, None] * (float(np.max(xyxy)) + 1.0)
    boxes = xyxy + offset
    x0, y0, x1, y1 = boxes.T
    area = np.maximum(x1 - x0, 0) * np.maximum(y1 - y0, 0)
    order = np.argsort(-scores, kind="stable")
    keep: list[int] = []
    while len(order):
        i = int(order[0])
        keep.append(i)
        rest = order[1:]
        iw = np.maximum(0.0, np.minimum(x1[i], x1[rest]) - np.maximum(x0[i], x0[rest]))
        ih = np.maximum(0.0, np.minimum(y1[i], y1[rest]) - np.maximum(y0[i], y0[rest]))
        inter = iw * ih
        union = area[i] + area[rest] - inter
        overlap = np.where(union > 0, inter / np.maximum(union, 1e-12), 0.0)
        order = rest[overlap <= iou]
    return np.array(keep, dtype=np.int64)


def clip_boxes(xyxy: NDArray[np.float64], width: int, height: int) -> NDArray[np.float64]:
    out = xyxy.copy()
    out[:, [0, 2]] = np.clip(out[:, [0, 2]], 0.0, float(width))
    out[:, [1, 3]] = np.clip(out[:, [1, 3]], 0.0, float(height))
    return out


def letterboxed_boxes(
    pred: NDArray[np.float64], class_ids: NDArray[np.int64], scores: NDArray[np.float64],
    pad_xy: tuple[float, float], scale: float, nms_iou: float,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Rows whose first four columns are (cx, cy, w, h) in letterboxed input pixels, as xyxy boxes
    in the original image's pixels, with class ids and scores, after class-wise NMS."""
    cxcy, wh = pred[:, :2], pred[:, 2:4]
    xyxy = np.concatenate([cxcy - wh / 2.0, cxcy + wh / 2.0], axis=1)
    xyxy = (xyxy - np.array([*pad_xy, *pad_xy])) / scale
    kept = nms(xyxy, scores, class_ids, nms_iou)
    return xyxy[kept], class_ids[kept], scores[kept]
