"""The map layer of an environment: its occupancy grid, built from the knowledge base or loaded
from a map_server map, kept in the environment document (``data["map"]``).

From the knowledge base: every background instance's map-frame footprint is rasterised, floors
as free, ceilings skipped, walls, tables and other structure as occupied (drawn after the
floors, so a wall on the floor stays a wall); the cells of every foreground trajectory row are
free (something walked there), unless a wall is there.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.analyze.gridmap import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    OccupancyGrid,
    grid_bounds,
    read_map_server,
    write_map_server,
)
from hiper_cli.errors import ConfigError
from hiper_cli.graph.columns import InstanceColumns
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.model import Environment

__all__ = ["MapConfig", "build_map", "environment_of", "export_map", "load_map", "map_for", "store_map"]

FREE_CLASSES = ("floor",)
SKIPPED_CLASSES = ("ceiling",)
KB_SOURCE = "knowledge base"
BUILD_RULES = 2  # part of a built map's key: a change of the rules below rebuilds stored maps


@dataclass(frozen=True)
class MapConfig:
    resolution_m: float = 0.05
    """Cell size (nav2's default map resolution)."""
    pad_m: float = 0.5
    """Free margin around what the knowledge base holds."""
    min_obstacle_height_m: float = 0.1
    """Background boxes lower than this above the floor do not block (a rug, a floor patch)."""

    def __post_init__(self) -> None:
        if self.resolution_m <= 0 or self.pad_m < 0:
            raise ConfigError(
                f"map: need resolution_m > 0 and pad_m >= 0, got {self.resolution_m}, {self.pad_m}"
            )


def _fill(cells: np.ndarray, grid: OccupancyGrid, inst: InstanceColumns, k: int, value: int) -> None:
    lo = inst.center_map_m[k, :2] - inst.half_aabb_m[k, :2]
    hi = inst.center_map_m[k, :2] + inst.half_aabb_m[k, :2]
    (iy0, iy1), (ix0, ix1), _ = grid.cell_of(np.array([lo, hi]))
    h, w = cells.shape
    cells[max(iy0, 0) : min(iy1 + 1, h), max(ix0, 0) : min(ix1 + 1, w)] = value


def build_map(kb: KnowledgeBase, config: MapConfig | None = None) -> OccupancyGrid:
    """The occupancy grid of everything the knowledge base holds (see the module doc)."""
    config = config or MapConfig()
    background = kb.instance_columns(layer="background")
    tracks = kb.trajectory_columns()
    xy = [tracks.rows[:, 1:3]]
    for k in range(len(background.uuids)):
        if background.class_names[k] in SKIPPED_CLASSES:
            continue
        half = background.half_aabb_m[k, :2]
        xy.append(np.array([background.center_map_m[k, :2] - half, background.center_map_m[k, :2] + half]))
    points = np.concatenate(xy) if xy else np.zeros((0, 2))
    if len(points) == 0:
        raise ConfigError(
            f"{kb.location}: no background and no trajectories to build a map from; "
            "run 'hiper perceive LOG' first or pass --map map.yaml"
        )
    origin, (h, w) = grid_bounds(points, config.resolution_m, config.pad_m)
    cells = np.full((h, w), UNKNOWN, dtype=np.int8)
    grid = OccupancyGrid(cells, config.resolution_m, origin)
    for k in range(len(background.uuids)):
        if background.class_names[k] in FREE_CLASSES:
            _fill(cells, grid, background, k, FREE)
    iy, ix, inside = grid.cell_of(tracks.rows[:, 1:3])
    cells[iy[inside], ix[inside]] = FREE
    floor_z = min(
        (
            float(background.center_map_m[k, 2] + background.half_aabb_m[k, 2])
            for k in range(len(background.uuids))
            if background.class_names[k] in FREE_CLASSES
        ),
        default=0.0,
    )
    for k in range(len(background.uuids)):
        name = background.class_names[k]
        if name in FREE_CLASSES or name in SKIPPED_CLASSES:
            continue
        top = background.center_map_m[k, 2] + background.half_aabb_m[k, 2]
        if top - floor_z >= config.min_obstacle_height_m:
            _fill(cells, grid, background, k, OCCUPIED)
    return grid


def environment_of(kb: KnowledgeBase, name: str | None = None) -> Environment:
    """The environment called ``name``, or the only one; a ``ConfigError`` lists them otherwise."""
    envs = kb.environments()
    if name is not None:
        found = [e for e in envs if e.name == name]
        if found:
            return found[0]
    elif len(envs) == 1:
        return envs[0]
    names = ", ".join(e.name for e in envs) or "none"
    what = f"environment {name!r} not found" if name else "several environments"
    raise ConfigError(f"{kb.location}: {what}; pass --env with one of: {names}")


def store_map(
    kb: KnowledgeBase,
    env: Environment,
    grid: OccupancyGrid,
    source: str,
    built_from: list[float] | None = None,
) -> Environment:
    """Keep ``grid`` as the map of ``env`` (its document's ``data["map"]``)."""
    env.data["map"] = grid.to_dict() | {"source": source, "built_from": built_from}
    kb.store_environment(env)
    return env


def load_map(env: Environment) -> OccupancyGrid | None:
    """The stored map of ``env``, if it has one."""
    stored = env.data.get("map")
    return OccupancyGrid.from_dict(stored) if isinstance(stored, dict) and "cells" in stored else None


def map_for(
    kb: KnowledgeBase,
    env: Environment,
    map_yaml: str | None = None,
    config: MapConfig | None = None,
    *,
    store: bool = True,
) -> OccupancyGrid:
    """The map to draw on: ``map_yaml`` when given (then stored as the environment's map), else
    a map loaded that way before, else the map built from the knowledge base, rebuilt (and
    stored) when perception has added or changed instances since. ``store=False`` leaves the
    knowledge base as it is (a read-only caller)."""
    if map_yaml is not None:
        grid = read_map_server(map_yaml)
        if store:
            store_map(kb, env, grid, str(map_yaml))
        return grid
    stored = load_map(env)
    meta = env.data.get("map") or {}
    if stored is not None and meta.get("source") != KB_SOURCE:
        return stored
    key = _content_key(kb)
    if (
        stored is not None
        and meta.get("built_from") == key
        and (config is None or config.resolution_m == stored.resolution_m)
    ):
        return stored
    grid = build_map(kb, config)
    if store:
        store_map(kb, env, grid, KB_SOURCE, key)
    return grid


def _content_key(kb: KnowledgeBase) -> list[float]:
    """What a built map depends on, cheaply: the instance count and the newest sighting (both
    read from indexes); a new perception run changes it."""
    n, newest = kb.instance_summary()
    return [float(BUILD_RULES), float(n), float(newest or 0.0)]


def export_map(
    kb: KnowledgeBase,
    out_yaml: str | Path,
    *,
    env_name: str | None = None,
    map_yaml: str | None = None,
    resolution_m: float = 0.05,
) -> dict[str, Any]:
    """``hiper analyze map``: the environment's map (loaded from ``map_yaml``, or built), stored
    in its document and written as map_server YAML + PGM; returns a summary."""
    env = environment_of(kb, env_name)
    grid = map_for(kb, env, map_yaml, MapConfig(resolution_m=resolution_m))
    yaml_p, pgm = write_map_server(grid, out_yaml)
    c = grid.cells
    return {
        "environment": env.name,
        "source": env.data["map"]["source"],
        "yaml": str(yaml_p),
        "pgm": str(pgm),
        "resolution_m": grid.resolution_m,
        "origin_m": [*grid.origin_xy_m, 0.0],
        "shape": list(grid.shape),
        "free_cells": int(np.count_nonzero(c == FREE)),
        "occupied_cells": int(np.count_nonzero(c >= 65)),
        "unknown_cells": int(np.count_nonzero(c == UNKNOWN)),
    }
