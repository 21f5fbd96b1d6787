"""The log's own images in the recording: RGB and depth of a subsample of frames, with what
recognition made of each frame drawn on it (``/robot/camera/image/...``).

Per frame: the RGB as JPEG (``rgb``), the depth in millimetres (``depth``), the detector's boxes
that matched a segmented blob (``detections``, as the observations keep them: class and score),
each observation's sampled blob pixels (``blobs``, in the class colour) and the pixels of the
background planes (``planes``). A detection that matched no blob is not in the knowledge base
and is not drawn. Frames are taken at most ``image_hz`` per second (0: every frame), so a long
log stays quick to write and to open.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph import KnowledgeBase
from hiper_cli.model import Observation
from hiper_cli.perceive.logs import LogReader
from hiper_cli.types import Frame
from hiper_cli.view.scene import TimeWindow
from hiper_cli.view.style import IMAGE_PATH, class_color

__all__ = ["FrameOverlay", "log_frame_images", "log_frames", "overlay_of", "pick_frames"]

# Observations of a frame carry the frame's stamp exactly; this absorbs float printing.
_STAMP_TOL_S = 1e-6


@dataclass(frozen=True)
class FrameOverlay:
    """What the knowledge base holds of one frame: detector boxes ``boxes_xyxy`` (N, 4) pixels
    with ``labels``/``box_classes``; blob pixels ``blob_uv`` (M, 2) with their classes; plane
    pixels ``plane_uv`` (P, 2) with their classes."""

    boxes_xyxy: NDArray[np.float64]
    labels: tuple[str, ...]
    box_classes: tuple[str, ...]
    blob_uv: NDArray[np.float64]
    blob_classes: tuple[str, ...]
    plane_uv: NDArray[np.float64]
    plane_classes: tuple[str, ...]


def pick_frames(stamps_s: NDArray[np.float64], window: TimeWindow, image_hz: float) -> list[int]:
    """Indices of the frames inside ``window``, at most ``image_hz`` per second (0: all)."""
    picked: list[int] = []
    last = -np.inf
    for k in np.flatnonzero(window.mask(np.asarray(stamps_s, dtype=np.float64))):
        if image_hz <= 0 or stamps_s[k] - last >= 1.0 / image_hz - 1e-9:
            picked.append(int(k))
            last = float(stamps_s[k])
    return picked


def overlay_of(observations: Sequence[Observation]) -> FrameOverlay:
    """The overlay of a frame from its observations."""
    boxes, labels, box_cls = [], [], []
    blobs: list[NDArray[np.float64]] = []
    blob_cls: list[str] = []
    planes: list[NDArray[np.float64]] = []
    plane_cls: list[str] = []
    for obs in observations:
        data, cls = obs.data, obs.class_name
        uv = np.asarray(data.get("pixels_uv") or [], dtype=np.float64).reshape(-1, 2)
        if obs.layer == "background":
            planes.append(uv)
            plane_cls += [cls] * len(uv)
            continue
        det = data.get("detection") or {}
        xyxy = det.get("xyxy") or data.get("image_box_xyxy")
        if xyxy is not None and len(xyxy) == 4:
            boxes.append([float(v) for v in xyxy])
            name = str(det.get("class", cls))
            labels.append(f"{name} {det['score']:.2f}" if "score" in det else name)
            box_cls.append(cls)
        blobs.append(uv)
        blob_cls += [cls] * len(uv)
    return FrameOverlay(np.asarray(boxes, dtype=np.float64).reshape(-1, 4), tuple(labels), tuple(box_cls),
                        np.concatenate(blobs) if blobs else np.zeros((0, 2)), tuple(blob_cls),
                        np.concatenate(planes) if planes else np.zeros((0, 2)), tuple(plane_cls))


def _colors(classes: tuple[str, ...]) -> NDArray[np.uint8]:
    return np.array([class_color(c) for c in classes], dtype=np.uint8).reshape(-1, 3)


def log_frame_images(rr: Any, rec: Any, frame: Frame, overlay: FrameOverlay, jpeg_quality: int = 85) -> None:
    """Log one frame's images and overlay at the recording's current time."""
    import cv2

    ok, jpeg = cv2.imencode(".jpg", frame.rgb[:, :, ::-1], [cv2.IMWRITE_JPEG_QUALITY, jpeg_quality])
    if ok:
        rec.log(IMAGE_PATH + "/rgb", rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg"))
    depth_mm = np.clip(np.nan_to_num(frame.depth_m) * 1000.0, 0, 65535).astype(np.uint16)
    rec.log(IMAGE_PATH + "/depth", rr.DepthImage(depth_mm, meter=1000.0))
    rec.log(IMAGE_PATH + "/detections", rr.Boxes2D(array=overlay.boxes_xyxy, array_format=rr.Box2DFormat.XYXY,
                                                   labels=list(overlay.labels),
                                                   colors=_colors(overlay.box_classes)))
    rec.log(IMAGE_PATH + "/blobs", rr.Points2D(overlay.blob_uv, colors=_colors(overlay.blob_classes),
                                               radii=1.5))
    rec.log(IMAGE_PATH + "/planes", rr.Points2D(overlay.plane_uv, colors=_colors(overlay.plane_classes),
                                                radii=1.0))


def log_frames(rec: Any, set_time: Any, reader: LogReader, kb: KnowledgeBase, window: TimeWindow,
               image_hz: float, jpeg_quality: int = 85) -> int:
    """Log the picked frames of ``reader`` with their overlays; ``set_time(stamp_s)`` sets the
    recording's timeline. Returns how many frames were logged."""
    from hiper_cli.view.recording import import_rerun

    rr = import_rerun()
    info = reader.info()
    picked = pick_frames(info.stamps_s, window, image_hz)
    for k in picked:
        frame = reader.read_frame(k)
        seen = kb.observations_between(frame.stamp_s - _STAMP_TOL_S, frame.stamp_s + _STAMP_TOL_S)
        set_time(frame.stamp_s)
        log_frame_images(rr, rec, frame, overlay_of(seen), jpeg_quality)
    return len(picked)
