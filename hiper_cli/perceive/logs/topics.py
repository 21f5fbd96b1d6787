"""Which bag topics and tf frames a reader uses: found by message type unless set here."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["BagTopics"]


@dataclass(frozen=True)
class BagTopics:
    """Topic and frame choices for rosbag1/rosbag2/MCAP logs; ``None`` means "find it".

    ``rgb_topic``/``depth_topic``: ``sensor_msgs/Image`` or ``CompressedImage``;
    ``info_topic``: ``sensor_msgs/CameraInfo`` of the colour camera;
    ``pose_topic``: ``/tf`` (default when present), ``nav_msgs/Odometry`` or
    ``geometry_msgs/PoseStamped`` (or ``PoseWithCovarianceStamped``), giving ``T_map_cam``
    once composed with the tf chain when the pose is of another frame;
    ``detections_topic``: ``vision_msgs/Detection2DArray``.
    ``map_frame``: the tf parent frame of the poses; ``camera_frame``: the tf child frame,
    by default the ``frame_id`` of the colour images (the camera optical frame).
    ``depth_scale``: units per metre of 16-bit depth images (ROS: 1000, millimetres).
    """

    rgb_topic: str | None = None
    depth_topic: str | None = None
    info_topic: str | None = None
    pose_topic: str | None = None
    detections_topic: str | None = None
    map_frame: str = "map"
    camera_frame: str | None = None
    depth_scale: float = 1000.0
