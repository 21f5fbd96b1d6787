"""The spatial map layer: a 2D occupancy grid per environment (ROS ``nav_msgs/OccupancyGrid``
values: -1 unknown, 0 free, 100 occupied; intermediate values are costs).

Built from the background (floors free, walls, tables and other structure occupied) and the
observed trajectories (where something walked is free), or loaded from a ROS map_server YAML
and its image with map_server's rules (``mode`` trinary/scale/raw, ``negate``,
``occupied_thresh``, ``free_thresh``; image row 0 is the top of the map, i.e. the largest y).
Cells are stored bottom-up: ``cells[iy, ix]`` covers x = origin_x + (ix + ½)·resolution.
"""

from __future__ import annotations

import base64
import math
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError, DataError
from hiper_cli.files import output_folder

__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "OccupancyGrid", "read_map_server", "write_map_server"]

UNKNOWN, FREE, OCCUPIED = -1, 0, 100
MODES = ("trinary", "scale", "raw")


@dataclass(frozen=True)
class OccupancyGrid:
    """``cells`` (H, W) int8 in [-1, 100], row 0 at ``origin_xy_m`` y; square cells of
    ``resolution_m``; map frame, yaw 0."""

    cells: NDArray[np.int8]
    resolution_m: float
    origin_xy_m: tuple[float, float]

    def __post_init__(self) -> None:
        c = np.asarray(self.cells)
        if c.ndim != 2 or c.dtype != np.int8 or c.size == 0:
            raise DataError(f"occupancy grid: expected (H, W) int8 cells, got {c.shape} {c.dtype}")
        if not self.resolution_m > 0:
            raise DataError(f"occupancy grid: resolution must be positive, got {self.resolution_m}")

    @property
    def shape(self) -> tuple[int, int]:
        return int(self.cells.shape[0]), int(self.cells.shape[1])

    def cell_of(
        self, xy_m: NDArray[np.float64]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
        """(iy, ix, inside) of (N, 2) map points."""
        p = np.asarray(xy_m, dtype=np.float64).reshape(-1, 2)
        ix = np.floor((p[:, 0] - self.origin_xy_m[0]) / self.resolution_m).astype(np.int64)
        iy = np.floor((p[:, 1] - self.origin_xy_m[1]) / self.resolution_m).astype(np.int64)
        h, w = self.shape
        return iy, ix, (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)

    def to_dict(self) -> dict[str, Any]:
        """The form stored in the environment document (cells zlib-compressed, base64)."""
        h, w = self.shape
        return {
            "resolution_m": self.resolution_m,
            "origin_m": [self.origin_xy_m[0], self.origin_xy_m[1], 0.0],
            "width": w,
            "height": h,
            "encoding": "int8 rows bottom-up, zlib, base64",
            "cells": base64.b64encode(zlib.compress(self.cells.tobytes(), 6)).decode("ascii"),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> OccupancyGrid:
        raw = zlib.decompress(base64.b64decode(d["cells"]))
        cells = np.frombuffer(raw, dtype=np.int8).reshape(int(d["height"]), int(d["width"])).copy()
        return cls(cells, float(d["resolution_m"]), (float(d["origin_m"][0]), float(d["origin_m"][1])))


def _parse_yaml(path: Path) -> dict[str, Any]:
    """The flat ``key: value`` YAML map_server writes (no nesting but the origin list)."""
    out: dict[str, Any] = {}
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if not line or ":" not in line:
            continue
        key, value = (s.strip() for s in line.split(":", 1))
        value = value.strip("'\"")
        if value.startswith("["):
            out[key] = [float(v) for v in value.strip("[]").split(",")]
        else:
            out[key] = value
    return out


def read_map_server(yaml_path: str | Path) -> OccupancyGrid:
    """A map_server map (YAML + PGM/PNG image) as an occupancy grid, with map_server's rules:
    trinary: occ > occupied_thresh → 100, occ < free_thresh → 0, else -1; scale: in between
    linearly 0-99 (transparent → -1); raw: the pixel value itself, 101-255 → -1 (``negate``
    is ignored in raw mode). occ = (255 - pixel) / 255, or pixel / 255 with ``negate``."""
    import cv2

    path = Path(yaml_path)
    if not path.exists():
        raise ConfigError(f"{path}: map YAML not found; pass a map_server map, e.g. --map maps/floor.yaml")
    meta = _parse_yaml(path)
    try:
        image_path = path.parent / str(meta["image"])
        resolution = float(meta["resolution"])
        origin = meta.get("origin", [0.0, 0.0, 0.0])
        negate = int(float(meta.get("negate", 0)))
        occ_t = float(meta.get("occupied_thresh", 0.65))
        free_t = float(meta.get("free_thresh", 0.196))
        mode = str(meta.get("mode", "trinary"))
    except (KeyError, ValueError) as err:
        raise ConfigError(f"{path}: not a map_server YAML ({err}); it needs image and resolution") from err
    if mode not in MODES:
        raise ConfigError(f"{path}: mode {mode!r}; expected one of {', '.join(MODES)}")
    if len(origin) >= 3 and abs(float(origin[2])) > 1e-9:
        raise ConfigError(f"{path}: origin yaw {origin[2]} is not supported; rotate the image to yaw 0")
    img = cv2.imread(str(image_path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ConfigError(f"{image_path}: cannot read the map image named in {path.name}")
    alpha = None
    if img.ndim == 3:
        if img.shape[2] == 4:
            alpha = img[:, :, 3]
        img = img[:, :, :3].mean(axis=2)
    pixel = np.asarray(img, dtype=np.float64)
    if mode == "raw":
        value = np.rint(pixel)
        cells = np.where(value <= 100, value, UNKNOWN)
    else:
        shade = pixel / 255.0
        occ = shade if negate else 1.0 - shade
        cells = np.full(pixel.shape, UNKNOWN, dtype=np.float64)
        cells[occ > occ_t] = OCCUPIED
        cells[occ < free_t] = FREE
        if mode == "scale":
            mid = (occ >= free_t) & (occ <= occ_t)
            cells[mid] = np.rint((occ[mid] - free_t) / (occ_t - free_t) * 100.0)
            if alpha is not None:
                cells[alpha != 255] = UNKNOWN
    grid = np.flipud(cells).astype(np.int8)
    return OccupancyGrid(grid, resolution, (float(origin[0]), float(origin[1])))


def write_map_server(
    grid: OccupancyGrid,
    yaml_path: str | Path,
    *,
    mode: str = "trinary",
    image: NDArray[np.uint8] | None = None,
) -> tuple[Path, Path]:
    """Write ``grid`` as map_server YAML + PGM beside it; returns (yaml, pgm).

    trinary: occupied black (0), free white (254), unknown grey (205), thresholds 0.65/0.196;
    raw: the cell values as pixels, unknown 255 (costmap-filter masks). ``image`` replaces the
    pixels (bottom-up, like ``cells``)."""
    import cv2

    if mode not in ("trinary", "raw"):
        raise ConfigError(f"map mode {mode!r}; expected trinary or raw")
    yaml_p = Path(yaml_path)
    pgm = yaml_p.with_suffix(".pgm")
    if yaml_p.suffix.lower() not in (".yaml", ".yml"):
        raise ConfigError(f"{yaml_p}: a map is written as map_server YAML; pass a .yaml path (PGM beside it)")
    output_folder(yaml_p.parent)
    if image is None:
        c = grid.cells
        if mode == "raw":
            image = np.where(c < 0, 255, c).astype(np.uint8)
        else:
            image = np.full(c.shape, 205, dtype=np.uint8)
            image[c == FREE] = 254
            image[c >= 65] = 0
    if not cv2.imwrite(str(pgm), np.flipud(image)):
        raise ConfigError(f"{pgm}: cannot write the map image; check the folder is writable")
    ox, oy = grid.origin_xy_m
    yaml_p.write_text(
        f"image: {pgm.name}\n"
        f"mode: {mode}\n"
        f"resolution: {grid.resolution_m:.6g}\n"
        f"origin: [{ox:.6g}, {oy:.6g}, 0.0]\n"
        "negate: 0\n"
        "occupied_thresh: 0.65\n"
        "free_thresh: 0.196\n"
    )
    return yaml_p, pgm


def grid_bounds(
    points_xy: NDArray[np.float64], resolution_m: float, pad_m: float
) -> tuple[tuple[float, float], tuple[int, int]]:
    """(origin, (H, W)) of a grid covering ``points_xy`` (N, 2) with ``pad_m`` around, on a
    lattice of ``resolution_m`` (the origin a multiple of it)."""
    lo = np.floor((points_xy.min(axis=0) - pad_m) / resolution_m) * resolution_m
    hi = points_xy.max(axis=0) + pad_m
    w = max(1, math.ceil((hi[0] - lo[0]) / resolution_m))
    h = max(1, math.ceil((hi[1] - lo[1]) / resolution_m))
    return (float(lo[0]), float(lo[1])), (h, w)
