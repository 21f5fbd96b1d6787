"""Two pieces of one table, cut apart by a chair in front of it, are one table.

A chair between the camera and a table the background layer has not mapped hides a band of
the table's top: ``tables.py`` then finds two tops in one frame, each with its legs, and each
becomes a table of its own. What tells one table with its middle hidden from two tables with
floor between them is the band itself: seen from the camera, the top's height between the
two pieces is hidden behind something nearer (the chair), where between two tables the camera
would see past that height to the floor or the wall behind.

Two pieces of one frame are joined (``join_hidden_pieces``) when their tops lie at one height
(within ``TOP_HEIGHT_TOLERANCE_M``), they face each other across at most
``table_pieces_max_gap_m`` or touch (their footprints overlap along the other axis by half
the narrower one), the joined table is at most ``table_pieces_max_length_m`` long (two desks
side by side with a chair before the gap stay two when together they would be longer than a
table), and most of the samples of the band at the top's height (``HIDDEN_SHARE``) that the
camera's view holds are hidden.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.config import RefineConfig
from hiper_cli.perceive.foreground.segment import Blob, sub_blob

__all__ = ["HIDDEN_SHARE", "TOP_HEIGHT_TOLERANCE_M", "join_hidden_pieces"]

FloatArray = NDArray[np.float64]
Hidden = Callable[[FloatArray], tuple[NDArray[np.bool_], NDArray[np.bool_]]]

TOP_HEIGHT_TOLERANCE_M = 0.04  # two slab bins of ``tables.py``
HIDDEN_SHARE = 0.7  # of the band's samples in view that something nearer hides
TOP_QUANTILE = 95  # a piece's top: this percentile of its points' heights (legs below)
BAND_SAMPLES = 5  # per axis of the band between two pieces


def _footprint(blob: Blob) -> tuple[FloatArray, FloatArray]:
    lo, hi = np.percentile(blob.points_map[:, :2], [2, 98], axis=0)
    return lo, hi


def _band(a: Blob, b: Blob, config: RefineConfig) -> FloatArray | None:
    """Samples (K, 3) of the band at the top's height between the two pieces' footprints (none
    when the footprints touch or overlap: nothing lies between them), or None when they do not
    face each other across a gap of at most ``table_pieces_max_gap_m`` or would be longer than
    ``table_pieces_max_length_m`` joined."""
    top_a = float(np.percentile(a.points_map[:, 2], TOP_QUANTILE))
    top_b = float(np.percentile(b.points_map[:, 2], TOP_QUANTILE))
    if abs(top_a - top_b) > TOP_HEIGHT_TOLERANCE_M:
        return None
    (lo_a, hi_a), (lo_b, hi_b) = _footprint(a), _footprint(b)
    gap = np.maximum(lo_b - hi_a, lo_a - hi_b)  # per axis; negative: they overlap along it
    axis = int(np.argmax(gap))
    other = 1 - axis
    if gap[axis] > config.table_pieces_max_gap_m:
        return None
    overlap = min(hi_a[other], hi_b[other]) - max(lo_a[other], lo_b[other])
    narrower = min(hi_a[other] - lo_a[other], hi_b[other] - lo_b[other])
    if overlap < 0.5 * narrower:
        return None
    if max(hi_a[axis], hi_b[axis]) - min(lo_a[axis], lo_b[axis]) > config.table_pieces_max_length_m:
        return None
    if gap[axis] <= 0.0:
        return np.zeros((0, 3))
    start = min(hi_a[axis], hi_b[axis])
    across = np.linspace(start, start + gap[axis], BAND_SAMPLES + 2)[1:-1]
    along = np.linspace(max(lo_a[other], lo_b[other]), min(hi_a[other], hi_b[other]), BAND_SAMPLES)
    grid = np.zeros((len(across) * len(along), 3))
    grid[:, axis] = np.repeat(across, len(along))
    grid[:, other] = np.tile(along, len(across))
    grid[:, 2] = 0.5 * (top_a + top_b)
    return grid


def _hidden_between(a: Blob, b: Blob, hidden: Hidden, config: RefineConfig) -> bool:
    band = _band(a, b, config)
    if band is None:
        return False
    if len(band) == 0:
        return True  # the footprints touch at one height: one top
    in_view, behind = hidden(band)
    n_view = int(np.count_nonzero(in_view))
    return n_view >= BAND_SAMPLES and int(np.count_nonzero(behind & in_view)) >= HIDDEN_SHARE * n_view


def join_hidden_pieces(
    tables: Sequence[Blob], hidden: Hidden, config: RefineConfig, width: int, height: int
) -> list[Blob]:
    """The table blobs of one frame (``tables.split_unseen_tables``) with each pair that is one
    table hidden in its middle joined (see the module docstring). ``hidden(points_map (K, 3))``
    returns (in the camera's view, hidden behind something nearer) per point."""
    pieces = list(tables)
    if config.table_pieces_max_gap_m <= 0 or len(pieces) < 2:
        return pieces
    joined = True
    while joined:  # three pieces past two chairs join in two rounds
        joined = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                if _hidden_between(pieces[i], pieces[j], hidden, config):
                    pieces[i] = _concat(pieces[i], pieces[j], config.pixel_step, width, height)
                    del pieces[j]
                    joined = True
                    break
            if joined:
                break
    return pieces


def _concat(a: Blob, b: Blob, step: int, width: int, height: int) -> Blob:
    whole = Blob(
        np.concatenate([a.points_cam, b.points_cam]),
        np.concatenate([a.points_map, b.points_map]),
        np.concatenate([a.pixels_uv, b.pixels_uv]),
        np.zeros(4),
        a.support_z_m,
    )
    return sub_blob(whole, np.arange(len(whole.points_cam)), step, width, height)
