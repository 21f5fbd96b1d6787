"""Appearance of a blob: a hue-saturation histogram of its pixels, to tell people apart.

A walker lost for longer than a few seconds (behind shelves, out of view while the robot turns)
can be anywhere within a walk of it; where the walker was no longer tells whether a new track
is the same person, the colours of the clothes still do. Hue and saturation, not brightness:
the light on a person changes with the distance and the angle to it. Dark and grey pixels
(saturation or value low) carry no hue and share one bin per brightness third.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

__all__ = ["HISTOGRAM_BINS", "histogram", "similarity"]

FloatArray = NDArray[np.float64]
HUE_BINS, SAT_BINS = 12, 3
GREY_BINS = 3  # achromatic pixels by value: dark, mid, light
HISTOGRAM_BINS = HUE_BINS * SAT_BINS + GREY_BINS
MIN_SATURATION = 40  # of 255: below this a pixel's hue is noise
MIN_VALUE = 40  # of 255: ... and below this too
MIN_PIXELS = 20  # fewer pixels give no histogram


def histogram(rgb: NDArray[np.uint8], pixels_uv: NDArray[np.int32]) -> FloatArray | None:
    """The normalised histogram (``HISTOGRAM_BINS``) of the colours at ``pixels_uv`` (u, v) of
    an RGB image, or None for fewer than ``MIN_PIXELS`` pixels."""
    if len(pixels_uv) < MIN_PIXELS:
        return None
    colours = rgb[pixels_uv[:, 1], pixels_uv[:, 0]].reshape(-1, 1, 3)
    hsv = cv2.cvtColor(colours, cv2.COLOR_RGB2HSV).reshape(-1, 3).astype(np.int64)
    h, s, v = hsv[:, 0], hsv[:, 1], hsv[:, 2]
    chromatic = (s >= MIN_SATURATION) & (v >= MIN_VALUE)
    hue_bin = np.minimum(h * HUE_BINS // 180, HUE_BINS - 1)
    sat_bin = np.minimum((s - MIN_SATURATION) * SAT_BINS // (256 - MIN_SATURATION), SAT_BINS - 1)
    grey_bin = HUE_BINS * SAT_BINS + np.minimum(v * GREY_BINS // 256, GREY_BINS - 1)
    bins = np.where(chromatic, hue_bin * SAT_BINS + np.maximum(sat_bin, 0), grey_bin)
    counts = np.bincount(bins, minlength=HISTOGRAM_BINS).astype(np.float64)
    return np.asarray(counts / counts.sum(), dtype=np.float64)


def similarity(a: FloatArray, b: FloatArray) -> float:
    """The Bhattacharyya coefficient of two histograms (normalised here): 1 for the same
    colours, 0 for none in common."""
    sa, sb = float(a.sum()), float(b.sum())
    if sa <= 0 or sb <= 0:
        return 0.0
    return float(np.sqrt(a / sa * (b / sb)).sum())
