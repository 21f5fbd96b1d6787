"""A detector for any ONNX export in a layout hiper reads (``layouts``): YOLOX of any size,
YOLOv5, YOLOv8 / YOLO11, RT-DETR and RF-DETR style models.

The layout is told from one inference on a blank image when the model is opened (or given by
the catalog). Each layout has its preprocessing: YOLOX takes BGR 0..255 letterboxed at the
top left; YOLOv5/v8 RGB 0..1 letterboxed in the centre; one-output DETR (Ultralytics RT-DETR)
RGB 0..1 resized to the input; two-output DETR (RF-DETR) the same, then ImageNet mean and std.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect import layouts
from hiper_cli.perceive.detect._onnx import clip_boxes, letterbox, open_session
from hiper_cli.perceive.detect.yolo_onnx import decode_yolov8
from hiper_cli.perceive.detect.yolox import decode_yolox
from hiper_cli.types import Detections, Frame

__all__ = ["OnnxDetector"]

_IMAGENET_MEAN = np.array([0.485, 0.456, 0.406], dtype=np.float32)
_IMAGENET_STD = np.array([0.229, 0.224, 0.225], dtype=np.float32)


def _metadata_names(meta: dict[str, str]) -> tuple[str, ...] | None:
    """Class names from Ultralytics-style ``names`` metadata (a dict or list literal)."""
    raw = meta.get("names")
    if not raw:
        return None
    try:
        names = ast.literal_eval(raw)
    except (ValueError, SyntaxError):
        return None
    if isinstance(names, dict):
        return tuple(str(names[k]) for k in sorted(names))
    if isinstance(names, list | tuple):
        return tuple(str(n) for n in names)
    return None


def _input_size(shape: list[Any], default_px: int) -> tuple[int, int]:
    if len(shape) == 4 and isinstance(shape[2], int) and isinstance(shape[3], int):
        return int(shape[2]), int(shape[3])
    return default_px, default_px


class OnnxDetector:
    """An ONNX detection model in one of ``layouts.LAYOUT_NAMES``, on the CPU.

    ``layout`` None tells it from the outputs; ``labels`` is a class-name file (default: one
    beside the model, see ``layouts.labels_file``); ``input_px`` is used when the model's input
    size is dynamic."""

    def __init__(
        self, path: Path, *, name: str | None = None, layout: str | None = None, labels: Path | None = None,
        input_px: int = 640, score_threshold: float = 0.3, nms_iou: float = 0.45, threads: int = 1,
    ) -> None:
        self.name = name or f"onnx:{path}"
        self.model_path = path
        self.session = open_session(path, threads)
        inp = self.session.get_inputs()[0]
        self.input_name = inp.name
        self.size_hw = _input_size(list(inp.shape), input_px)
        self.score_threshold = float(score_threshold)
        self.nms_iou = float(nms_iou)
        blank = np.zeros((1, 3, *self.size_hw), dtype=np.float32)
        try:
            shapes = [tuple(int(d) for d in np.shape(o)) for o in self._run(blank)]
        except Exception as err:  # onnxruntime raises its own types
            h, w = self.size_hw
            raise ConfigError(f"{path}: the model does not run on a [1, 3, {h}, {w}] float image ({err}); "
                              f"hiper reads {layouts.LAYOUTS_TEXT}") from err
        self.layout = layout or layouts.identify_layout(shapes, self.size_hw, str(path))
        meta = dict(self.session.get_modelmeta().custom_metadata_map or {})
        named, num_classes = _metadata_names(meta), self._num_classes(shapes)
        if named is not None and len(named) != num_classes:  # e.g. a post-processed [1, 300, 6]
            raise ConfigError(
                f"{path}: outputs {', '.join(str(list(s)) for s in shapes)} read as layout "
                f"{self.layout} give {num_classes} classes but the model names {len(named)}; "
                f"hiper reads {layouts.LAYOUTS_TEXT}")
        self.class_names = layouts.class_names(num_classes, named, labels or layouts.labels_file(path))

    def _num_classes(self, shapes: list[tuple[int, ...]]) -> int:
        first = shapes[0]
        if self.layout in ("yolox", "yolov5"):
            return first[2] - 5
        if self.layout == "yolov8":
            return first[1] - 4
        if len(shapes) == 1:
            return first[2] - 4
        return max(s[2] for s in shapes if len(s) == 3 and s[2] > 4)

    def _run(self, blob: NDArray[np.float32]) -> list[NDArray[np.float32]]:
        return list(self.session.run(None, {self.input_name: blob}))

    def _blob(self, rgb: NDArray[np.uint8]) -> tuple[NDArray[np.float32], float, tuple[float, float]]:
        """The input tensor, the letterbox scale and pad (1, (0, 0) for a plain resize)."""
        import cv2

        if self.layout == "detr":
            resized = cv2.resize(rgb, (self.size_hw[1], self.size_hw[0]), interpolation=cv2.INTER_LINEAR)
            x = resized.astype(np.float32) / np.float32(255.0)
            if len(self.session.get_outputs()) >= 2:
                x = (x - _IMAGENET_MEAN) / _IMAGENET_STD
            return np.ascontiguousarray(x.transpose(2, 0, 1)[None]), 1.0, (0.0, 0.0)
        yolox = self.layout == "yolox"
        canvas, r, pad = letterbox(rgb, self.size_hw, centre=not yolox)
        if yolox:  # BGR, raw pixel values
            return np.ascontiguousarray(canvas[:, :, ::-1].transpose(2, 0, 1)[None], dtype=np.float32), r, pad
        blob = canvas.transpose(2, 0, 1)[None].astype(np.float32) / np.float32(255.0)
        return np.ascontiguousarray(blob), r, pad

    def decode(
        self, outputs: list[NDArray[np.float32]], scale: float, pad: tuple[float, float],
        image_wh: tuple[int, int],
    ) -> layouts.Boxes:
        """Boxes in image pixels, class ids and scores from the raw outputs of one inference."""
        kw = {"score_threshold": self.score_threshold}
        if self.layout == "yolox":
            return decode_yolox(outputs[0], self.size_hw, scale, nms_iou=self.nms_iou, **kw)
        if self.layout == "yolov5":
            return layouts.decode_yolov5(outputs[0], scale, pad, nms_iou=self.nms_iou, **kw)
        if self.layout == "yolov8":
            return decode_yolov8(outputs[0], scale, pad, nms_iou=self.nms_iou, **kw)
        return layouts.decode_detr(outputs, image_wh, **kw)

    def detect(self, frame: Frame) -> Detections:
        blob, r, pad = self._blob(frame.rgb)
        xyxy, class_ids, scores = self.decode(self._run(blob), r, pad, (frame.width, frame.height))
        xyxy = clip_boxes(xyxy, frame.width, frame.height)
        names = self.class_names
        labels = tuple(names[int(c)] if int(c) < len(names) else f"class_{int(c)}" for c in class_ids)
        return Detections(xyxy, labels, scores)
