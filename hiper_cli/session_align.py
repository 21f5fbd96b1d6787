"""A session joins its place: the log's frame is aligned to the place's map before perception.

``perceive --align auto`` (the default): the first session of a place defines its map frame;
every later one is registered to the place's background cloud (``perceive.align``) from frames
spread over its log, and refused when it does not fit; that transform is then refined on the
log's first metres, where its odometry has not drifted yet (``perceive.align_start``), in the
directions the start constrains, and kept as it was when the refinement finds too little or
moves it too far. Along its path the log then drifts away from the map (and the map's own
session drifted too): ``correct_drift`` re-localises it on the map every metre of motion
(``perceive.align_path``), so each frame gets its own, smoothly varying transform and what the
session sees is compared with the map where both agree. ``--align none`` takes the log's poses
as map-frame poses; ``--align FILE`` reads ``T_map_log`` (a 4×4 matrix, JSON or 16 numbers).
Frames are then handed to the stages with ``T_map_cam = T_map_log · T_log_cam``, so everything
stored is in the place's one map frame; and during the run the session's own background adds
to the place's cloud (``MapCloudGrower``).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.errors import ConfigError, KnowledgeBaseError
from hiper_cli.graph import KnowledgeBase
from hiper_cli.graph.sessions import Alignment
from hiper_cli.model import Environment
from hiper_cli.perceive.align import BackgroundCloud, register
from hiper_cli.perceive.align_path import PathCorrection, correct_path, motion_m
from hiper_cli.perceive.align_start import refine_at_start
from hiper_cli.perceive.logs.trajectory import rotation_angle_rad
from hiper_cli.perceive.static_cloud import StaticCloud
from hiper_cli.types import Frame

__all__ = ["ALIGN_FRAMES", "MIN_FITNESS", "MapCloudGrower", "aligned", "choose_alignment", "correct_drift"]

ALIGN_FRAMES = 40  # frames spread over the log make its cloud
MIN_FITNESS = 0.4  # below this share of the log's background on the map, the log is refused
CLOUD_EVERY_S = 0.5  # the place's cloud takes a frame this often
START_MOTION_M = 3.0  # the start's cloud: frames until the log moved this far (0.5 m a radian turned)
START_STEP_M = 0.1  # ... one frame per this much motion
START_MIN_INLIERS = 0.3  # below this share of the start's points on the map, the start is not used
START_MAX_CHANGE = (0.25, 3.0)  # metres, degrees: a larger correction of the whole-log fit is refused


def _read_matrix(path: Path) -> np.ndarray:
    try:
        text = path.read_text()
    except OSError as err:
        raise ConfigError(f"--align {path}: cannot read it ({err.strerror}); pass none, auto or a file "
                          "with a 4x4 matrix") from err
    try:
        values = np.asarray(json.loads(text), dtype=np.float64)
    except ValueError:
        try:
            values = np.asarray([float(v) for v in text.replace(",", " ").split()], dtype=np.float64)
        except ValueError:
            values = np.zeros(0)
    if values.size != 16 or not np.allclose(values.reshape(4, 4)[3], [0, 0, 0, 1]):
        raise ConfigError(f"--align {path}: expected a 4x4 rigid transform T_map_log (JSON or 16 numbers, "
                          "last row 0 0 0 1)")
    return values.reshape(4, 4)


def log_cloud(reader: Any, n: int = ALIGN_FRAMES) -> np.ndarray:
    """The log's background cloud in its own frame, from ``n`` frames spread over it."""
    cloud = BackgroundCloud()
    total = len(reader)
    for k in np.unique(np.linspace(0, max(total - 1, 0), min(n, total)).astype(int)):
        cloud.add_frame(reader.read_frame(int(k)))
    return cloud.points()


def start_cloud(reader: Any) -> np.ndarray:
    """The background cloud (log frame) of the log's first ``START_MOTION_M`` of motion, one
    frame per ``START_STEP_M``: where the log's poses have drifted least."""
    poses = reader.info().T_map_cam if hasattr(reader, "info") else None
    cloud = BackgroundCloud()
    travelled, since, last = 0.0, np.inf, None
    for k in range(len(reader)):
        if poses is not None and last is not None:
            moved = motion_m(poses[last], poses[k])
            travelled, since = travelled + moved, since + moved
        if travelled > START_MOTION_M:
            break
        if since >= START_STEP_M or poses is None:
            cloud.add_frame(reader.read_frame(k))
            since = 0.0
        last = k
    return cloud.points()


def _refined(reader: Any, place: np.ndarray, found: Any) -> tuple[np.ndarray, str]:
    """The whole-log transform refined at the log's start, or kept, and why."""
    fit = refine_at_start(start_cloud(reader), place, found.T_map_log)
    change = np.linalg.inv(found.T_map_log) @ fit.T_map_log
    metres = float(np.linalg.norm(change[:3, 3]))
    degrees = float(np.degrees(rotation_angle_rad(change[:3, :3])))
    if fit.inliers < START_MIN_INLIERS or fit.constrained == 0:
        return found.T_map_log, (f"kept the whole log's fit: its first {START_MOTION_M:g} m show too little "
                                 f"of the map ({fit.inliers:.0%} of their points on it)")
    if metres > START_MAX_CHANGE[0] or degrees > START_MAX_CHANGE[1]:
        return found.T_map_log, (f"kept the whole log's fit: its first {START_MOTION_M:g} m would move it "
                                 f"{metres:.2f} m, {degrees:.1f} deg")
    return fit.T_map_log, (f"refined on its first {START_MOTION_M:g} m ({fit.constrained} of 6 directions "
                           f"constrained there; {metres:.3f} m, {degrees:.2f} deg from the whole log's fit)")


def choose_alignment(reader: Any, kb: KnowledgeBase, env: Environment, align: str,
                     log_name: str) -> Alignment:
    """The transform this session's log gets (see the module docstring); refuses a poor fit."""
    if align == "none":
        return Alignment.identity()
    if align != "auto":
        return Alignment(_read_matrix(Path(align)), "file")
    place = kb.map_cloud(env)
    if place is None or len(place) < 100 or not hasattr(reader, "read_frame"):
        return Alignment.identity()  # the first session of a place defines its map frame
    found = register(log_cloud(reader), place)
    if found.fitness < MIN_FITNESS:
        raise KnowledgeBaseError(
            f"{log_name}: does not align with place {env.name!r} of {kb.location} (fitness "
            f"{found.fitness:.2f} < {MIN_FITNESS}: too little of its background matches the map); pass "
            "--env NEW if it shows another place, or --align FILE with its transform, or --align none if "
            "its poses are in the map frame")
    T_map_log, how = _refined(reader, place, found)
    return Alignment(T_map_log, "registration", found.fitness, found.rmse_m, how)


def correct_drift(reader: Any, kb: KnowledgeBase, env: Environment,
                  alignment: Alignment) -> tuple[Alignment, PathCorrection | None]:
    """A registered session's drift corrected along its path against the place's map
    (``perceive.align_path``), and the alignment with a note saying how; a first session, a
    given transform or a log without its frames to read is left as it is."""
    if alignment.method != "registration" or not hasattr(reader, "read_frame"):
        return alignment, None
    place = kb.map_cloud(env)
    if place is None or len(place) < 100 or len(reader) < 2:
        return alignment, None
    path = correct_path(reader, place, alignment.T_map_log)
    note = "; ".join(n for n in (alignment.note, path.note()) if n)
    return replace(alignment, note=note), path


def aligned(frames: Iterator[Frame], alignment: Alignment,
            path: PathCorrection | None = None) -> Iterator[Frame]:
    """The frames with their poses carried into the map frame (per frame along ``path``)."""
    T = np.asarray(alignment.T_map_log, dtype=np.float64)
    if path is None and np.allclose(T, np.eye(4)):
        yield from frames
        return
    for frame in frames:
        if path is not None and 0 <= frame.pose_id < len(path.travelled_m):
            yield replace(frame, T_map_cam=path.T_map_log(frame.pose_id) @ frame.T_map_cam)
        else:
            yield replace(frame, T_map_cam=T @ frame.T_map_cam)


class MapCloudGrower:
    """The place's background cloud, grown by this session's frames (map frame) where they see
    new space, with what stands still in them (``perceive.static_cloud``), and stored at the
    end of the session."""

    def __init__(self, kb: KnowledgeBase, env: Environment) -> None:
        self.kb, self.env = kb, env
        stored = kb.map_cloud(env)
        self.before = stored  # the place as the earlier sessions saw it (for ``FreeBefore``)
        self.cloud = StaticCloud(stored)
        self._last_s = -np.inf

    def add(self, frame: Frame) -> None:
        if abs(frame.stamp_s - self._last_s) >= CLOUD_EVERY_S:
            self._last_s = frame.stamp_s
            self.cloud.add_frame(frame)

    def store(self) -> int:
        """Write the cloud (its own transaction); bytes stored."""
        return self.kb.store_map_cloud(self.env, self.cloud.points())
