"""A closer look with any detector: the image cut into overlapping tiles, each detected alone.

A detector with a fixed input (YOLOX-Nano: 416 × 416) shrinks a 640 × 480 image to 0.65 of
its size, and small or distant objects (a book on a shelf, a cup on a desk) fall below what it
can name. Cut into ``rows × cols`` tiles that overlap by ``overlap`` of a tile, each tile is
shrunk less (2 × 2 of a 640 × 480 image: 1.16 instead of 0.65, 1.8 times closer). The tiles'
detections, shifted back to the image, join the whole image's; a box that touches a tile's
inner edge is dropped (its object was cut there: a tile beside it, or the whole image, holds
it whole), and class-wise non-maximum suppression keeps one box per object.

The look costs ``rows × cols`` detector runs: ``keyframes.py`` spends it on the static scene a
few times a second, not on every frame.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect import Detector
from hiper_cli.perceive.detect._onnx import nms
from hiper_cli.types import Detections, Frame

__all__ = [
    "TILE_EDGE_PX", "TiledDetector", "merge_detections", "tile_boxes", "tile_detections", "whole_in_tile",
]

TILE_EDGE_PX = 4.0
"""A tile's detection whose box lies this close to an inner edge of the tile (one the image
goes on beyond) was cut there, and is dropped."""
MERGE_IOU = 0.45
"""Two boxes of one class overlapping this much (IoU) are one object: the better score stays."""


Box = tuple[int, int, int, int]
"""A tile: (x0, y0, x1, y1) in image pixels."""


def tile_boxes(width: int, height: int, rows: int, cols: int, overlap: float) -> list[Box]:
    """The tiles (x0, y0, x1, y1) in image pixels: ``rows × cols`` of equal size, covering the
    image, neighbours overlapping by ``overlap`` of a tile's width or height."""
    if rows < 1 or cols < 1 or not 0.0 <= overlap < 1.0:
        raise ConfigError(f"tiles {rows}x{cols} with overlap {overlap}: expected at least 1x1 and "
                          "an overlap in [0, 1), e.g. 2x2 with 0.25")
    tw = int(np.ceil(width / (cols - (cols - 1) * overlap)))
    th = int(np.ceil(height / (rows - (rows - 1) * overlap)))
    xs = np.linspace(0, width - tw, cols).round().astype(int) if cols > 1 else np.array([0])
    ys = np.linspace(0, height - th, rows).round().astype(int) if rows > 1 else np.array([0])
    return [(int(x), int(y), int(min(x + tw, width)), int(min(y + th, height))) for y in ys for x in xs]


def _crop(frame: Frame, box: Box) -> Frame:
    """``frame`` cut to ``box``: its images, and a camera whose principal point moved with it."""
    x0, y0, x1, y1 = box
    cam = replace(frame.camera, width=x1 - x0, height=y1 - y0, cx=frame.camera.cx - x0,
                  cy=frame.camera.cy - y0)
    return replace(frame, rgb=np.ascontiguousarray(frame.rgb[y0:y1, x0:x1]),
                   depth_m=np.ascontiguousarray(frame.depth_m[y0:y1, x0:x1]), camera=cam, detections=None)


def whole_in_tile(xyxy: NDArray[np.float64], box: Box, width: int,
                   height: int) -> NDArray[np.bool_]:
    """Which boxes (image pixels) keep clear of the tile's inner edges (those not on the image's)."""
    x0, y0, x1, y1 = box
    ok = np.ones(len(xyxy), dtype=bool)
    if x0 > 0:
        ok &= xyxy[:, 0] > x0 + TILE_EDGE_PX
    if y0 > 0:
        ok &= xyxy[:, 1] > y0 + TILE_EDGE_PX
    if x1 < width:
        ok &= xyxy[:, 2] < x1 - TILE_EDGE_PX
    if y1 < height:
        ok &= xyxy[:, 3] < y1 - TILE_EDGE_PX
    return ok


def tile_detections(detector: Detector, frame: Frame, box: Box) -> Detections:
    """``detector``'s detections on the tile ``box`` of ``frame``, in the image's pixels, without
    those cut by an inner edge of the tile."""
    found = detector.detect(_crop(frame, box))
    if not len(found):
        return found
    xyxy = found.xyxy + np.array([box[0], box[1], box[0], box[1]], dtype=np.float64)
    whole = whole_in_tile(xyxy, box, frame.width, frame.height)
    return Detections(xyxy, found.class_names, found.scores).subset(whole)


def merge_detections(parts: list[Detections], iou: float = MERGE_IOU) -> Detections:
    """``parts`` as one set of detections, one box per object and class (class-wise NMS)."""
    parts = [p for p in parts if len(p)]
    if not parts:
        return Detections.empty()
    xyxy = np.concatenate([p.xyxy for p in parts])
    names = tuple(n for p in parts for n in p.class_names)
    scores = np.concatenate([p.scores for p in parts])
    ids = {n: k for k, n in enumerate(sorted(set(names)))}
    keep = nms(xyxy, scores, np.array([ids[n] for n in names], dtype=np.int64), iou)
    return Detections(xyxy[keep], tuple(names[k] for k in keep), scores[keep])


class TiledDetector:
    """``detector`` on the whole image and on ``rows × cols`` overlapping tiles of it, merged.

    ``whole=False`` leaves the whole image out (its detections are already at hand: the frame's
    own look)."""

    def __init__(self, detector: Detector, rows: int = 2, cols: int = 2, overlap: float = 0.25,
                 whole: bool = True) -> None:
        tile_boxes(64, 64, rows, cols, overlap)  # checks the values
        self.detector = detector
        self.rows, self.cols, self.overlap, self.whole = rows, cols, overlap, whole
        self.name = f"{detector.name}+tiles{rows}x{cols}"
        self.class_names = getattr(detector, "class_names", None)

    def detect(self, frame: Frame) -> Detections:
        parts = [self.detector.detect(frame)] if self.whole else []
        for box in tile_boxes(frame.width, frame.height, self.rows, self.cols, self.overlap):
            parts.append(tile_detections(self.detector, frame, box))
        return merge_detections(parts)
