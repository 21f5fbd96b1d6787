"""C5, the basic model: 2D detector boxes projected into 3D with the SLAM pose, no range limit.

Each box's distance is the median valid depth inside its central half; where the depth has no
value (beyond the sensor's range), the distance follows from the box's pixel height and the
class's typical height (``TYPICAL_HEIGHT_M``), so a 2D detection localises at any range. There is
no tracking and no background: a projected box joins the nearest earlier detection of its class
within ``merge_m`` (a naive instance), else it starts a new one.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from hiper_cli.types import Detections, Frame

__all__ = ["TYPICAL_HEIGHT_M", "BaselineInstance", "BaselineRun", "project_box", "project_detections"]

TYPICAL_HEIGHT_M = {"person": 1.75, "bottle": 0.25, "cup": 0.1, "chair": 0.9, "tv": 0.6}
_DEFAULT_HEIGHT_M = 0.8


@dataclass
class BaselineInstance:
    """A naive instance: class, positions over time (map frame) and the boxes behind them."""

    class_name: str
    positions_m: list[NDArray[np.float64]] = field(default_factory=list)
    stamps_s: list[float] = field(default_factory=list)
    frames: list[int] = field(default_factory=list)
    boxes: list[NDArray[np.float64]] = field(default_factory=list)

    @property
    def center_m(self) -> NDArray[np.float64]:
        return np.asarray(self.positions_m[-1])


@dataclass
class BaselineRun:
    """All naive instances of a log and the per-frame projection times."""

    instances: list[BaselineInstance] = field(default_factory=list)
    times_s: list[float] = field(default_factory=list)
    observations: int = 0


def project_box(frame: Frame, xyxy: NDArray[np.float64], class_name: str) -> NDArray[np.float64] | None:
    """The map point (3,) a box stands for, or ``None`` for a degenerate box."""
    cam = frame.camera
    x0, y0, x1, y1 = (float(v) for v in xyxy)
    if x1 - x0 < 1 or y1 - y0 < 1:
        return None
    qx, qy = (x1 - x0) / 4, (y1 - y0) / 4
    u0, u1 = int(max(0, x0 + qx)), int(min(cam.width, x1 - qx + 1))
    v0, v1 = int(max(0, y0 + qy)), int(min(cam.height, y1 - qy + 1))
    patch = frame.depth_m[v0:v1, u0:u1]
    valid = patch[patch > 0]
    if valid.size:
        z = float(np.median(valid))
    else:  # no depth: from the pixel height and the class's typical height
        z = cam.fy * TYPICAL_HEIGHT_M.get(class_name, _DEFAULT_HEIGHT_M) / (y1 - y0)
    u, v = (x0 + x1) / 2, (y0 + y1) / 2
    p_cam = np.array([(u - cam.cx) * z / cam.fx, (v - cam.cy) * z / cam.fy, z])
    return np.asarray(frame.T_map_cam[:3, :3] @ p_cam + frame.T_map_cam[:3, 3], dtype=np.float64)


def project_detections(
    frames: Iterable[tuple[Frame, Detections]], merge_m: float = 0.5
) -> BaselineRun:
    """Project every detection of every frame and merge them into naive instances."""
    run = BaselineRun()
    for k, (frame, dets) in enumerate(frames):
        start = time.perf_counter()
        for xyxy, name in zip(dets.xyxy, dets.class_names, strict=True):
            p = project_box(frame, xyxy, name)
            if p is None:
                continue
            run.observations += 1
            near = [
                (float(np.linalg.norm(i.center_m - p)), i) for i in run.instances if i.class_name == name
            ]
            best = min(near, key=lambda t: t[0], default=None)
            inst = best[1] if best is not None and best[0] <= merge_m else None
            if inst is None:
                inst = BaselineInstance(name)
                run.instances.append(inst)
            inst.positions_m.append(p)
            inst.stamps_s.append(frame.stamp_s)
            inst.frames.append(k)
            inst.boxes.append(np.asarray(xyxy, dtype=np.float64))
        run.times_s.append(time.perf_counter() - start)
    return run
