"""A simulated log's ground truth in the realistic worlds' format, for scene scoring.

``hiper eval scene`` (and the worlds' own reference scorer) read a log's ``gt/instances.json``
(every instance seen: class, layer, box, plane and area of building pieces, visibility, and
for moving ones a trajectory) and ``gt/surface_points.npz`` (exact surface samples, static and
on the moving instances). ``hiper sim`` writes both beside its ``gt/world.json`` with this
recorder, made the way the worlds' files are: the noise-free depth of every ``SAMPLE_EVERY``-th
frame on a ``GRID_PX`` pixel grid up to the sensor's range, static samples thinned to one per
``DEDUP_M`` cell per instance; an instance is *observed* when one frame shows at least
``OBSERVED_MIN_PIXELS`` of its pixels with a depth return.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.sim.meshes import Mesh
from hiper_cli.types import CameraIntrinsics

__all__ = ["DynamicTruth", "SceneTruthRecorder", "StaticTruth"]

SAMPLE_EVERY = 5  # frames between surface samplings
GRID_PX = 4  # pixel step of the sampling grid
DEDUP_M = 0.02  # one static sample per instance per cell of this size
OBSERVED_MIN_PIXELS = 200
BACKGROUND_CLASSES = ("wall", "floor", "ceiling")  # the worlds' background layer
PLANE_NORMAL_MIN_DOT = 0.9  # a triangle this parallel to a piece's plane counts to its area
_THIN_EVERY = 40  # sampled frames between thinnings of the static samples (memory)
_CELL_BITS = 15  # per axis of the thinning key; cells within ±327 m of the origin

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class StaticTruth:
    """One static instance of the world: what ``instances.json`` says of it."""

    id: int
    name: str
    class_name: str
    mesh: Mesh
    plane: tuple[float, float, float, float] | None


@dataclass(frozen=True)
class DynamicTruth:
    """One moving instance: its [t, x, y, z] box-centre rows, body extent and preferred speed
    (people slow down and stop for each other and the robot: ``instances.json`` gives the
    speed it walked at while seen, ``_seen_speed_mps``)."""

    id: int
    name: str
    class_name: str
    rows: FloatArray  # (T, 4)
    extent_m: FloatArray  # (3,)
    speed_mps: float


class SceneTruthRecorder:
    """Fed every rendered frame (``add``); writes ``instances.json`` and ``surface_points.npz``."""

    def __init__(self, camera: CameraIntrinsics, max_range_m: float, n_ids: int) -> None:
        self.camera = camera
        self.max_range_m = max_range_m
        self.n_ids = n_ids
        self.frames_visible = np.zeros(n_ids, np.int64)
        self.max_pixels = np.zeros(n_ids, np.int64)
        self.frames_in_range = np.zeros(n_ids, np.int64)
        self.max_in_range = np.zeros(n_ids, np.int64)
        self.first_t = np.full(n_ids, np.inf)
        self.last_t = np.full(n_ids, -np.inf)
        self.n_frames = 0
        self._seen_stamps: dict[int, list[float]] = {}  # moving instances: stamps they were seen
        self._static: list[tuple[NDArray[np.float32], NDArray[np.int8], NDArray[np.uint16]]] = []
        self._dynamic: list[tuple[NDArray[np.float32], NDArray[np.uint16], NDArray[np.float64]]] = []
        self._sampled = 0
        v, u = np.mgrid[0 : camera.height : GRID_PX, 0 : camera.width : GRID_PX]
        self._grid = (v.ravel(), u.ravel())
        self._rays = np.stack([(u.ravel() - camera.cx) / camera.fx, (v.ravel() - camera.cy) / camera.fy,
                               np.ones(u.size)], axis=1)

    def add(
        self,
        stamp_s: float,
        hit_ids: NDArray[np.uint16],
        true_z_m: NDArray[np.float32],
        normal_cam: NDArray[np.float32],
        T_map_cam: FloatArray,
        dynamic_ids: Iterable[int],
    ) -> None:
        """One frame: its visibility counts, and every ``SAMPLE_EVERY``-th its surface samples."""
        ids = hit_ids.ravel().astype(np.int64)
        in_range = (true_z_m.ravel() > 0) & (true_z_m.ravel() <= self.max_range_m)
        seen = np.bincount(ids, minlength=self.n_ids)[: self.n_ids]
        ranged = np.bincount(ids[in_range], minlength=self.n_ids)[: self.n_ids]
        seen[0] = ranged[0] = 0
        self.frames_visible += seen > 0
        self.frames_in_range += ranged > 0
        self.max_pixels = np.maximum(self.max_pixels, seen)
        self.max_in_range = np.maximum(self.max_in_range, ranged)
        self.first_t = np.where(seen > 0, np.minimum(self.first_t, stamp_s), self.first_t)
        self.last_t = np.where(seen > 0, np.maximum(self.last_t, stamp_s), self.last_t)
        movers = frozenset(dynamic_ids)
        for i in movers:
            if 0 <= i < self.n_ids and ranged[i] > 0:
                self._seen_stamps.setdefault(i, []).append(stamp_s)
        if self.n_frames % SAMPLE_EVERY == 0:
            self._sample(stamp_s, hit_ids, true_z_m, normal_cam, T_map_cam, movers)
        self.n_frames += 1

    def _sample(
        self,
        stamp_s: float,
        hit_ids: NDArray[np.uint16],
        true_z_m: NDArray[np.float32],
        normal_cam: NDArray[np.float32],
        T_map_cam: FloatArray,
        dynamic: frozenset[int],
    ) -> None:
        z = true_z_m[self._grid].astype(np.float64)
        ids = hit_ids[self._grid]
        ok = (z > 0) & (z <= self.max_range_m) & (ids > 0)
        R, t = T_map_cam[:3, :3], T_map_cam[:3, 3]
        xyz = (self._rays[ok] * z[ok, None]) @ R.T + t
        ids = ids[ok]
        moving = np.isin(ids, np.fromiter(dynamic, np.int64, len(dynamic)))
        normals = normal_cam[self._grid][ok].astype(np.float64) @ R.T
        self._static.append((xyz[~moving].astype(np.float32),
                             np.round(np.nan_to_num(normals[~moving]) * 127).astype(np.int8),
                             ids[~moving]))
        stamps = np.full(int(moving.sum()), stamp_s)
        self._dynamic.append((xyz[moving].astype(np.float32), ids[moving], stamps))
        self._sampled += 1
        if self._sampled % _THIN_EVERY == 0:
            self._static = [self._thinned()]

    def _thinned(self) -> tuple[NDArray[np.float32], NDArray[np.int8], NDArray[np.uint16]]:
        """The static samples so far, one per ``DEDUP_M`` cell per instance."""
        if not self._static:
            return np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int8), np.zeros(0, np.uint16)
        xyz = np.concatenate([s[0] for s in self._static])
        normals = np.concatenate([s[1] for s in self._static])
        ids = np.concatenate([s[2] for s in self._static])
        half = 1 << (_CELL_BITS - 1)
        cells = np.clip(np.floor(xyz / DEDUP_M).astype(np.int64) + half, 0, (1 << _CELL_BITS) - 1)
        key = ids.astype(np.int64) << (3 * _CELL_BITS)
        for axis in range(3):
            key |= cells[:, axis] << ((2 - axis) * _CELL_BITS)
        _, first = np.unique(key, return_index=True)
        first.sort()
        return xyz[first], normals[first], ids[first]

    def write(
        self,
        gt_dir: Path,
        world: str,
        seed: int,
        rate_hz: float,
        static: Sequence[StaticTruth],
        dynamic: Sequence[DynamicTruth],
    ) -> None:
        """``gt_dir/instances.json`` and ``gt_dir/surface_points.npz``."""
        sx, sn, si = self._thinned()
        dyn = self._dynamic or [(np.zeros((0, 3), np.float32), np.zeros(0, np.uint16), np.zeros(0))]
        np.savez_compressed(
            gt_dir / "surface_points.npz",
            static_xyz=sx, static_normal=sn, static_id=si,
            dynamic_xyz=np.concatenate([d[0] for d in dyn]),
            dynamic_id=np.concatenate([d[1] for d in dyn]),
            dynamic_t=np.concatenate([d[2] for d in dyn]),
        )
        records = [self._static_record(s) for s in static if self.frames_visible[s.id] > 0]
        records += [self._dynamic_record(d) for d in dynamic if self.frames_visible[d.id] > 0]
        doc = {
            "log": world,
            "description": f"hiper sim, world {world}, seed {seed}",
            "synthetic": True,
            "map_frame": "map",
            "t0": 0.0,
            "rate_hz": rate_hz,
            "n_frames": self.n_frames,
            "duration_s": self.n_frames / rate_hz,
            "classes": sorted({r["class"] for r in records}),
            "background_classes": list(BACKGROUND_CLASSES),
            "observed_rule": f"max_in_range_pixels >= {OBSERVED_MIN_PIXELS}",
            "sources": ["hiper sim"],
            "seed": seed,
            "instances": sorted(records, key=lambda r: int(r["id"])),
        }
        (gt_dir / "instances.json").write_text(json.dumps(doc, indent=1) + "\n")

    def _visibility(self, i: int) -> dict[str, Any]:
        return {
            "frames_visible": int(self.frames_visible[i]),
            "max_pixels": int(self.max_pixels[i]),
            "frames_in_range": int(self.frames_in_range[i]),
            "max_in_range_pixels": int(self.max_in_range[i]),
            "observed": bool(self.max_in_range[i] >= OBSERVED_MIN_PIXELS),
            "first_seen_t": round(float(self.first_t[i]), 6),
            "last_seen_t": round(float(self.last_t[i]), 6),
        }

    def _static_record(self, s: StaticTruth) -> dict[str, Any]:
        lo, hi = s.mesh.bounds()
        rec: dict[str, Any] = {
            "id": s.id, "name": s.name, "model": s.name, "class": s.class_name, "alt_classes": [],
            "layer": "background" if s.class_name in BACKGROUND_CLASSES else "foreground",
            "static": True, **_box(lo, hi),
        }
        if s.plane is not None and s.class_name in BACKGROUND_CLASSES:
            rec["plane"] = list(s.plane)
            rec["area_m2"] = round(_plane_area_m2(s.mesh, np.asarray(s.plane[:3], np.float64)), 4)
        return {**rec, **self._visibility(s.id)}

    def _dynamic_record(self, d: DynamicTruth) -> dict[str, Any]:
        half = d.extent_m / 2.0
        lo, hi = d.rows[:, 1:4].min(axis=0) - half, d.rows[:, 1:4].max(axis=0) + half
        return {
            "id": d.id, "name": d.name, "model": d.name, "class": d.class_name, "alt_classes": [],
            "layer": "foreground", "static": False, **_box(lo, hi),
            "speed_mps": self._seen_speed_mps(d), "preferred_speed_mps": d.speed_mps,
            "active_from_t": float(d.rows[0, 0]),
            "body_size": [float(v) for v in d.extent_m],
            "trajectory": [[round(float(v), 5) for v in row] for row in d.rows],
            **self._visibility(d.id),
        }


    def _seen_speed_mps(self, d: DynamicTruth) -> float:
        """The median horizontal speed of ``d`` at the frames it was seen with depth: what a
        perceiver can measure (the preferred speed where it was never seen)."""
        seen = np.asarray(self._seen_stamps.get(d.id, []))
        if len(d.rows) < 2 or len(seen) == 0:
            return d.speed_mps
        t = d.rows[:, 0]
        v = np.gradient(d.rows[:, 1:3], t, axis=0)
        at = np.clip(np.searchsorted(t, seen), 0, len(t) - 1)
        return round(float(np.median(np.hypot(v[at, 0], v[at, 1]))), 4)


def _box(lo: FloatArray, hi: FloatArray) -> dict[str, list[float]]:
    return {
        "aabb_min": [round(float(v), 5) for v in lo],
        "aabb_max": [round(float(v), 5) for v in hi],
        "center": [round(float(v), 5) for v in (lo + hi) / 2.0],
        "size": [round(float(v), 5) for v in hi - lo],
    }


def _plane_area_m2(mesh: Mesh, normal: FloatArray) -> float:
    """The area of one side of a piece: its triangles parallel to its plane, halved (a wall box
    and a floor slab have two such faces)."""
    v = mesh.vertices[mesh.triangles]
    cross = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    area = np.linalg.norm(cross, axis=1) / 2.0
    unit = cross / np.maximum(2.0 * area, 1e-12)[:, None]
    parallel = np.abs(unit @ (normal / np.linalg.norm(normal))) >= PLANE_NORMAL_MIN_DOT
    return float(area[parallel].sum()) / 2.0
