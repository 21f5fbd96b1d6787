"""Two rates: the detector's quick look every few frames, the static scene a closer one at keyframes.

Every frame is segmented and tracked at the sensor rate. The quick look (the whole image at the
detector's input size) runs on every frame, or, with ``detector_hz`` set (``perceive
--detector-hz``), that many times a second and on every keyframe; the frames between are then
named by the last look's detections, moved to the new view (``held.py``). The quick look shrinks a
640 × 480 image to 416 × 312 for YOLOX-Nano, and small or distant things (a book on a shelf, a cup
on a desk) fall below what it can name. At a keyframe (``CLOSER_LOOK_S`` of log after the last
one, or sooner at a new viewpoint: the camera moved ``CLOSER_LOOK_MOVE_M`` or turned
``CLOSER_LOOK_TURN_DEG``) the detector also looks at the image's tiles (``detect.tiled``: 2 × 2
tiles, each shrunk less, 1.8 times closer). One tile a frame, on the keyframe and the frames after
it: the worker's time per frame grows by one detector run, not four, so the whole command keeps
the sensor rate, and over those few frames (a tenth of a second at 30 Hz) the static scene barely
moves in the image. The tile's detections joined with the frame's own, looked at or held
(``tiled.merge_detections``), name the blobs the tile held whole (``closer_detections``); those
names count in the closer looks' own vote (``class_vote``): the quick look's ``unknown`` on a
thing too small for it is no evidence against them.

Only a detector that looks at the image gets the closer look and a quick look below the sensor
rate: ``log`` and ``truth`` replay recorded detections of every frame, at no cost.
"""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.detect import Detector
from hiper_cli.perceive.detect.tiled import merge_detections, tile_boxes, tile_detections, whole_in_tile
from hiper_cli.types import Detections, Frame

__all__ = [
    "CLOSER_LOOK_MOVE_M", "CLOSER_LOOK_S", "CLOSER_LOOK_TILES", "CLOSER_LOOK_TURN_DEG",
    "KeyframeLook",
]

CLOSER_LOOK_S: float = 0.5
"""A keyframe at most this long (s of log) after the last one (0: no closer look)."""
CLOSER_LOOK_MOVE_M: float = 0.5
"""... or sooner, once the camera moved this far from where the last one was taken (m)."""
CLOSER_LOOK_TURN_DEG: float = 20.0
"""... or turned this much from the last one's viewing direction (degrees)."""
CLOSER_LOOK_TILES: tuple[int, int, float] = (2, 2, 0.25)
"""The closer look's tiles: rows, columns, overlap of neighbours (share of a tile)."""
GIVEN_KEPT = 8
"""Frames whose tile is remembered (``covers``): the detector runs at most one frame ahead."""
REPLAYED = ("log", "truth")
"""Detectors that replay recorded detections: no closer look at the image."""


class KeyframeLook:
    """Which frames get a tile of the closer look, and that look's detections.

    ``tile_for(frame)`` is called once per frame in the log's order (when its detection is
    started) and says which tile that frame gets (None: the quick look only); ``look`` runs the
    detector on that tile and joins its detections to the frame's own."""

    def __init__(self, detector: Detector, detector_name: str, detector_hz: float = 0.0) -> None:
        self.detector = detector
        self.detector_hz = detector_hz  # quick looks per s of log, and at keyframes (0: every frame)
        names = {detector_name, getattr(detector, "name", "")}
        self.looks_at_images = not names & set(REPLAYED)
        self.enabled = CLOSER_LOOK_S > 0 and self.looks_at_images
        self._last_s: float | None = None
        self._last_pose: np.ndarray | None = None
        self._pending: list[int] = []  # the tiles the frames after a keyframe still get
        self._looked_s: float | None = None  # the stamp of the last quick look
        self._scheduled_s: float | None = None  # the stamp of the frame scheduled last
        self._given: dict[float, int] = {}  # stamp (s) -> the tile of that frame, the latest few
        self._tiles: dict[float, Detections] = {}  # stamp (s) -> its tile's detections
        self._closer: dict[float, Detections] = {}  # stamp (s) -> its closer look's detections
        self.keyframes = 0
        self.quick_looks = 0

    def schedule(self, frame: Frame) -> tuple[bool, int | None]:
        """Whether the quick look runs on ``frame``, and the tile of the closer look it gets
        (``tile_for``). Called once per frame, in the log's order."""
        tile = self.tile_for(frame)
        if not self.looks_at_images:
            return True, tile
        step_s = 0.0 if self._scheduled_s is None else max(frame.stamp_s - self._scheduled_s, 0.0)
        self._scheduled_s = max(frame.stamp_s, self._scheduled_s or frame.stamp_s)
        # a frame handed over before the one looked at last (the first, started ahead) is looked at;
        # a frame half a step or more past 1 / detector_hz would be farther than this one
        age_s = None if self._looked_s is None else frame.stamp_s - self._looked_s
        look = (self.detector_hz <= 0 or age_s is None or age_s <= 0 or tile == 0
                or age_s >= 1.0 / self.detector_hz - step_s / 2.0 - 1e-6)
        if look:
            self._looked_s = frame.stamp_s
            self.quick_looks += 1
        return look, tile

    def tile_for(self, frame: Frame) -> int | None:
        """The tile (index into ``tile_boxes``) ``frame`` gets, or None."""
        if not self.enabled:
            return None
        if not self._pending and self._due(frame):
            rows, cols, _ = CLOSER_LOOK_TILES
            self._pending = list(range(rows * cols))
            self._last_s, self._last_pose = frame.stamp_s, frame.T_map_cam
            self.keyframes += 1
        if not self._pending:
            return None
        tile = self._pending.pop(0)
        self._given[frame.stamp_s] = tile
        while len(self._given) > GIVEN_KEPT:
            stamp_s = next(iter(self._given))
            del self._given[stamp_s]
            self._closer.pop(stamp_s, None)
            self._tiles.pop(stamp_s, None)
        return tile

    def covers(self, frame: Frame, xyxy: np.ndarray) -> bool:
        """Whether ``frame``'s tile of a closer look held the image box ``xyxy`` whole."""
        tile = self._given.get(frame.stamp_s)
        if tile is None:
            return False
        rows, cols, overlap = CLOSER_LOOK_TILES
        box = tile_boxes(frame.width, frame.height, rows, cols, overlap)[tile]
        x0, y0, x1, y1 = box
        inside = x0 <= xyxy[0] and y0 <= xyxy[1] and xyxy[2] <= x1 and xyxy[3] <= y1
        return bool(inside and whole_in_tile(np.reshape(xyxy, (1, 4)), box, frame.width, frame.height)[0])

    def _due(self, frame: Frame) -> bool:
        if self._last_s is None or self._last_pose is None:
            return True
        if frame.stamp_s - self._last_s >= CLOSER_LOOK_S:
            return True
        moved_m = float(np.linalg.norm(frame.T_map_cam[:3, 3] - self._last_pose[:3, 3]))
        cos = float(np.dot(frame.T_map_cam[:3, 2], self._last_pose[:3, 2]))
        turned_deg = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
        return moved_m >= CLOSER_LOOK_MOVE_M or turned_deg >= CLOSER_LOOK_TURN_DEG

    def look(self, frame: Frame, tile: int) -> None:
        """Run the closer look on ``frame``'s tile ``tile`` (in the detector's worker); ``join``
        adds the frame's own detections."""
        rows, cols, overlap = CLOSER_LOOK_TILES
        box = tile_boxes(frame.width, frame.height, rows, cols, overlap)[tile]
        self._tiles[frame.stamp_s] = tile_detections(self.detector, frame, box)

    def join(self, frame: Frame, dets: Detections) -> None:
        """Keep ``frame``'s closer look for ``closer_detections``: its tile's detections with
        ``dets``, the frame's own (looked at or held)."""
        tiled = self._tiles.pop(frame.stamp_s, None)
        if tiled is not None:
            self._closer[frame.stamp_s] = merge_detections([dets, tiled])

    def closer_detections(self, frame: Frame, xyxy: np.ndarray) -> Detections | None:
        """``frame``'s closer look when its tile held the image box ``xyxy`` whole, else None."""
        return self._closer.get(frame.stamp_s) if self.covers(frame, xyxy) else None

