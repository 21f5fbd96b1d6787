"""A focused look: the detector on a crop around an object its every-frame looks left undecided.

The every-frame look shrinks a 640 × 480 image to 416 × 312 for YOLOX-Nano; a bottle 3 m away is
a few dozen pixels there, and the detector names it in a tenth of its views, silent in the
rest, so the vote (``class_vote``) cannot tell it from a confusion repeated as rarely. A crop
around the object, a square ``FOCUS_SIDE`` times its image box's longest side (at least
``FOCUS_MIN_SIDE_PX``), shows it to the detector at several times the pixels, and its answer is
about that object: the crop holds it whole, in the middle.

Only a track that is a question gets such a look: the every-frame detector named it a class
(``class_vote.search_class``) but the vote does not show that class (too few names among the
silent views, or too weak against them). At most ``FOCUS_PER_S`` looks a second of log, the
tracks looked at least first, each at most ``FOCUS_MAX_LOOKS`` times, and only in a view that
shows its blob inside the image: the looks cost a detector run each, a few a second, not one a
frame. What a look says (a class, ``unknown`` for silence) counts in a vote of its own
(``class_vote.record_focus``): the every-frame hypothesis is named when the focused looks confirm
it (``class_vote.FOCUS_MIN_LOOKS``), two looks at different scales agreeing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.detect import Detector
from hiper_cli.perceive.detect.tiled import tile_detections
from hiper_cli.types import Detections, Frame

__all__ = ["FOCUS_MAX_LOOKS", "FOCUS_MIN_SIDE_PX", "FOCUS_PER_S", "FOCUS_SIDE", "FocusedLook", "focus_box"]

FOCUS_PER_S: float = 6.0
"""Focused looks per second of log, at most (0: none): a question is in view for a few seconds.
One detector run each (YOLOX-Nano, about 11 ms of CPU); they run only while a track is a
question, ``FOCUS_MAX_LOOKS`` at most each, so a log spends a few dozen in all."""
FOCUS_MAX_LOOKS: int = 8
"""Focused looks per track, at most: enough to confirm or refuse its hypothesis."""
FOCUS_SIDE: float = 2.0
"""The crop's side over the object's image box's longest side: the object and its context."""
FOCUS_MIN_SIDE_PX: float = 192.0
"""The crop's smallest side (pixels): the detector's 416 px input shows it 2.2 times enlarged."""
FOCUS_MAX_BOX_PX: float = 200.0
"""An image box longer than this (pixels) is looked at closely enough by the whole image's look."""


Box = tuple[int, int, int, int]


def focus_box(xyxy: NDArray[np.float64], width: int, height: int) -> Box | None:
    """The crop (x0, y0, x1, y1; pixels) around the image box ``xyxy``: a square of
    ``FOCUS_SIDE`` times its longest side, at least ``FOCUS_MIN_SIDE_PX``, moved inside the image;
    None for a box too large to gain from a crop (``FOCUS_MAX_BOX_PX``)."""
    longest = float(max(xyxy[2] - xyxy[0], xyxy[3] - xyxy[1]))
    if longest > FOCUS_MAX_BOX_PX:
        return None
    side = min(max(FOCUS_SIDE * longest, FOCUS_MIN_SIDE_PX), float(width), float(height))
    cx, cy = (xyxy[0] + xyxy[2]) / 2.0, (xyxy[1] + xyxy[3]) / 2.0
    x0 = round(float(min(max(cx - side / 2.0, 0.0), width - side)))
    y0 = round(float(min(max(cy - side / 2.0, 0.0), height - side)))
    return x0, y0, int(min(x0 + round(side), width)), int(min(y0 + round(side), height))


@dataclass
class Question:
    """A track the focused look may look at: its uuid, how often it was looked at already, and
    its blob's image box in this frame."""

    uuid: str
    looks: int
    xyxy: NDArray[np.float64]


class FocusedLook:
    """When focused looks run (``due``), which tracks they look at (``pick``), and the look
    itself (``look``: the detector on the crop, boxes in the image's pixels)."""

    def __init__(self, detector: Detector, enabled: bool) -> None:
        self.detector = detector
        self.enabled = enabled and FOCUS_PER_S > 0
        self._credit = 0.0  # looks owed (``FOCUS_PER_S`` × s of log since the last spent)
        self._last_s: float | None = None
        self.looks = 0

    def due(self, stamp_s: float) -> int:
        """How many looks this frame may spend (0 mostly): one per 1 / ``FOCUS_PER_S`` s of log."""
        if not self.enabled:
            return 0
        if self._last_s is not None:
            self._credit = min(self._credit + FOCUS_PER_S * max(stamp_s - self._last_s, 0.0), 1.0)
        else:
            self._credit = 1.0
        self._last_s = stamp_s
        return int(self._credit + 1e-9)

    def pick(self, questions: list[Question], budget: int) -> list[Question]:
        """The ``budget`` questions looked at least so far (``FOCUS_MAX_LOOKS`` at most each);
        the credit spent on them."""
        open_ = sorted((q for q in questions if q.looks < FOCUS_MAX_LOOKS), key=lambda q: (q.looks, q.uuid))
        chosen = open_[:budget]
        self._credit -= len(chosen)
        return chosen

    def look(self, frame: Frame, xyxy: NDArray[np.float64]) -> Detections | None:
        """The detector's detections on the crop around ``xyxy`` (image pixels), without those
        cut by the crop's edges inside the image; None when the box is too large for one."""
        box = focus_box(xyxy, frame.width, frame.height)
        if box is None:
            return None
        self.looks += 1
        return tile_detections(self.detector, frame, box)
