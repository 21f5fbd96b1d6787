"""How the view names and colours things: entity paths that mirror the KB's layers, and colours.

Entity paths (documented in docs/view.md) are built here only, so the Rerun recording, the
top-down picture and the tests agree: ``/background/<class>/<uuid>``,
``/foreground/<class>/<uuid>``, ``/robot/...``, ``/map/...``. Colours are RGB uint8; a class
without a fixed colour gets a stable one from its name, so a class keeps its colour everywhere.
"""

from __future__ import annotations

import colorsys
import hashlib

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CAMERA_PATH",
    "IMAGE_PATH",
    "ROBOT_PATH",
    "class_color",
    "entity_path",
    "speed_colors",
]

ROBOT_PATH = "/robot/path"
CAMERA_PATH = "/robot/camera"
IMAGE_PATH = "/robot/camera/image"

# Classes the scenes hold most, in colours a reader tells apart at a glance.
_FIXED: dict[str, tuple[int, int, int]] = {
    "wall": (120, 130, 150),
    "floor": (205, 190, 160),
    "ceiling": (170, 200, 220),
    "table": (150, 100, 60),
    "person": (220, 40, 40),
    "chair": (30, 150, 60),
    "couch": (120, 60, 160),
    "bed": (70, 110, 200),
    "unknown": (150, 150, 150),
}

# Speed colour ramp: blue (still) to green to red (at or above SPEED_RED_MPS).
SPEED_RED_MPS = 1.5


def class_color(class_name: str) -> tuple[int, int, int]:
    """The RGB colour of a class (fixed for common classes, else stable from the name)."""
    if class_name in _FIXED:
        return _FIXED[class_name]
    hue = int.from_bytes(hashlib.blake2b(class_name.encode(), digest_size=2).digest(), "big") / 65535
    r, g, b = colorsys.hsv_to_rgb(hue, 0.75, 0.85)
    return int(r * 255), int(g * 255), int(b * 255)


def speed_colors(speed_mps: NDArray[np.float64]) -> NDArray[np.uint8]:
    """(N, 3) uint8 RGB for (N,) speeds in m/s: blue at rest, green at half, red from 1.5 m/s."""
    s = np.clip(np.asarray(speed_mps, dtype=np.float64) / SPEED_RED_MPS, 0.0, 1.0)
    r = np.clip(2.0 * s - 1.0, 0.0, 1.0)
    g = 1.0 - np.abs(2.0 * s - 1.0)
    b = np.clip(1.0 - 2.0 * s, 0.0, 1.0)
    return (np.stack([r, g, b], axis=1) * 255).astype(np.uint8)


def _part(text: str) -> str:
    """One entity-path part: letters, digits, '-' and '_' (a class like 'potted plant' -> 'potted_plant')."""
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in text) or "_"


def entity_path(layer: str, class_name: str, uuid: str, *child: str) -> str:
    """``/<layer>/<class>/<uuid>[/child...]``, the path of an instance (and its parts)."""
    return "/" + "/".join(_part(p) for p in (layer, class_name, uuid, *child))
