"""Seeing a known surface again: a background instance's ``last_seen`` follows the camera.

Plane observations alone (Algorithm 2) move an instance's ``last_seen_s`` only when one merges
into it. A table seen again at 4.6 m, across a room at a grazing angle, or a wall piece half
hidden by furniture forms no plane segment, so "was there a table in the last 15 seconds"
would answer no while the table is in view. Each keyframe, the depth samples (every
``sighting_stride_px``-th pixel, map frame) that lie on a known instance, inside its box grown by
the inlier distance (``inlier_m`` times the depth, as the plane segmentation uses), are counted;
an instance with samples for ``sighting_min_pixels`` pixels of the image (the truth detector's
400 of 640×480, scaled to the image) is seen in this keyframe. Its ``last_seen_s`` moves; its
observations, box and plane do not: a sighting is no observation.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

import numpy as np

from hiper_cli.model import Instance
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.planes import sample_grid
from hiper_cli.types import Frame

__all__ = ["sighted"]

REFERENCE_PIXELS = 640 * 480  # ``sighting_min_pixels`` is given for this image size


def sighted(frame: Frame, instances: Iterable[Instance], cfg: BackgroundConfig) -> list[Instance]:
    """Copies of ``instances`` seen in ``frame`` (see the module doc), with ``last_seen_s`` at
    the frame's stamp; only those last seen ``sighting_refresh_s`` or more before it are tested
    (each sighting rewrites the instance in the knowledge base)."""
    todo = [i for i in instances if frame.stamp_s - i.last_seen_s >= cfg.sighting_refresh_s]
    if not todo or cfg.sighting_min_pixels <= 0:
        return []
    stride = cfg.sighting_stride_px
    grid = sample_grid(frame.depth_m, frame.camera, stride, cfg.min_depth_m, cfg.max_depth_m)
    cam = grid.points_cam[grid.valid]
    if len(cam) == 0:
        return []
    T = np.asarray(frame.T_map_cam, dtype=np.float64)
    points, z = cam @ T[:3, :3].T + T[:3, 3], cam[:, 2]
    h, w = frame.depth_m.shape[:2]
    min_samples = max(1, round(cfg.sighting_min_pixels * (h * w) / REFERENCE_PIXELS / (stride * stride)))
    margin = cfg.inlier_m * np.maximum(z, 1.0)
    lo_all, hi_all = points.min(axis=0), points.max(axis=0)
    out = []
    for inst in todo:
        box = inst.box
        lo, hi = box.aabb()
        if np.any(lo - margin.max() > hi_all) or np.any(hi + margin.max() < lo_all):
            continue  # out of this view
        local = np.abs((points - box.center_m) @ box.R) - box.extent_m / 2.0
        inside = np.all(local <= margin[:, None], axis=1)
        if int(inside.sum()) >= min_samples:
            out.append(dataclasses.replace(inst, last_seen_s=frame.stamp_s))
    return out
