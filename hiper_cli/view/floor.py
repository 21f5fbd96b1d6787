"""Grids to lay on the floor: heatmaps that ``hiper analyze`` stored, and an environment's map.

Read from analysis documents of a kind in ``FLOOR_KINDS`` (the newest per kind and class whose
window meets the view's) and from each environment's ``data["map"]``. Each needs a cell size
(``resolution_m`` or ``cell_m``), the map-frame (x, y) of the outer corner of cell [0, 0]
(``origin_m``; row i runs along +y, column j along +x) and the cells, in the first form found:

1. a 2-D array under one of ``GRID_KEYS``;
2. ``cells``: base64 of zlib-compressed int8 rows, bottom-up, ``width`` × ``height`` (the
   occupancy map ``hiper analyze`` keeps: -1 unknown, 0 free, 100 occupied);
3. ``files``: a written mask (``keepout_pgm``, ``pgm``, ``npy``): a map_server raw PGM (row 0 at
   the top, 255 unknown) or a .npy array (bottom-up), read when the file still exists.

Anything else is skipped, so a KB without analyses, or with analyses of another shape, still
views (docs/view.md). ``FloorImage.rgba()`` gives the one colour image both renderers draw.
"""

from __future__ import annotations

import base64
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from hiper_cli.view.window import TimeWindow

__all__ = ["FLOOR_KINDS", "GRID_KEYS", "FloorImage", "floor_images"]

FLOOR_KINDS = ("heatmap", "map", "occupancy", "costmap")
GRID_KEYS = ("grid", "image", "heat", "heatmap", "density", "counts", "probability", "cost")
_FILE_KEYS = ("keepout_pgm", "pgm", "npy")


@dataclass(frozen=True)
class FloorImage:
    """A (H, W) float64 grid on the floor: cell [i, j] covers x in origin_x + j·res, y in
    origin_y + i·res. ``name`` is its entity under ``/map`` (``heatmap/person``, ``occupancy``).
    Occupancy grids hold -1 (unknown), 0 (free) .. 100 (occupied); NaN is unknown in any grid."""

    name: str
    kind: str
    class_name: str
    grid: NDArray[np.float64]
    resolution_m: float
    origin_m: tuple[float, float]

    @property
    def extent_m(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) in the map frame."""
        h, w = self.grid.shape
        x0, y0 = self.origin_m
        return x0, x0 + w * self.resolution_m, y0, y0 + h * self.resolution_m

    def normalised(self) -> NDArray[np.float64]:
        """The grid scaled to [0, 1] over its known cells (unknown ones as 0)."""
        g = np.where(self._known(), np.nan_to_num(self.grid), 0.0)
        lo, hi = float(g.min()), float(g.max())
        return (g - lo) / (hi - lo) if hi > lo else np.zeros_like(g)

    def _known(self) -> NDArray[np.bool_]:
        known = np.isfinite(self.grid)
        return known & (self.grid >= 0) if self.kind == "occupancy" else known

    def rgba(self) -> NDArray[np.uint8]:
        """(H, W, 4) colours, row 0 at ``origin_m``: occupancy grey where occupied, faint where
        free, clear where unknown; other grids in the turbo colour map, more opaque where higher
        and clear below 3 % of their range (so a heatmap's long faint tails do not hide the map)."""
        import cv2

        known = self._known()
        if self.kind == "occupancy":
            occ = np.clip(np.nan_to_num(self.grid) / 100.0, 0.0, 1.0)
            gray = (240 - 150 * occ).astype(np.uint8)
            alpha = np.where(known, np.where(occ > 0.5, 140, 40), 0).astype(np.uint8)
            return np.dstack([gray, gray, gray, alpha])
        norm = self.normalised()
        values = (norm * 255).astype(np.uint8)
        rgb = cv2.applyColorMap(values, cv2.COLORMAP_TURBO)[:, :, ::-1]
        alpha = np.where(known & (norm >= 0.03), 60 + 160 * norm, 0).astype(np.uint8)
        return np.dstack([rgb, alpha])


def _cells(values: dict[str, Any]) -> NDArray[np.float64] | None:
    """The cells of ``values`` in one of the three forms of the module docstring, bottom-up."""
    raw = next((values[k] for k in GRID_KEYS if k in values), None)
    if raw is not None:
        return np.asarray(raw, dtype=np.float64)
    if isinstance(values.get("cells"), str) and "width" in values and "height" in values:
        data = zlib.decompress(base64.b64decode(values["cells"]))
        cells = np.frombuffer(data, dtype=np.int8).reshape(int(values["height"]), int(values["width"]))
        return cells.astype(np.float64)
    files: dict[str, Any] = values["files"] if isinstance(values.get("files"), dict) else {}
    for key in _FILE_KEYS:
        path = Path(str(files.get(key, "")))
        if not files.get(key) or not path.is_file():
            continue
        if path.suffix == ".npy":
            return np.asarray(np.load(path), dtype=np.float64)
        import cv2

        image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        if image is not None and image.ndim == 2:
            grid = np.flipud(image).astype(np.float64)  # map_server: row 0 is the top of the map
            grid[grid == 255] = np.nan
            return grid
    return None


def _grid(values: dict[str, Any], name: str, kind: str, class_name: str) -> FloorImage | None:
    res = values.get("resolution_m", values.get("cell_m"))
    origin = values.get("origin_m")
    if res is None or origin is None:
        return None
    try:
        grid = _cells(values)
        res_m = float(res)
        x0, y0 = (float(v) for v in list(origin)[:2])
    except (TypeError, ValueError, zlib.error, OSError):
        return None
    if grid is None or grid.ndim != 2 or grid.size == 0 or not res_m > 0:
        return None
    return FloorImage(name, kind, class_name, grid, res_m, (x0, y0))


def floor_images(
    analyses: Sequence[dict[str, Any]], environments: Sequence[dict[str, Any]], window: TimeWindow
) -> tuple[FloorImage, ...]:
    """The newest grid per (kind, class) among analysis documents overlapping ``window``, then
    each environment's map."""
    newest: dict[tuple[str, str], dict[str, Any]] = {}
    for doc in analyses:
        kind, cls = str(doc.get("kind", "")), str(doc.get("class", ""))
        if kind not in FLOOR_KINDS or not isinstance(doc.get("values"), dict):
            continue
        if not window.overlaps(float(doc.get("t_start_s", 0.0)), float(doc.get("t_end_s", 0.0))):
            continue
        if (kind, cls) not in newest or doc.get("created_s", 0) >= newest[(kind, cls)].get("created_s", 0):
            newest[(kind, cls)] = doc
    out = []
    for (kind, cls), doc in sorted(newest.items()):
        image = _grid(doc["values"], f"{kind}/{cls}" if cls else kind, kind, cls)
        if image is not None:
            out.append(image)
    for k, data in enumerate(environments):
        if isinstance(data.get("map"), dict):
            image = _grid(data["map"], "occupancy" if k == 0 else f"occupancy_{k}", "occupancy", "")
            if image is not None:
                out.append(image)
    return tuple(out)
