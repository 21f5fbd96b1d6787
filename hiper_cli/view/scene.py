"""What the view shows, read from a knowledge base into typed values: the ``ViewScene``.

The recording and the top-down picture both draw a ``ViewScene``, so neither touches the
store. ``load_scene`` reads the background and foreground instances (with their map-frame
trajectories), the robot's poses of every session (or of the sessions of one log) and the
floor images (``floor.py``), all cut to a time window in the log's stamps.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiper_cli.graph import KnowledgeBase
from hiper_cli.graph.door import SessionPoses
from hiper_cli.model import Box3D, Instance
from hiper_cli.view.floor import FloorImage, floor_images
from hiper_cli.view.window import TimeWindow

__all__ = ["BackgroundItem", "RobotPath", "TimeWindow", "TrackItem", "ViewScene", "load_scene"]


@dataclass(frozen=True)
class BackgroundItem:
    """A background instance: its map-frame box, its plane contour (K, 3) metres (K may be 0)."""

    uuid: str
    class_name: str
    box: Box3D
    contour_map_m: NDArray[np.float64]
    first_seen_s: float
    last_seen_s: float


@dataclass(frozen=True)
class TrackItem:
    """A foreground instance and where it was seen: ``stamps_s`` (N,), ``centers_map_m`` (N, 3),
    ``speed_mps`` (N,), N >= 1, in time order; ``box`` is its last box (extent and axes)."""

    uuid: str
    class_name: str
    state: str
    box: Box3D
    stamps_s: NDArray[np.float64]
    centers_map_m: NDArray[np.float64]
    speed_mps: NDArray[np.float64]

    @property
    def is_static(self) -> bool:
        """A static instance never moved: it is drawn at its fused box, with no path or speed."""
        return self.state == "static"

    @property
    def mean_speed_mps(self) -> float:
        """Path length over duration (0 for a single sighting)."""
        dt = float(self.stamps_s[-1] - self.stamps_s[0])
        if len(self.stamps_s) < 2 or dt <= 0:
            return 0.0
        return float(np.linalg.norm(np.diff(self.centers_map_m, axis=0), axis=1).sum() / dt)

    @property
    def span_m(self) -> float:
        """The largest horizontal extent of the path: how far the instance moved (or drifted)."""
        xy = self.centers_map_m[:, :2]
        return float(np.max(xy.max(axis=0) - xy.min(axis=0)))

    def seen_segments(self, gap_s: float) -> NDArray[np.bool_]:
        """(N-1,) True where two consecutive sightings are at most ``gap_s`` apart (the path
        between them was followed), False across a time the instance was not seen."""
        return np.diff(self.stamps_s) <= gap_s


# the camera poses of one session, within the window: the knowledge base's own record
RobotPath = SessionPoses


@dataclass(frozen=True)
class ViewScene:
    """Everything the view draws, within ``window``; ``t_min_s``/``t_max_s`` span what is in it."""

    kb_path: str
    window: TimeWindow
    background: tuple[BackgroundItem, ...]
    foreground: tuple[TrackItem, ...]
    robot: tuple[RobotPath, ...]
    floor: tuple[FloorImage, ...]

    @property
    def stamps_s(self) -> NDArray[np.float64]:
        parts = [t.stamps_s for t in self.foreground] + [r.stamps_s for r in self.robot]
        parts += [np.array([b.first_seen_s, b.last_seen_s]) for b in self.background]
        return np.concatenate(parts) if parts else np.zeros(0)

    @property
    def t_min_s(self) -> float:
        stamps = self.stamps_s
        return float(stamps.min()) if len(stamps) else 0.0

    @property
    def t_max_s(self) -> float:
        stamps = self.stamps_s
        return float(stamps.max()) if len(stamps) else 0.0

    def gap_s(self) -> float:
        """How long an instance may go unseen and still count as followed: twice the median
        interval between the robot's frames (at least 0.1 s; 0.5 s without poses)."""
        stamps = np.concatenate([r.stamps_s for r in self.robot]) if self.robot else np.zeros(0)
        steps = np.diff(np.unique(stamps))
        return max(0.1, 2.0 * float(np.median(steps))) if len(steps) else 0.5

    def floor_z_m(self) -> float:
        """Height of the floor: the lowest floor instance's centre, else 0."""
        floors = [b.box.center_m[2] for b in self.background if b.class_name == "floor"]
        return float(min(floors)) if floors else 0.0


def _background(inst: Instance) -> BackgroundItem:
    contour = np.asarray(inst.data.get("contour_map", []), dtype=np.float64).reshape(-1, 3)
    return BackgroundItem(inst.uuid, inst.class_name, inst.box, contour,
                          float(inst.first_seen_s), float(inst.last_seen_s))


def _track(inst: Instance, window: TimeWindow) -> TrackItem | None:
    """The instance's trajectory rows [t, x, y, z, vx, vy, vz] inside the window; an instance
    without rows is seen at its box centre at its first and last sighting."""
    box = inst.box
    rows = np.asarray(inst.data.get("trajectory") or [], dtype=np.float64)
    if rows.ndim != 2 or rows.shape[1] < 4 or len(rows) == 0:
        stamps = np.array(sorted({float(inst.first_seen_s), float(inst.last_seen_s)}))
        rows = np.column_stack([stamps, np.tile(box.center_m, (len(stamps), 1)), np.zeros((len(stamps), 3))])
    rows = rows[np.argsort(rows[:, 0], kind="stable")]
    rows = rows[window.mask(rows[:, 0])]
    if len(rows) == 0:
        return None
    speed = np.linalg.norm(rows[:, 4:7], axis=1) if rows.shape[1] >= 7 else np.zeros(len(rows))
    return TrackItem(inst.uuid, inst.class_name, str(inst.state), box,
                     rows[:, 0].copy(), rows[:, 1:4].copy(), np.nan_to_num(speed))


def _robot(kb: KnowledgeBase, log: Path | None, window: TimeWindow) -> tuple[RobotPath, ...]:
    paths = []
    wanted = str(log.resolve()) if log is not None else None
    sessions = kb.sessions()
    if wanted is not None and any(s.log_path == wanted for s in sessions):
        sessions = [s for s in sessions if s.log_path == wanted]
    for session in sessions:
        poses = kb.session_poses(session.id)
        keep = window.mask(poses.stamps_s)
        if keep.any():
            paths.append(RobotPath(session.id, session.log_path, poses.stamps_s[keep], poses.T_map_cam[keep]))
    return tuple(paths)


def load_scene(kb: KnowledgeBase, window: TimeWindow | None = None, log: Path | None = None) -> ViewScene:
    """The scene of ``kb`` within ``window`` (default: all of it). With ``log``, the robot path is
    that of the sessions that perceived this log (all sessions when none did)."""
    window = window or TimeWindow()
    background, foreground = [], []
    for inst in kb.instances_seen(window.start_s, window.end_s):
        if inst.layer == "background":
            background.append(_background(inst))
        elif inst.layer == "foreground" and (track := _track(inst, window)) is not None:
            foreground.append(track)
    floor = floor_images([a.to_dict() for a in kb.analyses()], [e.data for e in kb.environments()], window)
    return ViewScene(kb.location, window, tuple(background), tuple(foreground),
                     _robot(kb, log, window), floor)
