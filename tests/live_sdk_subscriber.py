"""An independent rmw_zenoh subscriber: zenoh-ros2-sdk listens to what ``hiper replay`` sends.

    python tests/live_sdk_subscriber.py PORT MSG_DIR SECONDS

Subscribes with the SDK alone (its key expressions with its own type hashes, its CDR
decoding) to the colour and depth images, camera info and /tf, connecting to
tcp/127.0.0.1:PORT, for SECONDS; then prints one JSON line: per topic the count and the
first message's key fields.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from typing import Any


def main() -> None:
    port, msg_dir, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])
    from zenoh_ros2_sdk import ROS2Subscriber, message_registry

    message_registry.get_registry(msg_dir)
    counts: dict[str, int] = {}
    first: dict[str, object] = {}

    def keep(name: str, fields: object) -> None:
        counts[name] = counts.get(name, 0) + 1
        first.setdefault(name, fields)

    def image(name: str) -> Callable[[Any], None]:
        return lambda m: keep(name, {"stamp": [m.header.stamp.sec, m.header.stamp.nanosec],
                                     "frame_id": m.header.frame_id, "encoding": m.encoding,
                                     "size": [m.width, m.height], "bytes": len(m.data)})

    subscribers = [
        ROS2Subscriber(topic="/camera/color/image_raw", msg_type="sensor_msgs/msg/Image",
                       callback=image("rgb"), router_port=port),
        ROS2Subscriber(topic="/camera/aligned_depth_to_color/image_raw", msg_type="sensor_msgs/msg/Image",
                       callback=image("depth"), router_port=port),
        ROS2Subscriber(topic="/camera/color/camera_info", msg_type="sensor_msgs/msg/CameraInfo",
                       callback=lambda m: keep("info", {"k": [float(v) for v in m.k]}), router_port=port),
        ROS2Subscriber(topic="/tf", msg_type="tf2_msgs/msg/TFMessage", router_port=port,
                       callback=lambda m: keep("tf", {"parent": m.transforms[0].header.frame_id,
                                                      "child": m.transforms[0].child_frame_id,
                                                      "x": m.transforms[0].transform.translation.x})),
    ]
    time.sleep(seconds)
    for subscriber in subscribers:
        subscriber.close()
    print(json.dumps({name: {"count": n, "first": first[name]} for name, n in counts.items()}), flush=True)


if __name__ == "__main__":
    main()
