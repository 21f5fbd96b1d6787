"""What an object cut from a table's blob may continue: not the track of that blob.

Before a table top is found in a blob (``tables.split_unseen_tables``), the table and what
stands on it are one blob, and no detection names it: its track gathers ``unknown`` views of
the table and the bottle together. Once the top is found, the blob falls apart into the table
and the bottle, and the nearest-centre assignment may hand the bottle that track (the table
goes to a track beside it), whose many unknown views then outvote the bottle's names. The
track was the table's more than the bottle's: its last blob held the table. So a part cut
from a table's blob (``Measurement.cut_from_table_m``) may not continue an unnamed track whose
last blob held most of that table (``HELD_SHARE`` of the table box's volume); the table may,
and the part starts a track of its own. A named track keeps its parts (a cup seen once with
its table in one blob is still the cup's).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.class_vote import UNKNOWN

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.track import Track

__all__ = ["HELD_SHARE", "held_tables", "last_box"]

FloatArray = NDArray[np.float64]
HELD_SHARE = 0.5  # of the table box's volume inside a track's last blob box: it held the table
MIN_VOLUME_M3 = 1e-6


def held_tables(
    last_boxes: Sequence[tuple[FloatArray, FloatArray] | None],
    tables: Sequence[tuple[FloatArray, FloatArray] | None],
) -> NDArray[np.bool_]:
    """(tracks × measurements) whether a track's last blob box (lower, upper; None: none) held
    the table the measurement was cut from (lower, upper; None: not cut from one)."""
    held = np.zeros((len(last_boxes), len(tables)), dtype=bool)
    cut = [j for j, box in enumerate(tables) if box is not None]
    if not cut:
        return held
    t_lo = np.array([tables[j][0] for j in cut])  # type: ignore[index]
    t_hi = np.array([tables[j][1] for j in cut])  # type: ignore[index]
    volume = np.maximum(np.prod(t_hi - t_lo, axis=1), MIN_VOLUME_M3)
    for i, box in enumerate(last_boxes):
        if box is None:
            continue
        inter = np.prod(np.clip(np.minimum(t_hi, box[1]) - np.maximum(t_lo, box[0]), 0.0, None), axis=1)
        held[i, cut] = inter >= HELD_SHARE * volume
    return held


def last_box(track: Track) -> tuple[FloatArray, FloatArray] | None:
    """The (lower, upper) corners of an unnamed track's last blob; None for a named track (it
    keeps its parts) or one without blobs."""
    if track.class_name != UNKNOWN or not track.seen.lower_m:
        return None
    return track.seen.lower_m[-1], track.seen.upper_m[-1]
