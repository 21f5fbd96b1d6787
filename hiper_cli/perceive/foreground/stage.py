"""The foreground stage: segmentation, detection (in a worker thread), matching and tracking."""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import PerceptionError
from hiper_cli.model import Box3D, Instance, Observation
from hiper_cli.perceive.detect import Detector, check_class_names, make_detector
from hiper_cli.perceive.foreground.amodal import (
    COMPLETE_FOOTPRINTS,
    FLOOR_STANDING,
    LEAST_HEIGHT_M,
    complete_base,
    complete_footprint,
    complete_height,
)
from hiper_cli.perceive.foreground.appearance import histogram
from hiper_cli.perceive.foreground.background_filter import TABLE_LEG_BAND_M, table_leg_boxes
from hiper_cli.perceive.foreground.carried import CARRIED_CLASSES, CARRIED_CONTAINMENT, drop_carried
from hiper_cli.perceive.foreground.class_vote import UNKNOWN, is_question, record_focus, shown_class
from hiper_cli.perceive.foreground.classes import filter_classes, one_name_per_box
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.earlier import meet_earlier
from hiper_cli.perceive.foreground.focus import FocusedLook, Question
from hiper_cli.perceive.foreground.geometry_only import geometry_only
from hiper_cli.perceive.foreground.held import HeldDetections
from hiper_cli.perceive.foreground.hidden import HIDDEN_PARTS, name_hidden
from hiper_cli.perceive.foreground.keyframes import KeyframeLook
from hiper_cli.perceive.foreground.legs import TABLE_LEG_REACH_M, TABLE_RIM_DEPTH_M, drop_table_legs
from hiper_cli.perceive.foreground.match import Match, assign_classes, named_within
from hiper_cli.perceive.foreground.moving import at_rest, has_moved, is_static
from hiper_cli.perceive.foreground.object_views import ObjectViews, name_by_views
from hiper_cli.perceive.foreground.plausible import (
    CLASS_SIZE_TOLERANCE,
    FIXTURE_CLASSES,
    FIXTURE_REACH_M,
    attached,
    longest_m,
    max_longest_m,
    min_longest_m,
)
from hiper_cli.perceive.foreground.priors import LearnedPriors
from hiper_cli.perceive.foreground.refine import refine_blobs
from hiper_cli.perceive.foreground.segment import Blob, segment
from hiper_cli.perceive.foreground.solid_map import SolidMap, is_solid, overlap_share
from hiper_cli.perceive.foreground.supports import floor_height_m, support_boxes
from hiper_cli.perceive.foreground.surface_samples import SurfaceSamples
from hiper_cli.perceive.foreground.table_views import TableViews
from hiper_cli.perceive.foreground.tables import split_unseen_tables
from hiper_cli.perceive.foreground.tracking import Measurement, Track, Tracker, object_box
from hiper_cli.perceive.foreground.unmapped_tables import (
    TABLE_CLASS,
    TABLE_SCORE,
    UNSEEN_TABLE_INSTANCES,
    table_match,
    withdraw_mapped,
)
from hiper_cli.perceive.foreground.vacated import EmptyPlaces
from hiper_cli.perceive.foreground.wall_relief import WallRelief
from hiper_cli.perceive.foreground.whole import (
    FULL_VIEW_COVER,
    FULL_VIEW_MIN_PX2,
    bottom_hidden,
    in_full_view,
    inside_image,
    occluded,
    seen_whole,
    top_hidden,
)
from hiper_cli.perceive.stage import FrameResult, World
from hiper_cli.types import Detections, Frame

__all__ = ["ForegroundStage"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
POINTS_PER_OBSERVATION: int = 64
"""Subsample of ``points_cam`` stored in each observation."""
PIXELS_PER_OBSERVATION: int = 48
"""Sample of pixel coordinates ``pixels_uv`` stored in each observation."""
WALKER_MAX_BASE_M: float = 1.2
"""A blob named by a walker class whose lowest point lies more than this above the floor
(the lowest floor instance's top; the map's z = 0 before one) is no walker: it stays
``unknown`` (0: off). People stand on the floor; behind a counter they still show below."""
WALKER_FROM_FLOOR: bool = True
"""An observation a detection names a walker class spans from the floor to its blob's top
(the centre halfway): people stand on the floor, and a person behind a shelf or a table
shows only the upper body (issue 17: person centres 0.5-0.8 m off in height)."""
SAME_BOX_IOU: float = 0.8
"""Two detections of different classes whose boxes overlap by this IoU are one object the
detector named twice (``classes.one_name_per_box``: a bottle and a vase, a bench and a
chair): the one with the higher score stays; ``walker_classes`` are left out; 1: off."""

FloatArray = NDArray[np.float64]
# Named constants (not the paper's): chosen so that they never bind on the simulated worlds.
OCCLUSION_MARGIN_M = 0.5  # a predicted centre this far behind the measured depth is hidden
HIDDEN_MARGIN_M = 0.1  # a point on a surface this far behind the measured depth is hidden
PIECE_SHARE = 0.8  # a named box this much inside another's is a piece of that object


@lru_cache(maxsize=4096)
def _spread(n: int, k: int) -> NDArray[np.int64]:
    """``min(n, k)`` indices evenly spread over ``range(n)`` (the organised grid order:
    deterministic, cheap; at least one apart, so no duplicates). Cached: read-only."""
    idx = np.linspace(0, n - 1, min(n, k)).astype(np.int64)
    idx.setflags(write=False)
    return idx


class ForegroundStage:
    """Foreground recognition of the HIPer model (paper IV-E to IV-H) as a pipeline ``Stage``.

    ``ForegroundStage(log_path=..., **options)``: ``options`` are the fields of
    ``ForegroundConfig`` (unknown names raise ``ConfigError``); ``log_path`` is the log being
    processed (the ``truth`` detector reads ``LOG/gt``). ``detector_instance`` replaces the
    registry lookup (tests, embedding).
    """

    name = "foreground"

    def __init__(
        self,
        log_path: str | Path | None = None,
        detector_instance: Detector | None = None,
        **options: Any,
    ) -> None:
        self.config = ForegroundConfig.from_options(**options)
        cfg = self.config
        # Import the heavy modules now, not inside the first frame's timing.
        import scipy.optimize
        import scipy.sparse.csgraph  # noqa: F401

        self.detector: Detector = detector_instance or make_detector(cfg.detector, log_path=log_path)
        check_class_names(cfg.classes, cfg.exclude_classes, self.detector, cfg.detector)
        # the ``log`` detector reads the log's own detections: perceive checks the log has them
        self.needs_log_detections = cfg.detector == "log"
        self._pool: ThreadPoolExecutor | None = None
        self._ahead: dict[int, tuple[Frame, Future[tuple[Detections | None, float]]]] = {}
        self._held = HeldDetections()  # the last quick look's, for the frames between (``held.py``)
        self._looked = True  # whether the detector looked at this frame (``_detections``)
        self._priors = LearnedPriors(cfg)
        self._floor_z_m = 0.0  # floor_height_m of the world, per frame (``_stands``)
        self._floor_mapped = False  # the background found a floor (``complete_base``)
        self.tracker = Tracker(cfg, self._priors.class_prior)
        self._instances: dict[str, Instance] = {}
        self._walls: list[Box3D] = []  # the background's walls, as of the latest frame
        self._empty: EmptyPlaces | None = None  # earlier sessions' static objects, seen empty?
        # whether the earlier sessions saw something inside a box (set by the caller, who has
        # the place's cloud): an object found there was not moved there (``_reidentify``)
        self.occupied_before: Callable[[Instance], bool] | None = None
        self._surfaces = SurfaceSamples()  # per track, points of its blobs: ``data["surface_map"]``
        self._solid = SolidMap()  # solid surfaces fused at keyframes: geometry-only objects
        self._relief = WallRelief()  # ... and what stands proud of the walls: objects hung there
        self._table_views = TableViews(cfg.min_detection_score)  # names for the mapped tables' bodies
        self._views = ObjectViews(cfg.min_detection_score, cfg.walker_classes)  # ... and unnamed objects'
        # the quick look at cfg.detector_hz, the closer look at the static scene at keyframes
        self._keyframes = KeyframeLook(self.detector, cfg.detector, cfg.detector_hz)
        # a crop around a track the every-frame looks left a question, a few times a second
        self._focus = FocusedLook(self.detector, self._keyframes.looks_at_images)
        self._measured: list[Blob | None] = []  # this frame's blob per measurement (``_focused``)
        self._large: list[Blob] = []  # this frame's clusters too large for one object (``_segment``)

    def _stands(self, class_name: str, blob: Blob) -> bool:
        """False for a walker-class blob whose lowest point is more than ``WALKER_MAX_BASE_M``
        above the floor: people stand on it, and even behind a counter their visible part
        reaches below that (a person detection on a poster, a shelf's top or a reflection)."""
        cfg = self.config
        if class_name not in cfg.walker_classes:
            return True
        if WALKER_MAX_BASE_M <= 0:
            return True
        return float(blob.bounds_map[0][2]) - self._floor_z_m <= WALKER_MAX_BASE_M

    def _standing_box(self, blob: Blob) -> tuple[FloatArray, FloatArray] | None:
        """The blob's box if it were a walker (``walker_from_floor``): from the floor to the
        blob's top. A person seen over a shelf or a table shows only the upper body, whose
        centre lies far above the person's; people stand on the floor."""
        if not WALKER_FROM_FLOOR:
            return None
        top = float(blob.bounds_map[1][2])
        if top <= self._floor_z_m:
            return None
        center = blob.center_map_m.copy()
        extent = blob.extent_map_m.copy()
        center[2] = (self._floor_z_m + top) / 2.0
        extent[2] = top - self._floor_z_m
        return center, extent

    # --- the stage --------------------------------------------------------------------------
    def _detect_timed(self, frame: Frame, look: bool, tile: int | None) -> tuple[Detections | None, float]:
        """The frame's detections when the quick look runs on it (else None: ``held.py``); and the
        closer look at its ``tile`` of a keyframe (``keyframes.py``)."""
        t0 = time.perf_counter()
        dets = self.detector.detect(frame) if look else None
        if tile is not None:
            self._keyframes.look(frame, tile)
        return dets, time.perf_counter() - t0

    def _submit(self, frame: Frame) -> Future[tuple[Detections | None, float]]:
        look, tile = self._keyframes.schedule(frame)
        if not look and tile is None:  # nothing for the worker
            done: Future[tuple[Detections | None, float]] = Future()
            done.set_result((None, 0.0))
            return done
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="hiper-detect")
        return self._pool.submit(self._detect_timed, frame, look, tile)

    def prepare(self, frame: Frame) -> None:
        """Start the detector on the next frame (``run_stages`` hands it over before it
        processes the current one): the worker thread detects while this thread segments."""
        if self.config.detector_threads:
            self._ahead[id(frame)] = (frame, self._submit(frame))

    def process(self, frame: Frame, world: World) -> FrameResult:
        """One frame: segment the depth into blobs, name them with the detections, measure them
        and track them (associate, fuse, move); the changed instances and their observations."""
        clock = [time.perf_counter()]
        future = self._detection_of(frame)
        self._priors.refresh(world)
        if self.config.reidentify:
            self._look_for_earlier(frame, world)
        scene = self._read_background(world)
        blobs, seg = self._segment(frame, scene)
        clock.append(time.perf_counter())
        dets, detect_s = self._detections(frame, future)
        clock.append(time.perf_counter())
        blobs, found_tables, dets = self._split_and_refine(frame, scene, blobs, dets)
        clock.append(time.perf_counter())
        observations, measurements, surfaces = self._measure(frame, scene, blobs, dets, found_tables)
        clock.append(time.perf_counter())
        instances, merged = self._track(frame, scene, (observations, measurements, surfaces))
        clock.append(time.perf_counter())
        return FrameResult(observations=observations, instances=instances, deleted_instances=merged,
                           timings_s=_timings(clock, detect_s, seg))

    def _detection_of(self, frame: Frame) -> Future[tuple[Detections | None, float]] | None:
        """The detector's work on ``frame``: started ahead by ``prepare``, started now in the
        worker, or None (``detector_threads`` off: detect in this thread)."""
        ahead = self._ahead.pop(id(frame), None)
        if ahead is not None and ahead[0] is frame:
            return ahead[1]
        return self._submit(frame) if self.config.detector_threads else None

    def _detections(
        self, frame: Frame, future: Future[tuple[Detections | None, float]] | None
    ) -> tuple[Detections, float]:
        """The frame's detections (waiting for the worker; the last look's, held, when the detector
        did not look at it: ``held.py``), with the classes the stage names, one name per box and no
        object carried by a person; and the detector's time (s)."""
        cfg = self.config
        if future is not None:
            try:
                dets, detect_s = future.result()
            except Exception as err:
                where = frame.source or f"frame {frame.pose_id}"
                raise PerceptionError(f"detector {self.detector.name!r} failed on {where}: {err}") from err
        else:
            dets, detect_s = self._detect_timed(frame, *self._keyframes.schedule(frame))
        self._looked = dets is not None
        if dets is None:
            dets = self._held.at(frame)
        else:
            self._held.keep(frame, dets)
            self._table_views.add(frame, dets)
        self._keyframes.join(frame, dets)
        tables = dets  # the table boxes the class filters drop name unnamed objects too (``object_views``)
        dets = filter_classes(dets, cfg.classes, cfg.exclude_classes)
        dets = one_name_per_box(dets, SAME_BOX_IOU, cfg.walker_classes)
        dets = drop_carried(dets, CARRIED_CLASSES, cfg.walker_classes, CARRIED_CONTAINMENT,
                            cfg.min_detection_score)
        self._views.add(frame, dets, self._looked, tables)
        return dets, detect_s

    def _read_background(self, world: World) -> _Background:
        """What the background layer knows now, as this frame's steps read it; the walls and the
        floor's height are kept for the boxes of the instances (``_box``, ``_stands``)."""
        cfg = self.config
        background = list(world.background.values())
        self._walls = _wall_boxes(world)
        self._floor_z_m = floor_height_m(background)
        self._floor_mapped = any(inst.class_name == "floor" for inst in background)
        tables = [inst for inst in background if inst.class_name == "table"]
        dropped = [inst.box for inst in background] if cfg.background_filter else []
        if cfg.background_filter and TABLE_LEG_BAND_M > 0:
            for inst in tables:
                dropped.extend(table_leg_boxes(inst.box, TABLE_LEG_BAND_M))
        return _Background(dropped, support_boxes(background), [inst.box for inst in tables],
                           support_boxes(tables))

    def _segment(self, frame: Frame, scene: _Background) -> tuple[list[Blob], Any]:
        """The frame's blobs (``segment.py``), without the legs of mapped tables."""
        cfg = self.config
        blobs, seg = segment(
            frame.depth_m, frame.camera, frame.T_map_cam, scene.dropped, cfg, scene.supports,
            keep_fragments=cfg.detection_join,
        )
        if cfg.background_filter:
            blobs = drop_table_legs(
                blobs, scene.tables, cfg, cfg.pixel_step, frame.camera.width, frame.camera.height
            )
        self._large = seg.large  # too large for an object, not for the static map (``_measure``)
        return blobs, seg

    def _split_and_refine(
        self, frame: Frame, scene: _Background, blobs: list[Blob], dets: Detections
    ) -> tuple[list[Blob], list[Blob], Detections]:
        """The blobs split from the tables the background has not mapped (``tables.py``), and
        trimmed and joined with the detections (``refine.py``); those tables' blobs; the
        detections without those that named a table (none names what remains of its blob)."""
        cfg = self.config
        width, height = frame.camera.width, frame.camera.height
        ok = dets.scores >= cfg.min_detection_score if len(dets) else np.zeros(0, dtype=bool)
        usable = dets.xyxy[ok] if len(dets) else np.zeros((0, 4))
        names = [n for n, keep in zip(dets.class_names, ok, strict=True) if keep]
        found_tables: list[Blob] = []
        if cfg.background_filter:
            blobs, found_tables, lookalikes = split_unseen_tables(blobs, usable, names, cfg, width, height)
            if lookalikes:
                dets, ok, usable, names = _without(dets, ok, np.flatnonzero(ok)[lookalikes])
            if TABLE_RIM_DEPTH_M > 0:
                blobs = drop_table_legs(blobs, scene.tables, cfg, cfg.pixel_step, width, height, rims=True)
        if cfg.detection_split or cfg.detection_join:
            blobs = refine_blobs(blobs, usable, cfg, width, height, scene.supports, classes=names,
                                 size_tolerance=CLASS_SIZE_TOLERANCE if cfg.class_sizes else None)
        return blobs, found_tables, dets

    def _measure(
        self, frame: Frame, scene: _Background, blobs: list[Blob], dets: Detections, found_tables: list[Blob]
    ) -> tuple[list[Observation], list[Measurement], list[FloatArray | None]]:
        """Per blob kept: its observation, its measurement for the tracker and its map points
        (None for a walker's: no surface is kept of what moves)."""
        cfg = self.config
        matches = assign_classes(
            np.array([b.image_box_xyxy for b in blobs]).reshape(-1, 4),
            dets,
            iou_threshold=cfg.iou_threshold,
            min_score=cfg.min_detection_score,
            unknown=UNKNOWN,
        )
        if HIDDEN_PARTS:  # the visible part of an object hidden in part (``hidden.py``)
            matches = name_hidden(
                matches, [b.pixels_uv for b in blobs], [b.points_cam[:, 2] for b in blobs], dets,
                frame, cfg.pixel_step, min_score=cfg.min_detection_score,
                floor_z_m=self._floor_z_m if self._floor_mapped else None,
            )
        observations: list[Observation] = []
        measurements: list[Measurement] = []
        surfaces: list[FloatArray | None] = []
        self._measured = []
        keyframe = self._solid.due(frame.stamp_s, frame.T_map_cam)
        # a keyframe's solid blobs but walkers' (``SolidMap``), those too large for one object too
        # (their points within the sensor's range: the slack beyond is for objects across it)
        held = [("", b.points_map[b.points_cam[:, 2] <= cfg.max_depth_m])
                for b in self._large if keyframe and is_solid(b.points_cam)]
        for blob, match in zip(blobs, matches, strict=True):
            match, longest = self._judged(frame, scene, blob, match)
            if match.detection_index is None and not cfg.keep_unknown:
                continue
            obs = self._observation(frame, blob, match, dets)
            observations.append(obs)
            if keyframe and match.class_name not in cfg.walker_classes and is_solid(blob.points_cam):
                held.append((obs.uuid, blob.points_map))
            surfaces.append(None if match.class_name in cfg.walker_classes else blob.points_map)
            measurement = self._measurement(frame, blob, match, dets, (obs, longest))
            closer = self._closer_class(frame, scene, blob)  # a keyframe's closer look (``keyframes.py``)
            measurements.append(measurement if closer is None else replace(measurement, closer_class=closer))
            self._measured.append(None if measurement.cut_by_border else blob)
        for blob in found_tables if UNSEEN_TABLE_INSTANCES else []:
            obs = self._observation(frame, blob, table_match(), dets)
            observations.append(obs)
            surfaces.append(blob.points_map)
            measurements.append(Measurement(blob.center_map_m, blob.extent_map_m, TABLE_CLASS, TABLE_SCORE,
                                            obs.uuid, bounds_map_m=_corners(blob)))
            self._measured.append(None)
        if keyframe:
            self._solid.add(frame, held)
            self._relief.add(frame, self._walls)
        return observations, measurements, surfaces

    def _judged(
        self, frame: Frame, scene: _Background, blob: Blob, match: Match
    ) -> tuple[Match, float | None]:
        """``match`` as the checks of a named class leave it (``unknown`` when the class's
        learned priors, standing, size or attachment rule the blob out), and
        the blob's longest side when it tells the class's size (seen whole; else None)."""
        cfg = self.config
        if match.detection_index is None:
            return match, None
        longest = longest_m(blob.points_map, float(blob.extent_map_m[2])) if cfg.class_sizes else None
        if not (
            self._priors.fits(match.class_name, blob, frame)
            and self._stands(match.class_name, blob)
            and (longest is None or longest <= max_longest_m(match.class_name, CLASS_SIZE_TOLERANCE))
            and (match.class_name not in FIXTURE_CLASSES
                 or attached(blob.points_map, self._walls, scene.tops, FIXTURE_REACH_M))
        ):
            return Match(UNKNOWN, 0.0, None, match.iou), None
        if longest is not None and min_longest_m(match.class_name, CLASS_SIZE_TOLERANCE) > 0 and (
            not inside_image(blob, cfg.pixel_step, frame.camera)
            or occluded(blob, frame.depth_m, frame.camera, frame.T_map_cam, cfg.pixel_step)
        ):
            longest = None  # cut by the border or hidden in part: no view of its whole length
        return match, longest

    def _measurement(
        self, frame: Frame, blob: Blob, match: Match, dets: Detections,
        seen: tuple[Observation, float | None],
    ) -> Measurement:
        """The tracker's measurement of a blob; ``seen``: its observation and its longest side
        (``_judged``)."""
        cfg = self.config
        obs, longest = seen
        full = cfg.refused_min_views > 0 and in_full_view(
            blob, frame.depth_m, frame.camera, frame.T_map_cam, cfg.pixel_step, FULL_VIEW_MIN_PX2
        )
        walker = match.class_name in cfg.walker_classes
        return Measurement(
            blob.center_map_m, blob.extent_map_m, match.class_name, match.score, obs.uuid,
            whole=match.detection_index is not None
            or seen_whole(blob, cfg, frame.camera, (frame.depth_m, frame.T_map_cam)),
            appearance=histogram(frame.rgb, blob.pixels_uv) if walker else None,
            standing=self._standing_box(blob),  # a walking track takes any blob as standing
            bounds_map_m=_corners(blob),
            longest_m=longest,
            detection_index=match.detection_index,
            detection_xyxy_px=None if match.detection_index is None else dets.xyxy[match.detection_index],
            viewpoint_map_m=frame.T_map_cam[:3, 3],
            top_hidden=COMPLETE_FOOTPRINTS and match.class_name in LEAST_HEIGHT_M
            and top_hidden(blob, frame.depth_m, cfg.pixel_step),
            bottom_hidden=COMPLETE_FOOTPRINTS and match.class_name in FLOOR_STANDING
            and bottom_hidden(blob, frame.depth_m, cfg.pixel_step),
            full_view=full,
            cut_by_border=not inside_image(blob, cfg.pixel_step, frame.camera),
            named_within=named_within(
                blob.image_box_xyxy, dets, min_score=cfg.min_detection_score, min_cover=FULL_VIEW_COVER,
            ) if full else frozenset(),
        )

    def _closer_class(self, frame: Frame, scene: _Background, blob: Blob) -> str | None:
        """The class a keyframe's closer look gives ``blob`` when its tile held it whole
        (``keyframes.py``), by the same matching and checks as every frame's; None: no such look."""
        dets = self._keyframes.closer_detections(frame, blob.image_box_xyxy)
        return None if dets is None else self._class_from(frame, scene, blob, dets)

    def _class_from(self, frame: Frame, scene: _Background, blob: Blob, dets: Detections) -> str:
        """The class a look's detections ``dets`` give ``blob``, by the same matching and checks
        as every frame's."""
        cfg = self.config  # the classes the stage names, one name per box (as ``_detections``)
        dets = filter_classes(dets, cfg.classes, cfg.exclude_classes)
        dets = one_name_per_box(dets, SAME_BOX_IOU, cfg.walker_classes)
        dets = drop_carried(dets, CARRIED_CLASSES, cfg.walker_classes, CARRIED_CONTAINMENT,
                            cfg.min_detection_score)
        (match,) = assign_classes(blob.image_box_xyxy.reshape(1, 4), dets, iou_threshold=cfg.iou_threshold,
                                  min_score=cfg.min_detection_score, unknown=UNKNOWN)
        return self._judged(frame, scene, blob, match)[0].class_name

    def _focused(self, frame: Frame, scene: _Background, joined: list[str | None]) -> None:
        """The focused looks this frame may spend (``focus.py``), on the tracks that are a
        question and whose blob this frame shows inside the image; their answers counted."""
        budget = self._focus.due(frame.stamp_s)
        if not budget:
            return
        tracks = {t.uuid: t for t in self.tracker.tracks}
        questions: list[Question] = []
        blobs: dict[str, Blob] = {}
        for blob, uuid in zip(self._measured, joined, strict=True):
            track = tracks.get(uuid) if uuid is not None and blob is not None else None
            if track is not None and blob is not None and is_question(track):
                questions.append(Question(track.uuid, sum(track.focus_counts.values()), blob.image_box_xyxy))
                blobs[track.uuid] = blob
        for question in self._focus.pick(questions, budget):
            dets = self._focus.look(frame, question.xyxy)
            if dets is not None:
                class_name = self._class_from(frame, scene, blobs[question.uuid], dets)
                record_focus(tracks[question.uuid], class_name)

    def _track(
        self, frame: Frame, scene: _Background,
        measured: tuple[list[Observation], list[Measurement], list[FloatArray | None]],
    ) -> tuple[list[Instance], list[str]]:
        """Track the frame's measurements; their observations get their instance, the tracks'
        surfaces their points. The instances changed and the uuids of those merged away (a
        track stitched into another, one whose evidence failed, a table the background mapped)."""
        observations, measurements, surfaces = measured
        changed, joined = self.tracker.step(frame.stamp_s, measurements, self._visibility(frame))
        self._focused(frame, scene, joined)
        tables_withdrawn = (
            withdraw_mapped(self.tracker, scene.tables, TABLE_LEG_REACH_M)
            if UNSEEN_TABLE_INSTANCES else []
        )
        if tables_withdrawn:  # the background layer mapped them: its instance is the table
            changed = [t for t in changed if t.uuid not in tables_withdrawn]
        confirmed = {t.uuid for t in self.tracker.tracks if t.confirmed}
        for obs, points, track_uuid in zip(observations, surfaces, joined, strict=True):
            if track_uuid in confirmed:
                obs.instance_uuid = track_uuid
            if points is not None and track_uuid is not None:
                self._surfaces.add(track_uuid, points)
        instances = [self._instance(t) for t in changed]
        # a track closed for good has its instance's surface already (tentative ones: none)
        self._surfaces.keep({t.uuid for t in (*self.tracker.tracks, *self.tracker.dormant)})
        gone = [*self.tracker.absorbed, *self.tracker.withdrawn, *tables_withdrawn]
        return instances, [u for u in gone if self._instances.pop(u, None) is not None]

    def finish(self, world: World) -> FrameResult:
        tracks = [*self.tracker.tracks, *self.tracker.dormant]
        closed = self.tracker.close_all()
        self._ahead.clear()
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None
        gone = [u for u in self.tracker.withdrawn if self._instances.pop(u, None) is not None]
        self._walls = _wall_boxes(world)
        instances = [self._instance(t) for t in closed]
        unconfirmed = self._unconfirmed()
        instances = [i for i in instances if i.uuid not in unconfirmed]
        gone += [u for u in unconfirmed if self._instances.pop(u, None) is not None]
        folded, grown = self._fold_pieces()
        instances = [i for i in instances if i.uuid not in folded]
        instances += [i for i in grown if all(i is not j for j in instances)]
        gone += folded
        counts: dict[str, int] = {}
        if self.config.reidentify:
            static = {t.uuid for t in tracks if t.confirmed and is_static(t, self.tracker.config)}
            earlier, absorbed, counts = self._reidentify(world, static)
            instances = [i for i in instances if i.uuid not in absorbed] + earlier
            gone += absorbed
        instances += [i for i in self._geometry_only(world, instances) if all(i is not j for j in instances)]
        renamed = name_by_views(self._views, [*self._instances.values(), *instances], world, gone,
                                self.config)  # the unnamed objects, by their views
        instances += [i for i in renamed if all(i is not j for j in instances)]
        return FrameResult(instances=instances, deleted_instances=gone, counts=counts)

    def _fold_pieces(self) -> tuple[list[str], list[Instance]]:
        """One place, one object: a static named instance whose box lies for ``PIECE_SHARE``
        inside the box of a static instance of another named class seen in more views is a
        piece of it (a couch's end taken for a chair); its views join that one's. Returns the
        uuids folded away and the instances that took their views."""
        walkers = self.tracker.config.walker_classes
        named = [i for i in self._instances.values()
                 if i.state == "static" and i.class_name != UNKNOWN and i.class_name not in walkers]
        folded: list[str] = []
        grown: list[Instance] = []
        for piece in sorted(named, key=lambda i: len(i.observation_uuids)):
            wholes = [i for i in named if i.class_name != piece.class_name and i.uuid not in folded
                      and len(i.observation_uuids) > len(piece.observation_uuids)
                      and overlap_share(piece.box, i.box) >= PIECE_SHARE]
            if wholes:
                whole = max(wholes, key=lambda i: len(i.observation_uuids))
                whole.observation_uuids = [*whole.observation_uuids, *piece.observation_uuids]
                folded.append(piece.uuid)
                grown.append(whole)
        for uuid in folded:
            del self._instances[uuid]
        return folded, [i for i in grown if i.uuid not in folded]

    def _unconfirmed(self) -> set[str]:
        """The static ``unknown`` instances whose surface no second keyframe of the map of solid
        things saw again, and a later one saw through (``SolidMap.confirmed``): the evidence
        says something unnamed is not there."""
        return {i.uuid for i in self._instances.values()
                if i.class_name == UNKNOWN and i.state == "static" and not self._solid.confirmed(i.box)}

    def _geometry_only(self, world: World, instances: list[Instance]) -> list[Instance]:
        """The instances of what the depth shows solid and no instance holds: ``unknown``, or
        ``table`` for a mapped table's body the detector named (``geometry_only.py``)."""
        own = [*self._instances.values(), *instances]
        taken = [i.box for i in (*world.foreground.values(), *own) if i.layer == "foreground"]
        return geometry_only(list(world.background.values()), taken, own, self._solid, self._relief,
                             self._table_views, self.config.min_class_observations)

    def _stays(self, inst: Instance) -> bool:
        """An object that stays where it was left: not a walker, nor an ``unknown`` that walked (a
        chair pushed across the room stays where it was pushed)."""
        if inst.class_name in self.tracker.config.walker_classes:
            return False
        return inst.class_name != UNKNOWN or inst.state == "static"

    def _look_for_earlier(self, frame: Frame, world: World) -> None:
        """Whether this frame saw the places of earlier sessions' static objects empty."""
        if self._empty is None:  # the first frame: the world holds earlier sessions' instances only
            self._empty = EmptyPlaces([i for i in world.foreground.values() if self._stays(i)])
        if self._empty.uuids:
            self._empty.look(self._projector(frame), frame.T_map_cam[:3, 3], frame.stamp_s)

    def _reidentify(self, world: World, static: set[str]) -> tuple[list[Instance], list[str], dict[str, int]]:
        """Earlier sessions' instances found again, moved or vacated (``earlier.py``), the uuids
        of this session's instances they absorbed, and the counts of each."""
        tracking = self.tracker.config
        return meet_earlier(
            self._instances, world.foreground, static, stays=self._stays,
            vacated=self._empty.vacated() if self._empty is not None else {},
            occupied=self.occupied_before or (lambda _: False),
            walkers=tracking.walker_classes, confirm_hits=tracking.confirm_hits,
        )

    # --- conversions ------------------------------------------------------------------------
    def _observation(self, frame: Frame, blob: Blob, match: Match, dets: Detections) -> Observation:
        n = len(blob.points_cam)
        pts_idx = _spread(n, POINTS_PER_OBSERVATION)
        pix_idx = _spread(n, PIXELS_PER_OBSERVATION)
        detection = None
        if match.detection_index is not None:
            k = match.detection_index
            detection = {
                "xyxy": [float(v) for v in dets.xyxy[k]],
                "class": dets.class_names[k],
                "score": float(dets.scores[k]),
                "iou": match.iou,
            }
            if not self._looked:
                detection["held"] = True  # the last look's, moved to this view (``held.py``)
        return Observation(
            layer="foreground",
            class_name=match.class_name,
            confidence=match.score,
            stamp_s=frame.stamp_s,
            pose_id=frame.pose_id,
            box=Box3D.from_points(blob.points_cam),
            data={
                "image_box_xyxy": [float(v) for v in blob.image_box_xyxy],
                "points_cam": np.round(blob.points_cam[pts_idx], 4).tolist(),
                "pixels_uv": blob.pixels_uv[pix_idx].tolist(),
                "center_map": [float(v) for v in blob.center_map_m],
                "num_points": n,
                "detection": detection,
            },
        )

    def _instance(self, track: Track) -> Instance:
        state = "dynamic" if has_moved(track, self.tracker.config) else "static"
        box = self._box(track)
        inst = self._instances.get(track.uuid)
        if inst is None:
            inst = Instance(
                layer="foreground",
                class_name=shown_class(track),
                box=box,
                first_seen_s=track.first_seen_s,
                last_seen_s=track.last_update_s,
                uuid=track.uuid,
                observation_uuids=track.observation_uuids,
                data={"trajectory": track.trajectory},
            )
            self._instances[track.uuid] = inst
        inst.class_name = shown_class(track)  # the tracker's class, when the views support it
        inst.box = box
        inst.last_seen_s = track.last_update_s
        inst.state = state  # type: ignore[assignment]
        # motion needs evidence: a static object stood at its fused centre all along, whatever
        # the filter read from its partial views (its stored speed is 0, its path a point)
        inst.data["trajectory"] = track.trajectory if state == "dynamic" else at_rest(track.trajectory, box)
        inst.confidence = track.confidence
        inst.data["closed"] = track.closed
        if track.closed and self._stays(inst) and (points := self._surfaces.of(track.uuid)):
            inst.data["surface_map"] = points  # for a later session's empty-place test
        return inst

    def _box(self, track: Track) -> Box3D:
        """The instance's box: ``object_box``; a static object's completed behind the faces seen,
        down to the floor when no view showed where it stands, and up to its class's least height
        when no view showed its top (``amodal.py``)."""
        centre, extent = object_box(track, self.tracker.config)
        if COMPLETE_FOOTPRINTS and is_static(track, self.tracker.config):
            lower, upper = complete_footprint(centre - extent / 2.0, centre + extent / 2.0, track.class_name,
                                              track.seen.viewpoint(), self._walls)
            if self._floor_mapped:
                lower, upper = complete_base(lower, upper, track.class_name, track.seen.bottom_seen(),
                                             self._floor_z_m)
            lower, upper = complete_height(lower, upper, track.class_name, track.seen.top_seen())
            centre, extent = (lower + upper) / 2.0, upper - lower
        return Box3D(centre, extent)

    def _projector(self, frame: Frame) -> Any:
        """A function taking map points (N, 3) to (in the camera's view: image and depth range,
        their depth z (m), the depth measured at their pixel (m, 0: no return))."""
        T_cam_map = np.linalg.inv(frame.T_map_cam)
        cam, depth, cfg = frame.camera, frame.depth_m, self.config

        def project(points_map: FloatArray) -> tuple[NDArray[np.bool_], FloatArray, FloatArray]:
            p = points_map @ T_cam_map[:3, :3].T + T_cam_map[:3, 3]
            z = p[:, 2]
            ok = (z > cfg.min_depth_m) & (z < cfg.max_depth_m)
            u = np.where(ok, cam.fx * p[:, 0] / np.where(ok, z, 1.0) + cam.cx, -1.0)
            v = np.where(ok, cam.fy * p[:, 1] / np.where(ok, z, 1.0) + cam.cy, -1.0)
            ok &= (u >= 0) & (u < cam.width) & (v >= 0) & (v < cam.height)
            ui = np.clip(u.astype(int), 0, cam.width - 1)
            vi = np.clip(v.astype(int), 0, cam.height - 1)
            return ok, z, depth[vi, ui]

        return project

    def _visibility(self, frame: Frame) -> Any:
        """A function telling which map points the camera sees now (in image, not occluded)."""
        project = self._projector(frame)

        def visible(points_map: FloatArray) -> NDArray[np.bool_]:
            ok, z, measured = project(points_map)
            occluded = (measured > 0) & (measured < z - OCCLUSION_MARGIN_M)
            return np.asarray(ok & ~occluded)

        return visible


def _without(
    dets: Detections, ok: NDArray[np.bool_], drop: NDArray[np.int64]
) -> tuple[Detections, NDArray[np.bool_], FloatArray, list[str]]:
    """``dets`` without the detections ``drop``, and its usable mask, boxes and class names."""
    keep = np.ones(len(dets), dtype=bool)
    keep[drop] = False
    kept = dets.subset(keep)
    ok = ok[keep]
    return kept, ok, kept.xyxy[ok], [n for n, k in zip(kept.class_names, ok, strict=True) if k]


@dataclass(frozen=True)
class _Background:
    """The background layer as one frame's foreground steps read it (map frame)."""

    dropped: list[Box3D]  # boxes whose points are background (with the bands of table legs)
    supports: list[Box3D]  # floors and table tops objects stand on (``support_boxes``)
    tables: list[Box3D]  # the mapped tables' boxes
    tops: list[Box3D]  # the mapped tables' tops


def _timings(clock: list[float], detect_s: float, seg: Any) -> dict[str, float]:
    """The frame's timings (s) from the ``process`` clock: start, segmented, detected, refined,
    measured, tracked."""
    start, segmented, detected, refined, measured, tracked = clock
    timings = {f"foreground_{k}": v for k, v in seg.timings_s.items()}
    timings.update(
        {
            "foreground_segment_s": segmented - start,
            "foreground_detect_s": detect_s,
            "foreground_detect_wait_s": detected - segmented,
            "foreground_refine_s": refined - detected,
            "foreground_match_s": measured - refined,
            "foreground_track_s": tracked - measured,
            "foreground_s": tracked - start,
            "foreground_points": float(seg.points),
            "foreground_points_after_background": float(seg.after_background),
        }
    )
    return timings


def _wall_boxes(world: World) -> list[Box3D]:
    return [inst.box for inst in world.background.values() if inst.class_name == "wall"]


def _corners(blob: Blob) -> tuple[FloatArray, FloatArray]:
    """(lower, upper) corners of ``blob``'s box, map frame, down to its support when the
    background filter cut its base."""
    lo, hi = blob.bounds_map
    centre, extent = blob.center_map_m, blob.extent_map_m
    lo, hi = lo.copy(), hi.copy()
    lo[2], hi[2] = centre[2] - extent[2] / 2.0, centre[2] + extent[2] / 2.0
    return lo, hi

