"""A ``ViewScene`` as a Rerun recording on the log's timeline (``rerun-sdk``, the ``view`` extra).

One timeline, ``stamp``: the log's stamps (a duration from 0 for logs whose stamps start near
0, as the simulator's; wall-clock time for stamps after 1973, as TUM's and ROS's). Background
instances appear when first seen, as translucent boxes in their class colour with their plane
contour; a static foreground instance is its fused box from its first sighting on, with no path
or speed; a moving one is a labelled box at each sighting, cleared when not seen for ``hold_s``,
with its path as a line strip coloured by speed and its speed as a scalar series; the robot's
path and its camera (a pinhole frustum) move along the poses. Entity paths:
``style.py`` and docs/view.md. Columns go in with ``send_columns`` so a long track is one call.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from hiper_cli.clock import WALL_CLOCK_MIN_S
from hiper_cli.errors import ConfigError
from hiper_cli.types import CameraIntrinsics
from hiper_cli.view.floor import FloorImage
from hiper_cli.view.scene import BackgroundItem, TrackItem, ViewScene
from hiper_cli.view.style import CAMERA_PATH, IMAGE_PATH, ROBOT_PATH, class_color, entity_path, speed_colors

__all__ = ["INSTALL_HINT", "TIMELINE", "RecordingConfig", "Timeline", "import_rerun", "log_pinhole",
           "new_recording", "quat_xyzw", "write_scene"]

TIMELINE = "stamp"
INSTALL_HINT = "pip install 'hiper[view]'"
# Stamps above this are seconds since 1970 (wall-clock logs), below it seconds since the log began.
EPOCH_STAMP_S = WALL_CLOCK_MIN_S
# A camera of 60° horizontal field of view, 4:3, when the recording has no log to take it from.
DEFAULT_CAMERA = CameraIntrinsics(width=640, height=480, fx=554.3, fy=554.3, cx=319.5, cy=239.5)


@dataclass(frozen=True)
class RecordingConfig:
    """``hold_s``: how long a foreground box stays after a sighting before it is cleared (None:
    ``ViewScene.gap_s()``, twice the log's median frame interval). ``background_alpha``: opacity of
    background boxes (0-255). ``frustum_m``: depth of the drawn camera frustum."""

    hold_s: float | None = None
    background_alpha: int = 90
    frustum_m: float = 0.4


def import_rerun() -> Any:
    """The ``rerun`` module, or a ``ConfigError`` that says how to install it."""
    try:
        import rerun
    except ImportError as err:
        raise ConfigError(f"a Rerun recording needs rerun-sdk, which is not installed: {INSTALL_HINT} "
                          "(or draw a picture with --png)") from err
    return rerun


def _blueprint(with_images: bool) -> Any:
    """The layout the viewer opens with: the 3D scene, the camera's image (with ``--log``) and
    the tracks' speeds, on the ``stamp`` timeline."""
    import rerun.blueprint as rrb

    side: list[Any] = [rrb.Spatial2DView(origin=IMAGE_PATH, name="camera")] if with_images else []
    side.append(rrb.TimeSeriesView(origin="/foreground", name="speed (m/s)"))
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Spatial3DView(origin="/", name="scene"), rrb.Vertical(*side),
                       column_shares=[2, 1]),
        rrb.TimePanel(timeline=TIMELINE),
    )


def new_recording(out: Path | None, spawn: bool, with_images: bool = False) -> Any:
    """A recording stream saving to ``out`` and/or streaming to a spawned viewer."""
    rr = import_rerun()
    rec = rr.RecordingStream("hiper_view")
    rr.set_log_time_enabled(False, recording=rec)
    blueprint = _blueprint(with_images)
    if spawn:
        rec.spawn(default_blueprint=blueprint)
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        rec.save(out, default_blueprint=blueprint)
    return rec


class Timeline:
    """Sets the ``stamp`` timeline of a recording in the right kind for the scene's stamps."""

    def __init__(self, rr: Any, rec: Any, scene: ViewScene) -> None:
        self.rr, self.rec = rr, rec
        self.kind = "timestamp" if scene.t_min_s > EPOCH_STAMP_S else "duration"

    def set(self, stamp_s: float) -> None:
        self.rec.set_time(TIMELINE, **{self.kind: float(stamp_s)})

    def column(self, stamps_s: NDArray[np.float64]) -> Any:
        return self.rr.TimeColumn(TIMELINE, **{self.kind: np.asarray(stamps_s, dtype=np.float64)})


def quat_xyzw(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation matrix as a quaternion (x, y, z, w), Rerun's order."""
    return np.asarray(Rotation.from_matrix(R).as_quat(), dtype=np.float64)


def _log_background(rr: Any, rec: Any, tl: Timeline, item: BackgroundItem, alpha: int, t0: float) -> None:
    path = entity_path("background", item.class_name, item.uuid)
    color = (*class_color(item.class_name), alpha)
    tl.set(max(item.first_seen_s, t0))
    rec.log(path, rr.Boxes3D(centers=[item.box.center_m], half_sizes=[item.box.extent_m / 2.0],
                             quaternions=[quat_xyzw(item.box.R)], colors=[color], fill_mode="solid",
                             labels=[item.class_name], show_labels=False))
    if len(item.contour_map_m) >= 3:
        loop = np.vstack([item.contour_map_m, item.contour_map_m[:1]])
        rec.log(path + "/contour", rr.LineStrips3D([loop], colors=[class_color(item.class_name)], radii=0.01))


def _seen_spans(stamps_s: NDArray[np.float64], hold_s: float) -> NDArray[np.float64]:
    """The stamps at which a track is cleared: ``hold_s`` after each sighting that is not
    followed by another within ``hold_s``, and after the last one."""
    ends = np.append(np.diff(stamps_s) > hold_s, True)
    cleared_s: NDArray[np.float64] = stamps_s[ends] + hold_s
    return cleared_s


def _log_static(rr: Any, rec: Any, tl: Timeline, track: TrackItem) -> None:
    """A static instance: its fused box from its first sighting on; no path, no speed series."""
    tl.set(track.stamps_s[0])
    rec.log(entity_path("foreground", track.class_name, track.uuid),
            rr.Boxes3D(centers=[track.box.center_m], half_sizes=[track.box.extent_m / 2.0],
                       quaternions=[quat_xyzw(track.box.R)], colors=[class_color(track.class_name)],
                       labels=[f"{track.class_name} {track.uuid[-4:]}"]))


def _log_track(rr: Any, rec: Any, tl: Timeline, track: TrackItem, hold_s: float) -> None:
    if track.is_static:
        _log_static(rr, rec, tl, track)
        return
    path = entity_path("foreground", track.class_name, track.uuid)
    n = len(track.stamps_s)
    label = f"{track.class_name} {track.uuid[-4:]}"
    color = class_color(track.class_name)
    boxes = rr.Boxes3D.columns(
        centers=track.centers_map_m,
        half_sizes=np.tile(track.box.extent_m / 2.0, (n, 1)),
        quaternions=np.tile(quat_xyzw(track.box.R), (n, 1)),
        colors=np.tile(np.array(color, dtype=np.uint8), (n, 1)),
        labels=[label] * n,
    )
    rec.send_columns(path, indexes=[tl.column(track.stamps_s)], columns=boxes)
    for t in _seen_spans(track.stamps_s, hold_s):
        tl.set(t)
        rec.log(path, rr.Clear(recursive=False))
    rec.send_columns(path + "/speed_mps", indexes=[tl.column(track.stamps_s)],
                     columns=rr.Scalars.columns(scalars=track.speed_mps))
    if n >= 2:
        # One strip per step, coloured by speed; a step across a time unseen is thin and grey.
        segments = np.stack([track.centers_map_m[:-1], track.centers_map_m[1:]], axis=1)
        seen = track.seen_segments(hold_s)
        colors = np.where(seen[:, None], speed_colors((track.speed_mps[:-1] + track.speed_mps[1:]) / 2.0),
                          np.array([170, 170, 170], dtype=np.uint8))
        tl.set(track.stamps_s[0])
        rec.log(path + "/trajectory", rr.LineStrips3D(
            segments, colors=colors, radii=np.where(seen, 0.015, 0.004),
            labels=[f"{label} {track.mean_speed_mps:.2f} m/s"] + [""] * (len(segments) - 1)))


def log_pinhole(rr: Any, rec: Any, camera: CameraIntrinsics, frustum_m: float) -> None:
    """The camera's intrinsics (static), drawn as a frustum ``frustum_m`` deep; and z up."""
    rec.log("/", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    rec.log(IMAGE_PATH, rr.Pinhole(image_from_camera=camera.K, resolution=[camera.width, camera.height],
                                   camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=frustum_m),
            static=True)


def _log_robot(rr: Any, rec: Any, tl: Timeline, scene: ViewScene, camera: CameraIntrinsics,
               frustum_m: float) -> None:
    strips = [r.T_map_cam[:, :3, 3] for r in scene.robot if len(r.stamps_s) >= 2]
    if strips:
        rec.log(ROBOT_PATH, rr.LineStrips3D(strips, colors=[(60, 60, 60)], radii=0.01), static=True)
    log_pinhole(rr, rec, camera, frustum_m)
    for robot in scene.robot:
        rec.send_columns(CAMERA_PATH, indexes=[tl.column(robot.stamps_s)],
                         columns=rr.Transform3D.columns(translation=robot.T_map_cam[:, :3, 3],
                                                        mat3x3=robot.T_map_cam[:, :3, :3]))


def _log_floor(rr: Any, rec: Any, image: FloorImage, z_m: float) -> None:
    """A grid as a textured quad on the floor (``/map/<name>``), in ``FloorImage.rgba`` colours."""
    rgba = image.rgba()
    x0, x1, y0, y1 = image.extent_m
    z = z_m + (0.005 if image.kind == "occupancy" else 0.01)  # heatmaps over the map
    corners = [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]]
    # Texture row 0 is cell row 0, at y0: texcoord v runs with y.
    rec.log(f"/map/{image.name}", rr.Mesh3D(vertex_positions=corners, triangle_indices=[[0, 1, 2], [0, 2, 3]],
                                             vertex_texcoords=[[0, 0], [1, 0], [1, 1], [0, 1]],
                                             albedo_texture=np.ascontiguousarray(rgba)), static=True)


def write_scene(rec: Any, scene: ViewScene, camera: CameraIntrinsics | None = None,
                config: RecordingConfig | None = None) -> dict[str, int]:
    """Log ``scene`` into ``rec``; the counts of what was logged, by kind."""
    rr = import_rerun()
    config = config or RecordingConfig()
    tl = Timeline(rr, rec, scene)
    t0 = scene.t_min_s
    for item in scene.background:
        _log_background(rr, rec, tl, item, config.background_alpha, t0)
    hold_s = config.hold_s if config.hold_s is not None else scene.gap_s()
    for track in scene.foreground:
        _log_track(rr, rec, tl, track, hold_s)
    _log_robot(rr, rec, tl, scene, camera or DEFAULT_CAMERA, config.frustum_m)
    for image in scene.floor:
        _log_floor(rr, rec, image, scene.floor_z_m())
    return {"background": len(scene.background), "foreground": len(scene.foreground),
            "poses": sum(len(r.stamps_s) for r in scene.robot), "floor_images": len(scene.floor)}

