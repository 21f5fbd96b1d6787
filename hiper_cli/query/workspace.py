"""The manipulation workspace (paper V-C): what a box of the map holds, for a grasp or place
planner. The static background as primitive shapes with their class (each instance's box
clipped to the workspace, with its plane when it has one) and the foreground as a voxel
occupancy grid with a class per voxel and each class's learned dynamics (the ODS analysis
where ``hiper analyze`` has run, else the instances' own state and speed)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import QueryError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.query.engine import make_context

__all__ = ["Primitive", "Workspace", "workspace"]

MAX_VOXELS = 4_000_000


@dataclass(frozen=True)
class Primitive:
    """A background instance inside the workspace: its box clipped to it (map frame, m)."""

    uuid: str
    class_name: str
    shape: str  # "plane" (a wall, floor, table top: thin box plus plane) or "box"
    center_m: tuple[float, float, float]
    extent_m: tuple[float, float, float]
    plane: tuple[float, float, float, float] | None  # a·x + b·y + c·z + d = 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "class": self.class_name,
            "shape": self.shape,
            "center_m": list(self.center_m),
            "extent_m": list(self.extent_m),
            "plane": None if self.plane is None else list(self.plane),
        }


@dataclass(frozen=True)
class Workspace:
    """``occupancy`` (nx, ny, nz) int16: -1 free, else an index into ``classes``; voxel
    (i, j, k) has its centre at ``origin_m + (i + 0.5, j + 0.5, k + 0.5) * resolution_m``."""

    center_m: tuple[float, float, float]
    size_m: tuple[float, float, float]
    resolution_m: float
    origin_m: tuple[float, float, float]
    background: tuple[Primitive, ...]
    classes: tuple[str, ...]
    occupancy: NDArray[np.int16]
    dynamics: dict[str, dict[str, Any]]
    foreground_uuids: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        occupied = np.argwhere(self.occupancy >= 0)
        return {
            "format": "hiper-workspace",
            "version": 1,
            "frame": "map",
            "center_m": list(self.center_m),
            "size_m": list(self.size_m),
            "resolution_m": self.resolution_m,
            "origin_m": list(self.origin_m),
            "shape": list(self.occupancy.shape),
            "background": [p.to_dict() for p in self.background],
            "foreground": {
                "classes": list(self.classes),
                "instance_uuids": list(self.foreground_uuids),
                "occupied": [[int(i), int(j), int(k), int(self.occupancy[i, j, k])] for i, j, k in occupied],
                "dynamics": self.dynamics,
            },
        }


def _t3(v: NDArray[np.float64]) -> tuple[float, float, float]:
    return round(float(v[0]), 4), round(float(v[1]), 4), round(float(v[2]), 4)


def _dynamics(kb: KnowledgeBase, class_name: str, rows: list[dict[str, Any]]) -> dict[str, Any]:
    ods = kb.analyses(kind="ods", class_name=class_name)
    if ods:
        latest = max(ods, key=lambda a: a.t_end_s)
        return {"source": "ods", "t_start_s": latest.t_start_s, "t_end_s": latest.t_end_s, **latest.values}
    speeds = [r["speed"] for r in rows if r["speed"] is not None]
    return {
        "source": "instances",
        "dynamic": sum(r["state"] == "dynamic" for r in rows),
        "static": sum(r["state"] == "static" for r in rows),
        "mean_speed_mps": float(np.mean(speeds)) if speeds else None,
    }


def workspace(
    kb: KnowledgeBase,
    center_m: tuple[float, float, float],
    size_m: float | tuple[float, float, float],
    *,
    resolution_m: float = 0.05,
) -> Workspace:
    """The workspace box of edge ``size_m`` (or sizes per axis) centred at ``center_m``."""
    size = np.broadcast_to(np.asarray(size_m, dtype=np.float64), (3,)).copy()
    center = np.asarray(center_m, dtype=np.float64)
    if center.shape != (3,) or not np.all(np.isfinite(center)):
        raise QueryError(f"--center {center_m}: expected x,y,z in metres")
    if not np.all(size > 0) or not resolution_m > 0:
        raise QueryError(f"--size {size_m} / --resolution {resolution_m}: must be positive (m)")
    shape = np.maximum(np.ceil(size / resolution_m).astype(int), 1)
    if int(np.prod(shape)) > MAX_VOXELS:
        raise QueryError(
            f"workspace of {shape.tolist()} voxels is too large; use a coarser --resolution "
            f"or a smaller --size (at most {MAX_VOXELS} voxels)"
        )
    lo, hi = center - size / 2.0, center + size / 2.0
    ctx = make_context(kb)
    idx = ctx.index
    meets = np.flatnonzero(
        np.all(idx.centers - idx.extents / 2 <= hi, axis=1)
        & np.all(idx.centers + idx.extents / 2 >= lo, axis=1)
    )
    rows = [idx.row(int(k)) for k in meets]
    background = []
    for r in sorted((r for r in rows if r["layer"] == "background"), key=lambda r: r["uuid"]):
        c, e = np.array(r["center"]), np.array(r["extent"])
        clo, chi = np.maximum(c - e / 2, lo), np.minimum(c + e / 2, hi)
        inst = kb.instance(r["uuid"])
        plane = inst.data.get("plane_map") if inst is not None else None
        background.append(
            Primitive(
                r["uuid"],
                r["class"],
                "plane" if plane else "box",
                _t3((clo + chi) / 2),
                _t3(chi - clo),
                (float(plane[0]), float(plane[1]), float(plane[2]), float(plane[3])) if plane else None,
            )
        )
    foreground = sorted((r for r in rows if r["layer"] == "foreground"), key=lambda r: r["uuid"])
    classes = tuple(sorted({r["class"] for r in foreground}))
    occupancy = np.full(tuple(shape), -1, dtype=np.int16)
    axes = [lo[k] + (np.arange(shape[k]) + 0.5) * resolution_m for k in range(3)]
    for r in foreground:
        c, e = np.array(r["center"]), np.array(r["extent"])
        sel = [np.flatnonzero(np.abs(axes[k] - c[k]) <= e[k] / 2 + resolution_m / 2) for k in range(3)]
        if all(len(s) for s in sel):
            occupancy[np.ix_(*sel)] = classes.index(r["class"])
    dynamics = {name: _dynamics(kb, name, [r for r in foreground if r["class"] == name]) for name in classes}
    return Workspace(
        _t3(center),
        _t3(size),
        resolution_m,
        _t3(lo),
        tuple(background),
        classes,
        occupancy,
        dynamics,
        tuple(r["uuid"] for r in foreground),
    )
