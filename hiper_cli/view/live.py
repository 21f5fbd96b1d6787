"""Perception streamed to Rerun while it runs: ``LiveView`` is an ``on_frame`` hook.

Handed to ``run_stages`` (or ``pipeline.perceive(on_frame=...)``), it logs each frame's camera
pose, the instances the frame created or updated (same entity paths as the recording, see
docs/view.md), clears foreground instances not updated for ``hold_s`` and merged-away ones,
and at most ``image_hz`` frames per second the RGB, depth, detector boxes and blobs. Nothing of
it runs when no hook is given, so perception without ``--view`` costs nothing more.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.model import FrameResult, Instance
from hiper_cli.types import Frame
from hiper_cli.view.camera import log_frame_images, overlay_of
from hiper_cli.view.recording import EPOCH_STAMP_S, import_rerun, log_pinhole, new_recording, quat_xyzw
from hiper_cli.view.style import CAMERA_PATH, ROBOT_PATH, class_color, entity_path

__all__ = ["LiveView"]

# Vertices of the robot's path sent with each image frame (subsampled beyond this).
_PATH_VERTICES = 500


class LiveView:
    """``live = LiveView.open(spawn=True)``; ``live(frame, result)`` per frame; ``live.close()``."""

    def __init__(self, rec: Any, image_hz: float = 2.0, hold_s: float = 0.5,
                 background_alpha: int = 90) -> None:
        self.rr = import_rerun()
        self.rec = rec
        self.image_hz = image_hz
        self.hold_s = hold_s
        self.alpha = background_alpha
        self._kind: str | None = None
        self._last_image_s = -np.inf
        self._stamp_s = 0.0
        self._path_m: list[list[float]] = []
        self._seen_s: dict[str, float] = {}  # foreground uuid -> last update
        self._paths: dict[str, str] = {}  # instance uuid -> entity path
        self._pinhole = False

    @classmethod
    def open(cls, *, spawn: bool = False, out: Path | None = None, image_hz: float = 2.0) -> LiveView:
        """A live view streaming to a new viewer (``spawn``) and/or saving to ``out`` (.rrd)."""
        return cls(new_recording(out, spawn, with_images=True), image_hz=image_hz)

    def _time(self, stamp_s: float) -> None:
        if self._kind is None:
            self._kind = "timestamp" if stamp_s > EPOCH_STAMP_S else "duration"
        self._stamp_s = stamp_s
        self.rec.set_time("stamp", **{self._kind: float(stamp_s)})

    def _instance(self, inst: Instance) -> None:
        rr = self.rr
        path = entity_path(inst.layer, inst.class_name, inst.uuid)
        if self._paths.get(inst.uuid, path) != path:  # its class changed ("unknown" -> "person")
            self.rec.log(self._paths[inst.uuid], rr.Clear(recursive=True))
        self._paths[inst.uuid] = path
        box = inst.box
        if inst.layer == "background":
            self.rec.log(path, rr.Boxes3D(centers=[box.center_m], half_sizes=[box.extent_m / 2.0],
                                          quaternions=[quat_xyzw(box.R)], fill_mode="solid",
                                          colors=[(*class_color(inst.class_name), self.alpha)]))
            return
        self._seen_s[inst.uuid] = self._stamp_s
        self.rec.log(path, rr.Boxes3D(centers=[box.center_m], half_sizes=[box.extent_m / 2.0],
                                      quaternions=[quat_xyzw(box.R)], colors=[class_color(inst.class_name)],
                                      labels=[f"{inst.class_name} {inst.uuid[-4:]}"]))

    def _clear(self, uuid: str) -> None:
        self._seen_s.pop(uuid, None)
        path = self._paths.pop(uuid, None)
        if path is not None:
            self.rec.log(path, self.rr.Clear(recursive=True))

    def _camera(self, frame: Frame) -> None:
        if not self._pinhole:
            log_pinhole(self.rr, self.rec, frame.camera, 0.4)
            self._pinhole = True
        T = frame.T_map_cam
        self.rec.log(CAMERA_PATH, self.rr.Transform3D(translation=T[:3, 3], mat3x3=T[:3, :3]))
        self._path_m.append(T[:3, 3].tolist())

    def _images(self, frame: Frame, result: FrameResult) -> None:
        if self.image_hz > 0 and frame.stamp_s - self._last_image_s < 1.0 / self.image_hz:
            return
        self._last_image_s = frame.stamp_s
        log_frame_images(self.rr, self.rec, frame, overlay_of(result.observations))
        if len(self._path_m) >= 2:
            path = self._path_m[:: max(1, len(self._path_m) // _PATH_VERTICES)]
            self.rec.log(ROBOT_PATH, self.rr.LineStrips3D([path], colors=[(60, 60, 60)], radii=0.01))

    def __call__(self, frame: Frame | None, result: FrameResult) -> None:
        """Log one frame's result (``frame`` None: what the stages flushed at the end)."""
        if frame is not None:
            self._time(frame.stamp_s)
            self._camera(frame)
        for inst in result.instances:
            self._instance(inst)
        for uuid in result.deleted_instances:
            self._clear(uuid)
        for uuid in [u for u, t in self._seen_s.items() if self._stamp_s - t > self.hold_s]:
            self._clear(uuid)
        if frame is not None:
            self._images(frame, result)

    def close(self) -> None:
        self.rec.flush()
        self.rec.disconnect()
