"""The true surfaces of a log (``gt/surface_points.npz`` of a realistic world or of a
``hiper sim`` log, ``sim/scene_truth.py``), for scoring.

``gt/surface_points.npz`` holds exact surface samples: ``static_xyz`` (N, 3), ``static_normal``
(N, 3, int8 × 127), ``static_id`` (N,), and ``dynamic_xyz``, ``dynamic_id``, ``dynamic_t`` on
the walking people. ``gt/instances.json`` gives each building piece's ``area_m2``.

A point's nearest true surface is measured as the reference scorer of the worlds does it:
to the plane of the nearest building piece (a plane centre over a hole under furniture is on
the wall), else point-to-plane along the nearest sample's normal where the point lies over
it, else the Euclidean distance. Each piece's plane is fitted here from its own samples: a
stored ``plane`` may disagree with them (the bookstore's ``wall_002`` has a normal 62° off
its samples').
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError

__all__ = ["SURFACE_FILE", "SurfaceTruth", "load_surfaces"]

SURFACE_FILE = "surface_points.npz"
PLANE_REACH_M = 1.0  # the piece's plane is used for points this close to one of its samples
LATERAL_M = 0.05  # a point within this of a sample's normal line is measured along the normal
MIN_PLANE_SAMPLES = 10

FloatArray = NDArray[np.float64]


@dataclass
class SurfaceTruth:
    """Surface samples and building-piece planes of one log."""

    static_xyz: FloatArray
    static_normal: FloatArray
    static_id: NDArray[np.int64]
    dynamic_xyz: FloatArray
    dynamic_id: NDArray[np.int64]
    piece_planes: dict[int, FloatArray]  # id: [nx, ny, nz, d], fitted to the samples
    piece_area_m2: dict[int, float]

    def __post_init__(self) -> None:
        from scipy.spatial import cKDTree

        self._static = cKDTree(self.static_xyz) if len(self.static_xyz) else None
        self._dynamic = cKDTree(self.dynamic_xyz) if len(self.dynamic_xyz) else None

    def nearest(self, points: FloatArray) -> tuple[FloatArray, NDArray[np.int64], NDArray[np.bool_]]:
        """Per point (N, 3): distance to, id of and whether static the nearest true surface."""
        n = len(points)
        dist_s, id_s = np.full(n, np.inf), np.zeros(n, np.int64)
        if self._static is not None:
            d, j = self._static.query(points)
            off = points - self.static_xyz[j]
            normal = self.static_normal[j]
            along = np.einsum("ij,ij->i", off, normal)
            lateral = np.linalg.norm(off - along[:, None] * normal, axis=1)
            dist_s = np.where(lateral < LATERAL_M, np.abs(along), d)
            id_s = self.static_id[j]
            for k in range(n):
                plane = self.piece_planes.get(int(id_s[k]))
                if plane is not None and d[k] < PLANE_REACH_M:
                    dist_s[k] = abs(float(plane[:3] @ points[k] + plane[3]))
        dist_d, id_d = np.full(n, np.inf), np.zeros(n, np.int64)
        if self._dynamic is not None:
            dist_d, j = self._dynamic.query(points)
            id_d = self.dynamic_id[j]
        dynamic = dist_d < dist_s
        return np.where(dynamic, dist_d, dist_s), np.where(dynamic, id_d, id_s), ~dynamic


def _fit(points: FloatArray) -> FloatArray:
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    normal = vt[-1]
    return np.append(normal, -float(normal @ centre))


def load_surfaces(log_dir: str | Path) -> SurfaceTruth:
    """Read ``LOG/gt/surface_points.npz`` and the pieces of ``LOG/gt/instances.json``."""
    gt = Path(log_dir) / "gt"
    path = gt / SURFACE_FILE
    try:
        with np.load(path) as npz:
            sx = np.asarray(npz["static_xyz"], np.float64).reshape(-1, 3)
            sn = np.asarray(npz["static_normal"], np.float64).reshape(-1, 3) / 127.0
            si = np.asarray(npz["static_id"], np.int64).reshape(-1)
            dx = np.asarray(npz["dynamic_xyz"], np.float64).reshape(-1, 3)
            di = np.asarray(npz["dynamic_id"], np.int64).reshape(-1)
        records = json.loads((gt / "instances.json").read_text())["instances"]
        pieces = {int(d["id"]): d for d in records if d.get("plane") and d.get("area_m2") is not None}
    except (OSError, KeyError, ValueError, TypeError, json.JSONDecodeError) as err:
        hint = ("; hiper sim writes both: make the log again with it"
                if (gt / "world.json").exists() else "")
        raise LogError(f"{path}: cannot read the true surfaces ({err}); scoring a scene "
                       f"needs gt/{SURFACE_FILE} and gt/instances.json{hint}") from err
    norms = np.linalg.norm(sn, axis=1, keepdims=True)
    sn = sn / np.where(norms > 0, norms, 1.0)
    planes: dict[int, FloatArray] = {}
    order = np.argsort(si, kind="stable")
    bounds = np.searchsorted(si[order], list(pieces), side="left")
    ends = np.searchsorted(si[order], list(pieces), side="right")
    for pid, a, b in zip(pieces, bounds, ends, strict=True):
        if str(pieces[pid].get("name", "")).endswith("_misc") or b - a < MIN_PLANE_SAMPLES:
            continue  # pooled small pieces are no plane
        planes[pid] = _fit(sx[order[a:b]])
    return SurfaceTruth(
        static_xyz=sx, static_normal=sn, static_id=si, dynamic_xyz=dx, dynamic_id=di,
        piece_planes=planes, piece_area_m2={pid: float(d["area_m2"]) for pid, d in pieces.items()},
    )
