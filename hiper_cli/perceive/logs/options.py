"""``LogOptions``: every choice a user can make about how a sensor log is read.

One frozen value for the camera (a ``camera.json``, a TUM preset or the six pinhole numbers),
the poses replacing the log's own, the timestamp tolerance and the bag topics. The CLI builds
it from its log flags; ``open_log(path, options)`` turns it into a reader.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs.topics import BagTopics
from hiper_cli.types import CameraIntrinsics

__all__ = ["DEFAULT_MAX_DT_S", "LogOptions"]

DEFAULT_MAX_DT_S = 0.02  # colour/depth/pose association tolerance; TUM's associate.py uses 0.02 s
ROS_DEPTH_SCALE = 1000.0  # 16UC1 depth images are millimetres


@dataclass(frozen=True)
class LogOptions:
    """How to read a log; every field left at ``None`` keeps what the log itself says.

    Camera: at most one of ``camera`` (a camera.json path), ``preset`` (TUM: fr1, fr2, fr3, ros)
    or all six of ``fx_px fy_px cx_px cy_px width_px height_px``. ``depth_scale`` is units per
    metre of 16-bit depth. ``poses`` is a TUM trajectory replacing the log's poses.
    ``max_dt_s`` is the tolerance when associating images, camera info, detections and poses
    by stamp. The topic and frame fields choose what a bag is read from (ignored for TUM).
    """

    poses: Path | None = None
    camera: Path | None = None
    preset: str | None = None
    fx_px: float | None = None
    fy_px: float | None = None
    cx_px: float | None = None
    cy_px: float | None = None
    width_px: int | None = None
    height_px: int | None = None
    depth_scale: float | None = None
    max_dt_s: float = DEFAULT_MAX_DT_S
    rgb_topic: str | None = None
    depth_topic: str | None = None
    info_topic: str | None = None
    pose_topic: str | None = None
    detections_topic: str | None = None
    map_frame: str = "map"
    camera_frame: str | None = None

    def __post_init__(self) -> None:
        pinhole = self._pinhole()
        given = [flag for flag, value in pinhole.items() if value is not None]
        if sum(x is not None for x in (self.camera, self.preset)) + bool(given) > 1:
            raise ConfigError("choose one of --camera, --preset or the --fx/--fy/--cx/--cy/--width/--height "
                              "flags")
        if given and len(given) < len(pinhole):
            missing = [flag for flag, value in pinhole.items() if value is None]
            raise ConfigError(f"camera flags: missing {' '.join(missing)}; give all of "
                              "--fx --fy --cx --cy --width --height, or --camera camera.json")
        if self.preset is not None:
            from hiper_cli.perceive.logs.tum import TUM_PRESETS

            if self.preset not in TUM_PRESETS:
                raise ConfigError(f"--preset {self.preset}: unknown preset; expected one of "
                                  f"{', '.join(TUM_PRESETS)}")

    def _pinhole(self) -> dict[str, float | int | None]:
        return {"--fx": self.fx_px, "--fy": self.fy_px, "--cx": self.cx_px, "--cy": self.cy_px,
                "--width": self.width_px, "--height": self.height_px}

    def intrinsics(self, log: Path) -> CameraIntrinsics | None:
        """The camera these options choose for ``log``, or ``None`` to keep the log's own."""
        from hiper_cli.perceive.logs.tum import TUM_PRESETS, load_camera_json

        intrinsics: CameraIntrinsics | None = None
        if self.camera is not None:
            intrinsics = load_camera_json(self.camera)
        elif self.preset is not None:
            intrinsics = TUM_PRESETS[self.preset]
        elif self.fx_px is not None:
            intrinsics = CameraIntrinsics(
                width=int(self.width_px or 0), height=int(self.height_px or 0), fx=float(self.fx_px),
                fy=float(self.fy_px or 0), cx=float(self.cx_px or 0), cy=float(self.cy_px or 0))
        if intrinsics is None and self.depth_scale is not None:
            from hiper_cli.perceive.logs.formats import detect_format

            if detect_format(log) == "tum":
                from hiper_cli.perceive.logs.tum import tum_camera

                intrinsics = tum_camera(log)[0]
        if intrinsics is not None and self.depth_scale is not None:
            intrinsics = replace(intrinsics, depth_scale=self.depth_scale)
        return intrinsics

    def topics(self) -> BagTopics:
        """The bag topic and tf frame choices."""
        return BagTopics(
            rgb_topic=self.rgb_topic, depth_topic=self.depth_topic, info_topic=self.info_topic,
            pose_topic=self.pose_topic, detections_topic=self.detections_topic, map_frame=self.map_frame,
            camera_frame=self.camera_frame,
            depth_scale=ROS_DEPTH_SCALE if self.depth_scale is None else self.depth_scale,
        )
