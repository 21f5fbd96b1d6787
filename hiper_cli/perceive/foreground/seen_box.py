"""The box a static object fills: the robust union of the boxes of the blobs it was seen as.

One view shows a part of an object (the near side of a bed, a chair's back above a table, a
couch cut by the image's edge), and a constant-velocity filter fed those parts drifts: a blob
that shrinks at the border moves its centroid, the filter reads a velocity and extrapolates it
after the last update. The box of every blob, in the map frame, does not drift; their union
covers what all the views saw together. The union takes the ``SEEN_BOX_QUANTILE`` of the blobs' lower
corners and the 1 - ``SEEN_BOX_QUANTILE`` of their upper ones, so that a few blobs of something else
(a wrong association, depth noise at an edge) do not stretch it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["SEEN_BOX_QUANTILE", "SeenBox"]

FloatArray = NDArray[np.float64]
SEEN_BOX_QUANTILE = 0.2  # of the blobs' corners; 1 in 5 blobs may reach past the box
MAX_SEEN_BOXES = 600  # the latest blob boxes kept (40 s of a static object at 15 Hz)
MIN_MOVED_BOXES = 8  # blobs before the first and last quarters can tell a move
MOVED_MARGIN_M = 0.1  # the quarters' boxes lie this far apart horizontally: it moved


@dataclass
class SeenBox:
    """The map-frame (lower, upper) corners of the blobs of one track, latest last."""

    lower_m: list[FloatArray] = field(default_factory=list)
    upper_m: list[FloatArray] = field(default_factory=list)
    _cache: tuple[int, FloatArray, FloatArray] | None = field(default=None, repr=False)

    def add(self, lower_m: FloatArray, upper_m: FloatArray) -> None:
        self.lower_m.append(np.asarray(lower_m, dtype=np.float64))
        self.upper_m.append(np.asarray(upper_m, dtype=np.float64))
        if len(self.lower_m) > 2 * MAX_SEEN_BOXES:  # trimmed in batches: amortised O(1)
            del self.lower_m[:-MAX_SEEN_BOXES]
            del self.upper_m[:-MAX_SEEN_BOXES]
        self._cache = None

    def extend(self, other: SeenBox) -> None:
        """Add the blobs of ``other`` (a track this one absorbed)."""
        for lo, hi in zip(other.lower_m, other.upper_m, strict=True):
            self.add(lo, hi)

    def __len__(self) -> int:
        return len(self.lower_m)

    def moved(self) -> bool:
        """Whether the object moved: the (median) box of its first quarter of blobs and that of
        its last quarter lie apart horizontally. Views of one static object from different sides
        overlap (each shows some of it); a cart that drove more than its length does not."""
        n = len(self.lower_m)
        if n < MIN_MOVED_BOXES:
            return False
        start = max(n - MAX_SEEN_BOXES, 0)
        k = max((n - start) // 4, 1)
        lower, upper = np.array(self.lower_m[start:]), np.array(self.upper_m[start:])
        first_lo, first_hi = np.median(lower[:k, :2], axis=0), np.median(upper[:k, :2], axis=0)
        last_lo, last_hi = np.median(lower[-k:, :2], axis=0), np.median(upper[-k:, :2], axis=0)
        gap = np.maximum(last_lo - first_hi, first_lo - last_hi)
        return bool(np.any(gap > MOVED_MARGIN_M))

    def corners(self) -> tuple[FloatArray, FloatArray] | None:
        """(lower, upper) corners of the union; None before any blob."""
        n = len(self.lower_m)
        if n == 0:
            return None
        if self._cache is not None and self._cache[0] == n:
            return self._cache[1], self._cache[2]
        start = max(n - MAX_SEEN_BOXES, 0)
        lo = np.quantile(np.array(self.lower_m[start:]), SEEN_BOX_QUANTILE, axis=0)
        hi = np.quantile(np.array(self.upper_m[start:]), 1.0 - SEEN_BOX_QUANTILE, axis=0)
        hi = np.maximum(hi, lo)
        self._cache = (n, lo, hi)
        return lo, hi

    def box(self) -> tuple[FloatArray, FloatArray] | None:
        """(centre, extent) of the union; None before any blob."""
        found = self.corners()
        if found is None:
            return None
        lo, hi = found
        return (lo + hi) / 2.0, hi - lo
