"""The box a static object fills: the robust union of the boxes of the blobs it was seen as.

One view shows a part of an object (the near side of a bed, a chair's back above a table, a
couch cut by the image's edge), and a constant-velocity filter fed those parts drifts: a blob
that shrinks at the border moves its centroid, the filter reads a velocity and extrapolates it
after the last update. The box of every blob, in the map frame, does not drift; their union
covers what all the views saw together. The union takes the ``SEEN_BOX_QUANTILE`` of the blobs' lower
corners and the 1 - ``SEEN_BOX_QUANTILE`` of their upper ones, so that a few blobs of something else
(a wrong association, depth noise at an edge) do not stretch it.

The detector tells which blobs show the object: a track also takes blobs no detection named,
and some of those are something else (floor strips beside a bed seen through a doorway, a table
leg, the table a bottle stood on before the background mapped it). When at least
``MIN_NAMED_BOXES`` of the blobs were named (by any class: a bed taken for a couch is still the
bed), the union is of the named ones only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["SEEN_BOX_QUANTILE", "SeenBox"]

FloatArray = NDArray[np.float64]
SEEN_BOX_QUANTILE = 0.2  # of the blobs' corners; 1 in 5 blobs may reach past the box
MAX_SEEN_BOXES = 600  # the latest blob boxes kept (40 s of a static object at 15 Hz)
MIN_MOVED_BOXES = 8  # blobs before the first and last quarters can tell a move
MOVED_MARGIN_M = 0.1  # the quarters' boxes lie this far apart horizontally: it moved
MIN_NAMED_BOXES = 5  # named blobs enough to make the box of them alone
MIN_BRIDGING_BOXES = 2  # views reaching both where a track was first and last: it did not move
_NO_VIEWPOINT = np.full(3, np.nan)


@dataclass
class SeenBox:
    """The map-frame (lower, upper) corners of the blobs of one track, latest last."""

    lower_m: list[FloatArray] = field(default_factory=list)
    upper_m: list[FloatArray] = field(default_factory=list)
    named: list[bool] = field(default_factory=list)  # per blob: a detection named it
    # per blob: the camera's position, map frame (NaN: not given), for ``amodal``
    viewpoints_m: list[FloatArray] = field(default_factory=list)
    tops_hidden: list[bool] = field(default_factory=list)  # per blob: its top was not in view
    bottoms_hidden: list[bool] = field(default_factory=list)  # per blob: its base was not in view
    classes: list[str] = field(default_factory=list)  # per blob: the class its view gave it
    _cache: tuple[int, FloatArray, FloatArray] | None = field(default=None, repr=False)
    _moved: tuple[int, bool] | None = field(default=None, repr=False)
    # per-blob lists as arrays (rows of the lists at their current length; ``_array``)
    _arrays: dict[str, NDArray[Any]] = field(default_factory=dict, repr=False)

    def add(
        self,
        lower_m: FloatArray,
        upper_m: FloatArray,
        named: bool = False,
        viewpoint_m: FloatArray | None = None,
        top_hidden: bool = False,
        bottom_hidden: bool = False,
        class_name: str = "",
    ) -> None:
        self.lower_m.append(np.asarray(lower_m, dtype=np.float64))
        self.upper_m.append(np.asarray(upper_m, dtype=np.float64))
        self.named.append(bool(named))
        view = _NO_VIEWPOINT if viewpoint_m is None else np.asarray(viewpoint_m, dtype=np.float64)
        self.viewpoints_m.append(view)
        self.tops_hidden.append(bool(top_hidden))
        self.bottoms_hidden.append(bool(bottom_hidden))
        self.classes.append(class_name)
        if len(self.lower_m) > 2 * MAX_SEEN_BOXES:  # trimmed in batches: amortised O(1)
            del self.lower_m[:-MAX_SEEN_BOXES]
            del self.upper_m[:-MAX_SEEN_BOXES]
            del self.named[:-MAX_SEEN_BOXES]
            del self.viewpoints_m[:-MAX_SEEN_BOXES]
            del self.tops_hidden[:-MAX_SEEN_BOXES]
            del self.bottoms_hidden[:-MAX_SEEN_BOXES]
            del self.classes[:-MAX_SEEN_BOXES]
            self._arrays.clear()
        self._cache = None
        self._moved = None

    def extend(self, other: SeenBox) -> None:
        """Add the blobs of ``other`` (a track this one absorbed)."""
        for blob in zip(other.lower_m, other.upper_m, other.named, other.viewpoints_m, other.tops_hidden,
                        other.bottoms_hidden, other.classes, strict=True):
            self.add(*blob)

    def __len__(self) -> int:
        return len(self.lower_m)

    def _latest(self, per_blob: Sequence[Any]) -> Sequence[Any]:
        """``per_blob`` (one value per blob) of the latest ``MAX_SEEN_BOXES`` blobs (the lists
        are trimmed in batches, so they may hold more)."""
        return per_blob[max(len(self.lower_m) - MAX_SEEN_BOXES, 0):]

    def _array(self, name: str) -> NDArray[Any]:
        """The per-blob list ``name`` as one array, rows for the latest ``MAX_SEEN_BOXES``
        blobs (``np.array`` of ``_latest``). Kept between calls and grown by the rows added
        since: the box, its move and its viewpoint are read every frame, and converting up to
        1200 small arrays each time cost more than the rest of the reading."""
        values: list[Any] = getattr(self, name)
        have = self._arrays.get(name)
        if have is None or len(have) > len(values):
            have = np.array(values)
        elif len(have) < len(values):
            have = np.concatenate([have, np.array(values[len(have):])]) if len(have) else np.array(values)
        have.flags.writeable = False  # shared between calls: read only
        self._arrays[name] = have
        return have[max(len(values) - MAX_SEEN_BOXES, 0):]

    def _used(self, per_blob: str) -> NDArray[Any]:
        """The per-blob list ``per_blob`` (an attribute name) of the blobs the box is of: the
        latest ``MAX_SEEN_BOXES``, the named ones alone when there are ``MIN_NAMED_BOXES`` of them."""
        values = self._array(per_blob)
        named = self._array("named").astype(bool, copy=False)
        return values[named] if int(named.sum()) >= MIN_NAMED_BOXES else values

    def _boxes(self) -> tuple[FloatArray, FloatArray]:
        """(lower, upper) corners (K, 3) of the blobs the box is of (``_used``)."""
        return self._used("lower_m"), self._used("upper_m")

    def viewpoint(self) -> FloatArray | None:
        """The median camera position (map frame) of the blobs the box is of (``_used``); None
        when no blob had one."""
        views = self._used("viewpoints_m").astype(np.float64).reshape(-1, 3)
        views = views[np.isfinite(views).all(axis=1)]
        return np.median(views, axis=0) if len(views) else None

    def top_seen(self) -> bool:
        """Whether views showed the object's top: at least ``SEEN_BOX_QUANTILE`` of the blobs
        the box is of (``_used``), as many as its upper quantile needs, had it in view."""
        return self._shown("tops_hidden")

    def bottom_seen(self) -> bool:
        """Whether views showed where the object stands: at least ``SEEN_BOX_QUANTILE`` of the
        blobs the box is of (``_used``), as many as its lower quantile needs, had its base in view."""
        return self._shown("bottoms_hidden")

    def _shown(self, hidden_per_blob: str) -> bool:
        """Whether at least ``SEEN_BOX_QUANTILE`` of the blobs the box is of (``_used``) were not
        hidden there (no blob: shown)."""
        hidden = self._used(hidden_per_blob).astype(bool)
        return len(hidden) == 0 or float(np.mean(~hidden)) >= SEEN_BOX_QUANTILE

    def moved(self) -> bool:
        """Whether the object moved: the (median) box of its first quarter of blobs and that of
        its last quarter lie apart horizontally, and no view (``MIN_BRIDGING_BOXES`` of them)
        reached both. Views of one static object from different sides overlap (each shows some
        of it), and a large one seen in parts as the view pans (a TV's right end, then its left
        end) was also seen whole in between; a cart that drove more than its length was not."""
        n = len(self.lower_m)
        if n < MIN_MOVED_BOXES:
            return False
        if self._moved is None or self._moved[0] != n:
            self._moved = (n, self._moved_now())
        return self._moved[1]

    def shift_m(self, every_blob: bool = False) -> float:
        """How far the object went, horizontally: between the (median) box of its first quarter
        of blobs and that of its last, the lesser move of the two sides along each axis when
        both moved the same way (0 otherwise). A blob that grew as more of it came into view
        moved one side only; a walker moves both (0 with fewer than ``MIN_MOVED_BOXES``).
        ``every_blob``: of all the latest blobs, not the named ones alone (``_used``): the
        path of a walker, whom a detector names in some frames only."""
        if len(self.lower_m) < MIN_MOVED_BOXES:
            return 0.0
        (first_lo, first_hi), (last_lo, last_hi) = self._quarters(every_blob)[2:]
        d_lower, d_upper = last_lo - first_lo, last_hi - first_hi
        both = np.where(d_lower * d_upper > 0, np.minimum(np.abs(d_lower), np.abs(d_upper)), 0.0)
        return float(np.hypot(*both))

    def _quarters(self, every_blob: bool = False) -> tuple[
        FloatArray, FloatArray, tuple[FloatArray, FloatArray], tuple[FloatArray, FloatArray]
    ]:
        """The blobs' (lower, upper) corners (``_boxes``; ``every_blob``: of all the latest), then
        the horizontal (lower, upper) corners of the median box of the first quarter of them and
        of the last quarter."""
        if every_blob:
            lower, upper = self._array("lower_m"), self._array("upper_m")
        else:
            lower, upper = self._boxes()
        k = max(len(lower) // 4, 1)
        first = (np.median(lower[:k, :2], axis=0), np.median(upper[:k, :2], axis=0))
        last = (np.median(lower[-k:, :2], axis=0), np.median(upper[-k:, :2], axis=0))
        return lower, upper, first, last

    def _moved_now(self) -> bool:
        lower, upper, (first_lo, first_hi), (last_lo, last_hi) = self._quarters()
        gap = np.maximum(last_lo - first_hi, first_lo - last_hi)
        if not np.any(gap > MOVED_MARGIN_M):
            return False
        reach_first = np.all((lower[:, :2] <= first_hi) & (upper[:, :2] >= first_lo), axis=1)
        reach_last = np.all((lower[:, :2] <= last_hi) & (upper[:, :2] >= last_lo), axis=1)
        return int(np.count_nonzero(reach_first & reach_last)) < MIN_BRIDGING_BOXES

    def corners(self) -> tuple[FloatArray, FloatArray] | None:
        """(lower, upper) corners of the union; None before any blob."""
        n = len(self.lower_m)
        if n == 0:
            return None
        if self._cache is not None and self._cache[0] == n:
            return self._cache[1], self._cache[2]
        lower, upper = self._boxes()
        lo = np.quantile(lower, SEEN_BOX_QUANTILE, axis=0)
        hi = np.quantile(upper, 1.0 - SEEN_BOX_QUANTILE, axis=0)
        hi = np.maximum(hi, lo)
        self._cache = (n, lo, hi)
        return lo, hi

    def top_of(self, class_name: str) -> float | None:
        """The height (m, map frame) of the top of the blobs views named ``class_name``, as the
        union takes it (its upper quantile); None when no kept blob was. A table found by its
        shape is as high as its top, whatever stood on it when a detector named the blob."""
        kept = zip(self._latest(self.upper_m), self._latest(self.classes), strict=True)
        tops = [upper[2] for upper, named in kept if named == class_name]
        return float(np.quantile(tops, 1.0 - SEEN_BOX_QUANTILE)) if tops else None

    def box(self) -> tuple[FloatArray, FloatArray] | None:
        """(centre, extent) of the union; None before any blob."""
        found = self.corners()
        if found is None:
            return None
        lo, hi = found
        return (lo + hi) / 2.0, hi - lo
