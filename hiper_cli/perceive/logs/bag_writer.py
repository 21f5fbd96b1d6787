"""Write ``Frame``s as a rosbag1 ``.bag``, a rosbag2 folder (sqlite3) or a rosbag2 MCAP folder.

One frame becomes, all stamped with the frame's stamp: a colour ``sensor_msgs/Image``
(rgb8) or ``CompressedImage`` (png/jpeg, on ``<rgb_topic>/compressed``), a depth ``Image``
(16UC1 millimetres or 32FC1 metres), a ``CameraInfo``, the pose (``/tf`` map -> camera
optical frame, or map -> base on ``/tf`` plus a static base -> camera on ``/tf_static``,
or a ``nav_msgs/Odometry``, or a ``geometry_msgs/PoseStamped``) and, when the frame has
detections, a ``vision_msgs/Detection2DArray``. ``open_log`` reads all of it back.

    with BagWriter("out/log.bag", "rosbag1", camera) as writer:
        for frame in frames:
            writer.write(frame)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.images import ROS_DEPTH_MM_PER_M
from hiper_cli.perceive.logs.ros_types import typestore
from hiper_cli.perceive.logs.trajectory import matrix_to_quat_xyzw
from hiper_cli.perceive.logs.tum_writer import depth_to_uint16
from hiper_cli.types import CameraIntrinsics, Frame

__all__ = ["BAG_KINDS", "BagLayout", "BagWriter", "stamp_to_sec_nsec"]

BAG_KINDS = ("rosbag1", "rosbag2", "mcap")

# camera optical frame (z forward, x right, y down) in a base frame (x forward, z up)
R_BASE_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class BagLayout:
    """Topics, frames and encodings the writer uses (the defaults follow realsense-ros)."""

    rgb_topic: str = "/camera/color/image_raw"
    depth_topic: str = "/camera/aligned_depth_to_color/image_raw"
    info_topic: str = "/camera/color/camera_info"
    detections_topic: str = "/detections"
    pose_topic: str = "/tf"
    pose_as: Literal["tf", "odometry", "pose"] = "tf"
    map_frame: str = "map"
    camera_frame: str = "camera_color_optical_frame"
    base_frame: str | None = None
    base_height_m: float = 1.0
    rgb_format: Literal["raw", "png", "jpeg"] = "raw"
    depth_encoding: Literal["16UC1", "32FC1"] = "16UC1"
    depth_scale: float = ROS_DEPTH_MM_PER_M


def stamp_to_sec_nsec(stamp_s: float) -> tuple[int, int]:
    """Seconds to ROS (sec, nanosec), rounded to the microsecond like TUM stamps."""
    micros = round(stamp_s * 1e6)
    return micros // 1_000_000, (micros % 1_000_000) * 1000


class BagWriter:
    """Writes frames into a new bag of ``kind`` ``rosbag1``, ``rosbag2`` (sqlite3) or ``mcap``."""

    def __init__(self, path: str | Path, kind: str, camera: CameraIntrinsics,
                 layout: BagLayout = BagLayout()) -> None:
        if kind not in BAG_KINDS:
            raise LogError(f"bag kind '{kind}': unknown; expected one of {', '.join(BAG_KINDS)}")
        self.path = Path(path)
        if self.path.exists():
            raise LogError(f"{self.path}: exists already; choose a new output path")
        self.kind = kind
        self.camera = camera
        self.layout = layout
        self.ros1 = kind == "rosbag1"
        self.store = typestore(self.ros1)
        self.types = self.store.types
        self._seq = 0
        self._static_written = False
        self._connections: dict[str, Any] = {}
        if self.ros1:
            from rosbags.rosbag1 import Writer as Writer1

            self._writer: Any = Writer1(self.path)
        else:
            from rosbags.rosbag2 import StoragePlugin
            from rosbags.rosbag2 import Writer as Writer2

            plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
            self._writer = Writer2(self.path, version=9, storage_plugin=plugin)
        self._writer.open()
        self.frames = 0

    # --- message building -------------------------------------------------------------
    def _time(self, stamp_s: float) -> Any:
        sec, nsec = stamp_to_sec_nsec(stamp_s)
        return self.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec)

    def _header(self, stamp_s: float, frame_id: str) -> Any:
        header = self.types["std_msgs/msg/Header"]
        if self.ros1:
            return header(seq=self._seq, stamp=self._time(stamp_s), frame_id=frame_id)
        return header(stamp=self._time(stamp_s), frame_id=frame_id)

    def _pose_msg(self, T: NDArray[np.float64]) -> Any:
        t = self.types
        q = matrix_to_quat_xyzw(T[:3, :3])
        return t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=float(T[0, 3]), y=float(T[1, 3]), z=float(T[2, 3])),
            orientation=t["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]),
        )

    def _transform(self, stamp_s: float, parent: str, child: str, T: NDArray[np.float64]) -> Any:
        t = self.types
        q = matrix_to_quat_xyzw(T[:3, :3])
        transform = t["geometry_msgs/msg/Transform"](
            translation=t["geometry_msgs/msg/Vector3"](x=float(T[0, 3]), y=float(T[1, 3]), z=float(T[2, 3])),
            rotation=t["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]),
        )
        return t["geometry_msgs/msg/TransformStamped"](
            header=self._header(stamp_s, parent), child_frame_id=child, transform=transform
        )

    def _image(self, stamp_s: float, frame_id: str, image: NDArray[Any], encoding: str) -> Any:
        height, width = image.shape[:2]
        data = np.ascontiguousarray(image).view(np.uint8).reshape(-1)
        return self.types["sensor_msgs/msg/Image"](
            header=self._header(stamp_s, frame_id), height=height, width=width, encoding=encoding,
            is_bigendian=0, step=len(data) // height, data=data,
        )

    def _camera_info(self, stamp_s: float) -> Any:
        cam = self.camera
        K = cam.K.reshape(-1)
        P = np.zeros(12)
        P[[0, 2, 5, 6, 10]] = [cam.fx, cam.cx, cam.fy, cam.cy, 1.0]
        D = np.array(cam.distortion, dtype=np.float64)
        fields = {"D": D, "K": K, "R": np.eye(3).reshape(-1), "P": P}
        if not self.ros1:
            fields = {k.lower(): v for k, v in fields.items()}
        t = self.types
        roi = t["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0,
                                                    do_rectify=False)
        return t["sensor_msgs/msg/CameraInfo"](
            header=self._header(stamp_s, self.layout.camera_frame), height=cam.height, width=cam.width,
            distortion_model="plumb_bob" if cam.distortion else "", binning_x=0, binning_y=0, roi=roi,
            **fields,
        )

    def _detections(self, frame: Frame) -> Any:
        t = self.types
        assert frame.detections is not None
        items = []
        for box, name, score in zip(frame.detections.xyxy, frame.detections.class_names,
                                    frame.detections.scores, strict=True):
            center = t["vision_msgs/msg/Pose2D"](
                position=t["vision_msgs/msg/Point2D"](x=float(box[0] + box[2]) / 2,
                                                      y=float(box[1] + box[3]) / 2),
                theta=0.0,
            )
            hypothesis = t["vision_msgs/msg/ObjectHypothesisWithPose"](
                hypothesis=t["vision_msgs/msg/ObjectHypothesis"](class_id=name, score=float(score)),
                pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=self._pose_msg(np.eye(4)),
                                                                covariance=np.zeros(36)),
            )
            items.append(t["vision_msgs/msg/Detection2D"](
                header=self._header(frame.stamp_s, self.layout.camera_frame), results=[hypothesis],
                bbox=t["vision_msgs/msg/BoundingBox2D"](center=center, size_x=float(box[2] - box[0]),
                                                        size_y=float(box[3] - box[1])),
                id="",
            ))
        return t["vision_msgs/msg/Detection2DArray"](
            header=self._header(frame.stamp_s, self.layout.camera_frame), detections=items
        )

    # --- writing ----------------------------------------------------------------------
    def _put(self, topic: str, msgtype: str, msg: Any, stamp_s: float) -> None:
        conn = self._connections.get(topic)
        if conn is None:
            conn = self._writer.add_connection(topic, msgtype, typestore=self.store)
            self._connections[topic] = conn
        raw = (self.store.serialize_ros1(msg, msgtype) if self.ros1
               else self.store.serialize_cdr(msg, msgtype))
        sec, nsec = stamp_to_sec_nsec(stamp_s)
        self._writer.write(conn, sec * 1_000_000_000 + nsec, raw)

    def write(self, frame: Frame) -> None:
        """Append one frame (colour, depth, camera info, pose, detections)."""
        import cv2

        lay, stamp = self.layout, frame.stamp_s
        if lay.rgb_format == "raw":
            self._put(lay.rgb_topic, "sensor_msgs/msg/Image",
                      self._image(stamp, lay.camera_frame, frame.rgb, "rgb8"), stamp)
        else:
            ok, buf = cv2.imencode(f".{'png' if lay.rgb_format == 'png' else 'jpg'}", frame.rgb[:, :, ::-1])
            if not ok:
                raise LogError(f"{self.path}: cannot encode frame {frame.pose_id} as {lay.rgb_format}")
            msg = self.types["sensor_msgs/msg/CompressedImage"](
                header=self._header(stamp, lay.camera_frame),
                format=f"rgb8; {lay.rgb_format} compressed bgr8",
                data=buf.reshape(-1).astype(np.uint8),
            )
            self._put(f"{lay.rgb_topic}/compressed", "sensor_msgs/msg/CompressedImage", msg, stamp)
        if lay.depth_encoding == "16UC1":
            depth: NDArray[Any] = depth_to_uint16(frame.depth_m, lay.depth_scale)
        else:
            depth = frame.depth_m.astype(np.float32)
        self._put(lay.depth_topic, "sensor_msgs/msg/Image",
                  self._image(stamp, lay.camera_frame, depth, lay.depth_encoding), stamp)
        self._put(lay.info_topic, "sensor_msgs/msg/CameraInfo", self._camera_info(stamp), stamp)
        self._write_pose(frame)
        if frame.detections is not None:
            self._put(lay.detections_topic, "vision_msgs/msg/Detection2DArray", self._detections(frame),
                      stamp)
        self._seq += 1
        self.frames += 1

    def _write_pose(self, frame: Frame) -> None:
        lay, stamp, T = self.layout, frame.stamp_s, frame.T_map_cam
        if lay.pose_as == "tf":
            tf = self.types["tf2_msgs/msg/TFMessage"]
            if lay.base_frame is None:
                transforms = [self._transform(stamp, lay.map_frame, lay.camera_frame, T)]
            else:
                T_base_cam = np.eye(4)
                T_base_cam[:3, :3] = R_BASE_OPTICAL
                T_base_cam[2, 3] = lay.base_height_m
                if not self._static_written:
                    static = self._transform(stamp, lay.base_frame, lay.camera_frame, T_base_cam)
                    self._put("/tf_static", "tf2_msgs/msg/TFMessage", tf(transforms=[static]), stamp)
                    self._static_written = True
                T_map_base = T @ np.linalg.inv(T_base_cam)
                transforms = [self._transform(stamp, lay.map_frame, lay.base_frame, T_map_base)]
            self._put(lay.pose_topic, "tf2_msgs/msg/TFMessage", tf(transforms=transforms), stamp)
        elif lay.pose_as == "odometry":
            t = self.types
            zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
            odom = t["nav_msgs/msg/Odometry"](
                header=self._header(stamp, lay.map_frame), child_frame_id=lay.camera_frame,
                pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=self._pose_msg(T),
                                                                covariance=np.zeros(36)),
                twist=t["geometry_msgs/msg/TwistWithCovariance"](
                    twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)),
            )
            self._put(lay.pose_topic, "nav_msgs/msg/Odometry", odom, stamp)
        else:
            msg = self.types["geometry_msgs/msg/PoseStamped"](
                header=self._header(stamp, lay.map_frame), pose=self._pose_msg(T)
            )
            self._put(lay.pose_topic, "geometry_msgs/msg/PoseStamped", msg, stamp)

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
