"""Merging background observations into instances (Algorithm 2, ``MergeOb``).

An observation, moved into the map frame with its pose, is tested against every live
instance with criteria of increasing cost: class, alignment (normal angle and plane offset),
box overlap (with a margin) and contour overlap (shapely polygons in the instance's plane,
with a margin). A table top's observation also reaches on behind what hid its plane
(``hidden.py``): the pieces of a desk a chair's back or a row of bottles cut apart are one
top, and the instance's contour fills the gap between them. No match makes a new instance,
one match merges, several matches merge all of them into the oldest and delete the others.

An instance's geometry is a pure fold of its observations in time order (area-weighted
normal and centroid, union of contours), so ``reanchor`` can recompute it from the
observations with other poses and get what incremental merging would have produced.
Instance ``data``: ``plane_map`` [a, b, c, d], ``contour_map`` (K, 3) and ``fit``
(``w``: summed weight = observed area in m², ``n``: weighted normal sum, ``c``: weighted
centroid sum) that makes merging incremental.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D, Instance, Observation
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.contour import (
    PlaneFrame,
    to_polygon,
    to_ring,
    transform_plane,
    transform_points,
)

__all__ = [
    "MapObservation",
    "fold",
    "instance_matches",
    "match_instances",
    "merge_into",
    "new_instance",
    "to_map",
]

FloatArray = NDArray[np.float64]
MIN_THICKNESS_M = 0.02


@dataclass(frozen=True)
class MapObservation:
    """A background observation with its plane, contour and centroid in the map frame."""

    obs: Observation
    plane_map: FloatArray
    contour_map: FloatArray
    centroid_map: FloatArray
    weight: float
    # points of the plane beyond the contour that something nearer hid (``hidden.py``)
    hidden_map: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))


def to_map(obs: Observation, T_map_cam: FloatArray) -> MapObservation:
    """Move an observation's plane data into the map frame with the pose it was seen from."""
    data = obs.data
    centroid = np.asarray(data.get("centroid_cam", obs.box.center_m), dtype=np.float64)
    return MapObservation(
        obs,
        transform_plane(np.asarray(data["plane_cam"], dtype=np.float64), T_map_cam),
        transform_points(np.asarray(data["contour_cam"], dtype=np.float64), T_map_cam),
        transform_points(centroid, T_map_cam)[0],
        float(data.get("area_m2", 1.0)),
        transform_points(np.asarray(data.get("hidden_cam", []), dtype=np.float64), T_map_cam),
    )


def _fused(inst: Instance) -> bool:
    """Whether ``inst`` carries its fused plane (fit, plane and contour in the map frame): one
    known only by its summary, as an import writes it, has no evidence to merge new views into."""
    return all(key in inst.data for key in ("fit", "plane_map", "contour_map"))


def _geometry(inst: Instance) -> tuple[FloatArray, FloatArray, FloatArray]:
    d = inst.data
    fit = d["fit"]
    return (
        np.asarray(d["plane_map"], dtype=np.float64),
        np.asarray(d["contour_map"], dtype=np.float64).reshape(-1, 3),
        np.asarray(fit["c"], dtype=np.float64) / float(fit["w"]),
    )


def _box(contour_map: FloatArray, frame: PlaneFrame, thickness_m: float) -> Box3D:
    uv = frame.to_2d(contour_map)
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    center = frame.to_3d((lo + hi) / 2.0)[0]
    extent = np.array([hi[0] - lo[0], hi[1] - lo[1], max(thickness_m, MIN_THICKNESS_M)])
    return Box3D(center, extent, frame.R)


def _set_geometry(inst: Instance, fit: dict[str, Any], polygon: Any, frame: PlaneFrame) -> None:
    ring = to_ring(polygon, frame)
    inst.data["plane_map"] = [*frame.normal.tolist(), frame.d]
    inst.data["contour_map"] = ring.tolist()
    inst.data["fit"] = fit
    if len(ring) >= 3:
        inst.box = _box(ring, frame, MIN_THICKNESS_M)


def _plane_of(fit: dict[str, Any]) -> FloatArray:
    n = np.asarray(fit["n"], dtype=np.float64)
    n = n / np.linalg.norm(n)
    c = np.asarray(fit["c"], dtype=np.float64) / float(fit["w"])
    return np.append(n, -float(n @ c))


def _union(polygons: Sequence[Any], close_m: float) -> Any:
    from shapely import union_all

    merged = union_all([p for p in polygons if not p.is_empty])
    if close_m > 0:  # bridge the small gaps between neighbouring views
        merged = merged.buffer(close_m, join_style="mitre").buffer(-close_m, join_style="mitre")
    return merged.simplify(0.02)


def new_instance(mo: MapObservation, cfg: BackgroundConfig) -> Instance:
    """A new instance made of one observation."""
    fit = {"w": mo.weight, "n": (mo.plane_map[:3] * mo.weight).tolist(),
           "c": (mo.centroid_map * mo.weight).tolist()}
    frame = PlaneFrame(_plane_of(fit))
    inst = Instance(
        layer="background",
        class_name=mo.obs.class_name,
        box=_box(mo.contour_map, frame, MIN_THICKNESS_M),
        first_seen_s=mo.obs.stamp_s,
        last_seen_s=mo.obs.stamp_s,
        confidence=mo.obs.confidence,
        observation_uuids=[mo.obs.uuid],
    )
    _set_geometry(inst, fit, to_polygon(mo.contour_map, frame), frame)
    mo.obs.instance_uuid = inst.uuid
    return inst


def merge_into(target: Instance, others: Sequence[Instance], mo: MapObservation | None,
               cfg: BackgroundConfig) -> Instance:
    """Fold ``others`` and the observation ``mo`` into ``target`` (updated in place)."""
    fits = [target.data["fit"], *(o.data["fit"] for o in others)]
    rings = [np.asarray(i.data["contour_map"], dtype=np.float64).reshape(-1, 3) for i in (target, *others)]
    if mo is not None:
        fits.append({"w": mo.weight, "n": (mo.plane_map[:3] * mo.weight).tolist(),
                     "c": (mo.centroid_map * mo.weight).tolist()})
        rings.append(mo.contour_map)
    fit = {
        "w": float(sum(float(f["w"]) for f in fits)),
        "n": np.sum([np.asarray(f["n"], dtype=np.float64) for f in fits], axis=0).tolist(),
        "c": np.sum([np.asarray(f["c"], dtype=np.float64) for f in fits], axis=0).tolist(),
    }
    frame = PlaneFrame(_plane_of(fit))
    polygons = [to_polygon(r, frame) for r in rings]
    if mo is not None and len(mo.hidden_map):
        polygons.append(_bridge(polygons[-1], mo.hidden_map, polygons[:-1], frame, cfg))
    polygon = _union(polygons, cfg.merge_contour_margin_m / 2.0)
    _set_geometry(target, fit, polygon, frame)
    for other in others:
        known = set(target.observation_uuids)
        target.observation_uuids.extend(u for u in other.observation_uuids if u not in known)
        target.first_seen_s = min(target.first_seen_s, other.first_seen_s)
        target.last_seen_s = max(target.last_seen_s, other.last_seen_s)
    if mo is not None:
        target.observation_uuids.append(mo.obs.uuid)
        target.first_seen_s = min(target.first_seen_s, mo.obs.stamp_s)
        target.last_seen_s = max(target.last_seen_s, mo.obs.stamp_s)
        mo.obs.instance_uuid = target.uuid
    return target


def _reach(seen: Any, hidden_map: FloatArray, frame: PlaneFrame, cfg: BackgroundConfig) -> Any:
    """``seen`` and the hidden plane points joined to it: how far the surface may go on behind
    occluders. The points count by the cells, half the contour margin wide, that hold them, each
    grown by half a cell, so points that close chain up (far cheaper than buffering each point)."""
    import shapely

    cell = cfg.merge_contour_margin_m / 2.0
    ij = np.unique(np.floor(frame.to_2d(hidden_map) / cell), axis=0)
    lo, hi = (ij - 0.5) * cell, (ij + 1.5) * cell
    grown = shapely.union_all(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
    joined = shapely.union_all([seen, grown])
    parts = getattr(joined, "geoms", [joined])
    return shapely.union_all([p for p in parts if p.intersects(seen)] or [seen])


def _bridge(seen: Any, hidden_map: FloatArray, known: Sequence[Any], frame: PlaneFrame,
            cfg: BackgroundConfig) -> Any:
    """The hidden part of the plane between an observation's ``seen`` polygon and the
    instances it joins (``known``): its reach within the convex hull of them all."""
    from shapely import union_all

    return _reach(seen, hidden_map, frame, cfg).intersection(union_all([seen, *known]).convex_hull)


def _matches(class_name: str, plane: FloatArray, contour: FloatArray, centroid: FloatArray,
             inst: Instance, cfg: BackgroundConfig, hidden: FloatArray | None = None) -> bool:
    # 1. class
    if inst.class_name != class_name:
        return False
    # 2. alignment: normal angle and mutual plane offsets
    plane_i, contour_i, centroid_i = _geometry(inst)
    if float(plane[:3] @ plane_i[:3]) < np.cos(np.radians(cfg.merge_angle_deg)):
        return False
    if abs(float(plane_i[:3] @ centroid) + plane_i[3]) > cfg.merge_offset_m:
        return False
    if abs(float(plane[:3] @ centroid_i) + plane[3]) > cfg.merge_offset_m:
        return False
    # 3. boxes (axis-aligned hulls of the contours) overlap, with a margin
    if len(contour_i) < 3 or len(contour) < 3:
        return False
    m = cfg.merge_box_margin_m
    reach = contour if hidden is None or not len(hidden) else np.vstack([contour, hidden])
    if np.any(reach.min(axis=0) - m > contour_i.max(axis=0)) or np.any(
        contour_i.min(axis=0) - m > reach.max(axis=0)
    ):
        return False
    # 4. contours overlap in the instance's plane, with a margin (the observation's reaching
    # on behind what hid its plane, ``hidden.py``)
    frame = PlaneFrame(plane_i)
    seen, known = to_polygon(contour, frame), to_polygon(contour_i, frame)
    if seen.distance(known) <= cfg.merge_contour_margin_m:
        return True
    if hidden is None or not len(hidden):
        return False
    return bool(_reach(seen, hidden, frame, cfg).distance(known) <= cfg.merge_contour_margin_m)


def match_instances(mo: MapObservation, instances: Sequence[Instance],
                    cfg: BackgroundConfig) -> list[Instance]:
    """The instances ``mo`` belongs to, oldest first."""
    found = [
        inst for inst in instances
        if _fused(inst) and _matches(mo.obs.class_name, mo.plane_map, mo.contour_map, mo.centroid_map,
                                     inst, cfg, mo.hidden_map)
    ]
    return sorted(found, key=lambda i: (i.first_seen_s, i.uuid))


def instance_matches(a: Instance, b: Instance, cfg: BackgroundConfig) -> bool:
    """Whether two instances satisfy the merge criteria (used to find duplicates)."""
    if not (_fused(a) and _fused(b)):
        return False
    plane, contour, centroid = _geometry(a)
    return _matches(a.class_name, plane, contour, centroid, b, cfg)


def fold(observations: Sequence[MapObservation], cfg: BackgroundConfig,
         base: Instance | None = None) -> Instance:
    """One instance from its observations in time order (``base`` keeps uuid and state)."""
    ordered = sorted(observations, key=lambda m: (m.obs.stamp_s, m.obs.uuid))
    inst = new_instance(ordered[0], cfg)
    for mo in ordered[1:]:
        merge_into(inst, [], mo, cfg)
    if base is not None:
        inst.uuid = base.uuid
        inst.state = base.state
        for mo in ordered:
            mo.obs.instance_uuid = base.uuid
    return inst
