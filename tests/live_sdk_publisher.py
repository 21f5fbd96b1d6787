"""An independent rmw_zenoh publisher: zenoh-ros2-sdk publishes a recorded log's frames.

    python tests/live_sdk_publisher.py LOG PORT MSG_DIR HZ

Reads the frames with hiper's log reader, and publishes with the SDK alone (its own key
expressions, type hashes, CDR and attachments) colour and depth ``sensor_msgs/Image``,
``CameraInfo`` and ``/tf`` (map -> camera optical frame) on the topics hiper perceives by
default, connecting to tcp/127.0.0.1:PORT. ``MSG_DIR`` holds the message definitions, so the
SDK needs no network. Prints ``published N`` at the end.
"""

from __future__ import annotations

import sys
import time

import numpy as np


def main() -> None:
    log, port, msg_dir, hz = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
    from zenoh_ros2_sdk import ROS2Publisher, message_registry

    message_registry.get_registry(msg_dir)
    from hiper_cli.perceive.logs import open_log
    from hiper_cli.perceive.logs.trajectory import matrix_to_quat_xyzw

    topics = (("rgb", "/camera/color/image_raw", "sensor_msgs/msg/Image"),
              ("depth", "/camera/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image"),
              ("info", "/camera/color/camera_info", "sensor_msgs/msg/CameraInfo"),
              ("tf", "/tf", "tf2_msgs/msg/TFMessage"))
    publishers = {name: ROS2Publisher(topic=topic, msg_type=msgtype, router_port=port)
                  for name, topic, msgtype in topics}
    types = publishers["rgb"].session_mgr.store.types
    time.sleep(1.5)  # let the subscriber see the publishers
    frame_id = "camera_color_optical_frame"
    n = 0
    for frame in open_log(log):
        micros = round(frame.stamp_s * 1e6)
        stamp = types["builtin_interfaces/msg/Time"](sec=micros // 1_000_000,
                                                     nanosec=(micros % 1_000_000) * 1000)

        def header(frame_name: str, stamp: object = stamp) -> object:
            return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame_name)

        h, w = frame.depth_m.shape
        publishers["rgb"].publish(header=header(frame_id), height=h, width=w, encoding="rgb8", is_bigendian=0,
                                  step=w * 3, data=np.ascontiguousarray(frame.rgb).reshape(-1))
        depth = np.ascontiguousarray(frame.depth_m, dtype=np.float32).view(np.uint8).reshape(-1)
        publishers["depth"].publish(header=header(frame_id), height=h, width=w, encoding="32FC1",
                                    is_bigendian=0, step=w * 4, data=depth)
        cam = frame.camera
        publishers["info"].publish(
            header=header(frame_id), height=h, width=w, distortion_model="plumb_bob", d=np.zeros(5),
            k=np.array([cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1], dtype=np.float64),
            r=np.eye(3).reshape(-1), p=np.array([cam.fx, 0, cam.cx, 0, 0, cam.fy, cam.cy, 0, 0, 0, 1, 0.0]),
            binning_x=0, binning_y=0,
            roi=types["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0,
                                                          do_rectify=False))
        T = frame.T_map_cam
        q = matrix_to_quat_xyzw(T[:3, :3])
        transform = types["geometry_msgs/msg/Transform"](
            translation=types["geometry_msgs/msg/Vector3"](x=float(T[0, 3]), y=float(T[1, 3]),
                                                           z=float(T[2, 3])),
            rotation=types["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]))
        publishers["tf"].publish(transforms=[types["geometry_msgs/msg/TransformStamped"](
            header=header("map"), child_frame_id=frame_id, transform=transform)])
        n += 1
        time.sleep(1.0 / hz)
    time.sleep(0.5)
    for publisher in publishers.values():
        publisher.close()
    print(f"published {n}", flush=True)


if __name__ == "__main__":
    main()
