"""The background stage: keyframes → plane observations → merged background instances."""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D, Instance, Observation
from hiper_cli.perceive.background.bounds import edge_evidence, is_open, view_bounded
from hiper_cli.perceive.background.classify import classify_plane
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.contour import (
    PlaneFrame,
    contour_from_mask,
    to_polygon,
    transform_plane,
    transform_points,
)
from hiper_cli.perceive.background.fronts import deep_sides, front_sides, segment_labels
from hiper_cli.perceive.background.hidden import hidden_points
from hiper_cli.perceive.background.merge import (
    MapObservation,
    match_instances,
    merge_into,
    new_instance,
    to_map,
)
from hiper_cli.perceive.background.not_walls import NotWalls
from hiper_cli.perceive.background.planes import PlaneSegment, SampleGrid, extract_planes
from hiper_cli.perceive.background.sighting import sighted
from hiper_cli.perceive.background.table_votes import TableVotes
from hiper_cli.perceive.background.under import under_evidence
from hiper_cli.perceive.background.wall_range import FarWalls
from hiper_cli.perceive.stage import FrameResult, World
from hiper_cli.types import Frame

__all__ = ["BackgroundStage", "observe", "observe_all"]

FloatArray = NDArray[np.float64]
MIN_PLANE_THICKNESS_M = 0.02  # a plane observation's box is at least this thick (2 σ of its fit)
MIN_CONFIDENCE = 0.05  # the worst-fitting plane still gets this confidence


def _observation(seg: PlaneSegment, grid: SampleGrid, frame: Frame, cfg: BackgroundConfig,
                 segments: list[PlaneSegment], labels: NDArray[np.int64]) -> Observation | None:
    contour_cam = contour_from_mask(
        seg.mask, grid.stride, frame.camera, seg.plane_cam, cfg.contour_epsilon_px, grid.points_cam
    )
    if len(contour_cam) < 3:
        return None
    pf = PlaneFrame(seg.plane_cam)
    area = float(to_polygon(contour_cam, pf).area)
    if area < cfg.min_area_m2:
        return None
    plane_map = transform_plane(seg.plane_cam, frame.T_map_cam)
    contour_map = transform_points(contour_cam, frame.T_map_cam)
    class_name = classify_plane(plane_map, contour_map, cfg)
    vertical = abs(plane_map[2]) < np.sin(np.radians(cfg.vertical_deg))
    if class_name is None and vertical and cfg.wall_view_bounded and view_bounded(grid, frame.camera, seg,
                                                                                 cfg):
        class_name = classify_plane(plane_map, contour_map, cfg, view_bounded=True)
    if class_name is None:
        return None
    uv = pf.to_2d(contour_cam)
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    thickness = max(2.0 * seg.rms_m, MIN_PLANE_THICKNESS_M)
    box = Box3D(pf.to_3d((lo + hi) / 2.0)[0], np.array([*(hi - lo), thickness]), pf.R)
    edges = edge_evidence(grid, frame.camera, seg, cfg) if class_name == "wall" and cfg.wall_bounds else None
    # a table top on legs, or the top of a box stack, a cabinet or a bed (``under.py``)
    under = under_evidence(grid, seg, cfg) if class_name == "table" and cfg.table_needs_legs else None
    # where the top goes on behind something nearer (``hidden.py``)
    hidden = hidden_points(grid, frame.camera, seg, cfg) if class_name == "table" else np.zeros((0, 3))
    if edges is not None and cfg.wall_fronts:
        for side in front_sides(grid, frame.camera, seg, segments, labels, cfg):
            edges[side] = "front"  # a furniture front before a wall
        height_m = grid.points_cam @ frame.T_map_cam[2, :3] + frame.T_map_cam[2, 3]
        for side in deep_sides(grid, seg, height_m, cfg):
            edges[side] = "front"  # a furniture front with a side face of furniture depth
    rows, cols = np.nonzero(seg.mask)
    pick = np.linspace(0, len(rows) - 1, min(cfg.pixel_sample, len(rows))).astype(int)
    pixels_uv = np.stack([cols[pick], rows[pick]], axis=1) * grid.stride
    centroid = grid.points_cam[seg.mask].mean(axis=0)
    z = float(centroid[2])
    confidence = float(np.clip(1.0 - seg.rms_m / (cfg.inlier_m * max(z, 1.0)), MIN_CONFIDENCE, 1.0))
    return Observation(
        layer="background",
        class_name=class_name,
        confidence=confidence,
        stamp_s=frame.stamp_s,
        pose_id=frame.pose_id,
        box=box,
        data={
            "plane_cam": seg.plane_cam.tolist(),
            "contour_cam": contour_cam.tolist(),
            "centroid_cam": centroid.tolist(),
            "pixels_uv": pixels_uv.astype(int).tolist(),
            "area_m2": area,
            "rms_m": seg.rms_m,
            "num_points": seg.n_points,
            "method": cfg.method,
            **({"edges": edges} if edges is not None else {}),
            **({"under": under} if under is not None else {}),
            **({"hidden_cam": np.round(hidden, 4).tolist()} if len(hidden) else {}),
        },
    )


def _open(obs: Observation) -> bool:
    """A wall candidate that does not reach the ceiling or the floor (``bounds.py``)."""
    return is_open(obs.data.get("edges", {}))


def observe_all(frame: Frame, cfg: BackgroundConfig) -> tuple[list[Observation], list[Observation]]:
    """(observations, open walls): the classified plane observations of one frame, and the
    vertical planes that would be walls but end in the room (furniture fronts)."""
    grid, segments = extract_planes(frame.depth_m, frame.camera, cfg)
    out: list[Observation] = []
    open_walls: list[Observation] = []
    labels = segment_labels(grid.shape, segments)
    for seg in segments:
        obs = _observation(seg, grid, frame, cfg, segments, labels)
        if obs is not None:
            (open_walls if _open(obs) else out).append(obs)
    return out, open_walls


def observe(frame: Frame, cfg: BackgroundConfig) -> list[Observation]:
    """Algorithm 1 (``ExtractOb``): the classified plane observations of one frame (a table top
    this frame sees on a solid front is none)."""
    return [o for o in observe_all(frame, cfg)[0] if o.data.get("under") != "solid"]


def _copy(inst: Instance) -> Instance:
    """A copy merging may change without touching the world's instance (it replaces data values)."""
    return dataclasses.replace(inst, observation_uuids=list(inst.observation_uuids), data=dict(inst.data))


def merge_observations(observations: list[MapObservation], live: dict[str, Instance],
                       cfg: BackgroundConfig) -> tuple[dict[str, Instance], list[str]]:
    """Algorithm 2 for each observation; ``live`` is updated. Returns (touched, deleted)."""
    touched: dict[str, Instance] = {}
    deleted: list[str] = []
    for mo in observations:
        found = match_instances(mo, list(live.values()), cfg)
        if not found:
            inst = new_instance(mo, cfg)
        else:
            target = found[0] if found[0].uuid in touched else _copy(found[0])
            inst = merge_into(target, found[1:], mo, cfg)
            for dup in found[1:]:
                live.pop(dup.uuid, None)
                touched.pop(dup.uuid, None)
                deleted.append(dup.uuid)
        live[inst.uuid] = inst
        touched[inst.uuid] = inst
    return touched, deleted


def _warm_up(method: str) -> None:
    """Load the extractors' libraries now, so the first keyframe's time is not inflated."""
    import cv2  # noqa: F401
    import scipy.sparse.csgraph  # noqa: F401
    import shapely  # noqa: F401

    if method == "ransac":
        import open3d as o3d

        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.random.default_rng(0).random((64, 3))))
        cloud.segment_plane(distance_threshold=0.01, ransac_n=3, num_iterations=10)


class BackgroundStage:
    """Background recognition (paper IV-C/D) as a ``Stage``; options are ``BackgroundConfig`` fields."""

    name = "background"

    def __init__(self, log_path: Any = None, **options: Any) -> None:
        del log_path  # the background needs nothing from the log besides the frames
        self.config = BackgroundConfig.from_options(**options)
        self._last_keyframe_s: float | None = None
        # whether ``prepare`` handed over a next frame since the last ``process``; None while
        # no runner looks ahead (a caller feeding frames itself): no frame is known to be last
        self._next_seen: bool | None = None
        self._not_walls = NotWalls(self.config)
        self._table_votes = TableVotes(self.config)
        self._far_walls = FarWalls(self.config)
        _warm_up(self.config.method)

    def is_keyframe(self, stamp_s: float) -> bool:
        if self._last_keyframe_s is None:
            return True
        return stamp_s - self._last_keyframe_s >= 1.0 / self.config.keyframe_hz - 1e-3

    def prepare(self, frame: Frame) -> None:
        """``run_stages`` hands over the next frame before it processes the current one; a frame
        processed with none handed over is the log's last, and a keyframe: what the robot saw
        last is in the map (a wall seen only in a log's last half second)."""
        del frame
        self._next_seen = True

    def process(self, frame: Frame, world: World) -> FrameResult:
        last = self._next_seen is False
        if self._next_seen is not None:
            self._next_seen = False
        if not (self.is_keyframe(frame.stamp_s) or last):
            return FrameResult(skipped="not a keyframe")
        self._last_keyframe_s = frame.stamp_s
        start, start_cpu = time.perf_counter(), time.process_time()
        observations, open_walls = observe_all(frame, self.config)
        live = dict(world.background)
        vetoed = self._not_walls.veto([to_map(o, frame.T_map_cam) for o in open_walls], live)
        kept = []
        for obs in observations:
            mo = to_map(obs, frame.T_map_cam)
            if obs.class_name == "wall" and self._not_walls.covers(mo):
                continue  # a plane seen ending in the room before: not a wall
            self._far_walls.note(obs)  # seen from too far to tell a wall from a front or a door?
            if "under" in obs.data and not self._table_votes.vote(mo, obs.data["under"]):
                continue  # a top most views saw on a solid front: not a table
            kept.append(mo)
        observations = [mo.obs for mo in kept]
        touched, deleted = merge_observations(kept, live, self.config)
        deleted = vetoed + deleted + self._table_votes.settle(live)
        touched = {uuid: inst for uuid, inst in touched.items() if uuid in live}
        for inst in sighted(frame, [i for u, i in live.items() if u not in touched], self.config):
            touched[inst.uuid] = live[inst.uuid] = inst
        timings = {
            "background_s": time.perf_counter() - start,
            # CPU time of the process (all its threads): what the keyframe costs, whatever else runs
            "background_cpu_s": time.process_time() - start_cpu,
        }
        for obs in observations:  # the keyframe's processing time goes into the knowledge base too
            obs.data["keyframe_s"] = timings["background_s"]
            obs.data["keyframe_cpu_s"] = timings["background_cpu_s"]
        return FrameResult(
            observations=observations,
            instances=list(touched.values()),
            deleted_instances=[u for u in deleted if u in world.background],
            timings_s=timings,
        )

    def finish(self, world: World) -> FrameResult:
        """Withdraw the walls no view saw near enough to tell from a door or a front
        (``wall_range.py``)."""
        return FrameResult(deleted_instances=self._far_walls.unconfirmed(world.background.values()))
