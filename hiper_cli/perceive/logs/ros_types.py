"""ROS message type stores for the bag reader and writer, with vision_msgs added.

The stock rosbags type stores lack ``vision_msgs``; the definitions below are those of
vision_msgs 4.x (ROS 2 Humble), which the writer uses for ROS 1 and ROS 2 alike. Bags
recorded elsewhere embed their own definitions, and the reader reads either layout
(``hypothesis.class_id`` or ROS 1's ``id``; ``center.position.x`` or ``center.x``).
"""

from __future__ import annotations

from functools import cache
from typing import Any

__all__ = ["typestore"]

VISION_MSGS = {
    "vision_msgs/msg/Point2D": "float64 x\nfloat64 y\n",
    "vision_msgs/msg/Pose2D": "vision_msgs/Point2D position\nfloat64 theta\n",
    "vision_msgs/msg/BoundingBox2D": "vision_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y\n",
    "vision_msgs/msg/ObjectHypothesis": "string class_id\nfloat64 score\n",
    "vision_msgs/msg/ObjectHypothesisWithPose": (
        "vision_msgs/ObjectHypothesis hypothesis\ngeometry_msgs/PoseWithCovariance pose\n"
    ),
    "vision_msgs/msg/Detection2D": (
        "std_msgs/Header header\nvision_msgs/ObjectHypothesisWithPose[] results\n"
        "vision_msgs/BoundingBox2D bbox\nstring id\n"
    ),
    "vision_msgs/msg/Detection2DArray": "std_msgs/Header header\nvision_msgs/Detection2D[] detections\n",
}
# missing from the ROS 1 Noetic store
TF2_MSGS = {"tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n"}


@cache
def typestore(ros1: bool) -> Any:
    """The ROS 1 Noetic or ROS 2 Humble type store plus vision_msgs (and tf2_msgs for ROS 1)."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    types: dict[str, Any] = {}
    for name, text in {**VISION_MSGS, **TF2_MSGS}.items():
        if name in store.types:
            continue
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store
