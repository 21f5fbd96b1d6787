"""The heatmap generator (paper VI-B, Algorithm 5).

The class's trajectory rows in the window are summed into the map's grid, each weighted by the
time it stands for (until the track's next row, at most ``max_row_dt_s``), and inflated with a
normal distribution of σ = μ_v · ``kernel_time_s`` (where the class gets to in that time; at
least ``min_kernel_sigma_m``), μ_v the class's learned mean speed. The density is scaled so its
peak is the ``occupancy_cap`` (paper: 80 %): a crowded corridor costs a planner, never blocks it.
The inverse map (``cap - heat`` on the known cells) draws a search to where the class is found.
Summing points and then convolving once equals overlaying one kernel per point (the
convolution is linear), at the cost of one filter pass instead of one kernel per row.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.analyze.gridmap import UNKNOWN, OccupancyGrid
from hiper_cli.analyze.window import TimeWindow
from hiper_cli.errors import ConfigError

__all__ = ["Heatmap", "HeatmapConfig", "heatmap_from_rows"]


@dataclass(frozen=True)
class HeatmapConfig:
    occupancy_cap: float = 0.8
    """Peak occupancy of the heat (paper: filled up to 80 %)."""
    kernel_time_s: float = 1.0
    """σ of the inflating normal distribution is the class's mean speed times this."""
    min_kernel_sigma_m: float = 0.25
    """σ at least this (a standing class, or none learned: about a body's radius)."""
    default_speed_mps: float = 0.0
    """μ_v when the class has no learned ODS and no moving rows."""
    max_row_dt_s: float = 1.0
    """A row stands for the time until its track's next row, at most this."""

    def __post_init__(self) -> None:
        if not 0.0 < self.occupancy_cap <= 1.0:
            raise ConfigError(f"heatmap: occupancy_cap must be in (0, 1], got {self.occupancy_cap}")
        if self.min_kernel_sigma_m <= 0 or self.kernel_time_s < 0 or self.max_row_dt_s <= 0:
            raise ConfigError("heatmap: kernel sizes and max_row_dt_s must be positive")


@dataclass(frozen=True)
class Heatmap:
    """``heat`` (H, W) float32 in [0, cap] on ``grid``'s cells (bottom-up); ``inverse`` the
    search map (cap - heat on known cells, 0 elsewhere)."""

    class_name: str
    window: TimeWindow
    grid: OccupancyGrid
    heat: NDArray[np.float32]
    config: HeatmapConfig
    speed_mps: float
    sigma_m: float
    rows: int
    instances: int
    seconds: float

    @property
    def inverse(self) -> NDArray[np.float32]:
        known = self.grid.cells != UNKNOWN
        return np.where(known, self.config.occupancy_cap - self.heat, 0.0).astype(np.float32)

    def summary(self) -> dict[str, Any]:
        h = self.heat
        return {
            "class": self.class_name,
            "window": self.window.to_dict(),
            "rows": self.rows,
            "instances": self.instances,
            "speed_mps": self.speed_mps,
            "kernel_sigma_m": self.sigma_m,
            "occupancy_cap": self.config.occupancy_cap,
            "resolution_m": self.grid.resolution_m,
            "origin_m": [*self.grid.origin_xy_m, 0.0],
            "shape": list(h.shape),
            "hot_cells": int(np.count_nonzero(h >= 0.5 * self.config.occupancy_cap)),
            "warm_cells": int(np.count_nonzero(h >= 0.05 * self.config.occupancy_cap)),
            "seconds": round(self.seconds, 4),
        }


def _row_weights(rows: NDArray[np.float64], track: NDArray[np.int64], max_dt_s: float) -> NDArray[np.float64]:
    """Seconds each row stands for: until the same track's next row (rows ordered by track,
    then stamp), at most ``max_dt_s``; a track's last row gets the share of the row before it."""
    n = len(rows)
    w = np.full(n, -1.0)
    if n == 0:
        return w
    same = track[1:] == track[:-1]
    w[:-1] = np.where(same, np.clip(np.diff(rows[:, 0]), 0.0, max_dt_s), -1.0)
    ends = w < 0
    before = np.concatenate([[-1.0], w[:-1]])
    w[ends] = np.where(before[ends] >= 0, before[ends], max_dt_s)
    return w


def heatmap_from_rows(
    class_name: str,
    rows: NDArray[np.float64],
    track: NDArray[np.int64],
    grid: OccupancyGrid,
    window: TimeWindow,
    speed_mps: float | None,
    config: HeatmapConfig | None = None,
) -> Heatmap:
    """Algorithm 5 over trajectory rows (M, 7) (ordered by track, then stamp) of one class."""
    import cv2

    t_start = time.perf_counter()
    config = config or HeatmapConfig()
    keep = window.mask(rows[:, 0])
    rows, track = rows[keep], track[keep]
    if speed_mps is None:
        moving = np.hypot(rows[:, 4], rows[:, 5]) if len(rows) else np.zeros(0)
        speed_mps = float(moving.mean()) if moving.size else config.default_speed_mps
    sigma_m = max(config.min_kernel_sigma_m, speed_mps * config.kernel_time_s)
    weights = _row_weights(rows, track, config.max_row_dt_s)
    iy, ix, inside = grid.cell_of(rows[:, 1:3])
    h, w = grid.shape
    cells = iy[inside] * w + ix[inside]
    flat = np.bincount(cells, weights=weights[inside], minlength=h * w).astype(np.float64)  # float if empty
    sigma_cells = sigma_m / grid.resolution_m
    k = 2 * int(np.ceil(3.0 * sigma_cells)) + 1  # the kernel to 3σ
    density = cv2.GaussianBlur(
        flat.reshape(h, w), (k, k), sigma_cells, sigmaY=sigma_cells, borderType=cv2.BORDER_CONSTANT
    )
    peak = float(density.max()) if density.size else 0.0
    heat = (density * (config.occupancy_cap / peak) if peak > 0 else np.zeros((h, w))).astype(np.float32)
    return Heatmap(
        class_name,
        window,
        grid,
        heat,
        config,
        float(speed_mps),
        float(sigma_m),
        len(rows),
        int(np.unique(track).size),
        time.perf_counter() - t_start,
    )
