"""Whether a blob shows a whole, solid object (evidence for an ``unknown`` instance).

An unmatched blob is a lasting object only if the camera saw all of it: a blob touching the
image's edge is cut there (a shelf, a wall or a floor remnant seen through the border), one
longer than ``unknown_max_extent_m`` is structure or several things, and a flat one (its
points within a centimetre or two of one plane, beyond the depth noise) is a piece of a
surface the background did not claim: a wall, a floor, a furniture side.
"""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.types import CameraIntrinsics

__all__ = ["seen_whole", "thickness_m"]


def thickness_m(points: np.ndarray) -> float:
    """The spread (σ, m) of ``points`` (N, 3) along their thinnest direction."""
    if len(points) < 4:
        return 0.0
    centred = points - points.mean(axis=0)
    cov = centred.T @ centred / len(points)
    return float(np.sqrt(max(float(np.linalg.eigvalsh(cov)[0]), 0.0)))


def seen_whole(blob: Blob, config: ForegroundConfig, camera: CameraIntrinsics) -> bool:
    """Whether ``blob`` lies inside the image, is compact and is not flat."""
    x0, y0, x1, y1 = (float(v) for v in blob.image_box_xyxy)
    edge = config.pixel_step
    if x0 <= edge or y0 <= edge or x1 >= camera.width - edge or y1 >= camera.height - edge:
        return False
    if float(np.max(blob.extent_map_m)) > config.unknown_max_extent_m:
        return False
    depth = float(np.median(blob.points_cam[:, 2]))
    flat_m = config.unknown_min_thickness_m + config.background_margin_per_m2 * depth * depth
    return thickness_m(blob.points_cam) >= flat_m
