"""``hiper replay LOG zenoh://...``: publish a recorded log as a ROS 2 robot on rmw_zenoh would.

Every frame of any log hiper reads becomes the messages ``BagWriter`` writes into a bag
(colour and depth ``sensor_msgs/Image``, ``CameraInfo``, the pose on ``/tf``), published on
rmw_zenoh key expressions with its attachment, at the log's own rate. The default topics are
those ``hiper perceive zenoh://`` reads, so the two meet without any flag.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from hiper_cli.errors import LogError
from hiper_cli.perceive.live.rmw import Attachment, open_session, topic_key
from hiper_cli.perceive.logs.bag_writer import BagLayout, BagWriter
from hiper_cli.perceive.logs.ros_types import typestore
from hiper_cli.types import CameraIntrinsics, Frame

__all__ = ["REPLAY_LAYOUT", "ReplaySummary", "ZenohPublisher", "replay_frames"]

# realsense-ros topics and frames; depth as 32FC1 metres, which carries any log's depth unrounded
REPLAY_LAYOUT = BagLayout(depth_encoding="32FC1")


class ZenohPublisher(BagWriter):
    """A ``BagWriter`` whose messages go to Zenoh publishers instead of a bag file."""

    def __init__(self, session: Any, camera: CameraIntrinsics, layout: BagLayout = REPLAY_LAYOUT,
                 domain_id: int = 0) -> None:
        # the message building of BagWriter, none of its file writing
        self.camera, self.layout, self.kind, self.ros1 = camera, layout, "zenoh", False
        self.store = typestore(False)
        self.types = self.store.types
        self._seq, self._static_written, self.frames = 0, False, 0
        self._connections: dict[str, Any] = {}
        self._writer = None
        self.session, self.domain_id = session, domain_id
        self.gid = os.urandom(16)  # one GID for all of this process' publishers, as a node would
        self._sequence: dict[str, int] = {}

    def _put(self, topic: str, msgtype: str, msg: Any, stamp_s: float) -> None:
        publisher = self._connections.get(topic)
        if publisher is None:
            import zenoh

            # reliable, as rmw_zenoh maps ROS 2's default QoS: a full link holds the publisher
            # back rather than losing messages (the subscriber drops frames itself, newest kept)
            key = topic_key(topic, msgtype, domain_id=self.domain_id)
            if topic == "/tf_static":  # transient local: late subscribers get the cached sample
                import zenoh.ext

                publisher = zenoh.ext.declare_advanced_publisher(
                    self.session, key, congestion_control=zenoh.CongestionControl.BLOCK,
                    cache=zenoh.ext.CacheConfig(1), publisher_detection=True)
            else:
                publisher = self.session.declare_publisher(
                    key, congestion_control=zenoh.CongestionControl.BLOCK)
            self._connections[topic] = publisher
        payload = bytes(self.store.serialize_cdr(msg, msgtype))
        sequence = self._sequence.get(topic, 0) + 1
        self._sequence[topic] = sequence
        attachment = Attachment(sequence, time.time_ns(), self.gid).to_bytes()
        publisher.put(payload, encoding="application/cdr", attachment=attachment)

    def close(self) -> None:
        for publisher in self._connections.values():
            publisher.undeclare()
        self._connections = {}


@dataclass
class ReplaySummary:
    """What a replay published."""

    endpoint: str
    how: str
    frames: int = 0
    seconds: float = 0.0
    late_frames: int = 0  # frames published later than their due time by over one period

    def to_dict(self) -> dict[str, Any]:
        return {"endpoint": self.endpoint, "session": self.how, "frames": self.frames,
                "seconds": round(self.seconds, 3), "late_frames": self.late_frames}


def replay_frames(frames: Iterable[Frame], camera: CameraIntrinsics, endpoint: str, *,
                  rate: float = 1.0, hz: float | None = None, layout: BagLayout = REPLAY_LAYOUT,
                  wait_s: float = 30.0, start_delay_s: float = 1.0,
                  stop: threading.Event | None = None,
                  progress: Callable[[int], None] | None = None) -> ReplaySummary:
    """Publish ``frames`` on ``endpoint`` at their stamps' pace (× ``rate``), or at ``hz``.

    ``start_delay_s`` lets subscribers discover the publishers before the first frame.
    """
    if rate <= 0 or (hz is not None and hz <= 0):
        raise LogError(f"replay rate {hz if hz is not None else rate}: must be positive")
    session, how = open_session(endpoint, wait_s=wait_s, stop=stop)
    summary = ReplaySummary(endpoint=endpoint, how=how)
    publisher = ZenohPublisher(session, camera, layout)
    try:
        time.sleep(start_delay_s)
        start = time.monotonic()
        first_stamp: float | None = None
        for k, frame in enumerate(frames):
            if stop is not None and stop.is_set():
                break
            first_stamp = frame.stamp_s if first_stamp is None else first_stamp
            due = start + (k / hz if hz is not None else (frame.stamp_s - first_stamp) / rate)
            delay = due - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            elif hz is not None and -delay > 1.0 / hz:
                summary.late_frames += 1
            publisher.write(frame)
            summary.frames += 1
            if progress is not None:
                progress(summary.frames)
        summary.seconds = time.monotonic() - start
        time.sleep(0.2)  # let the last messages leave before the session closes
    finally:
        publisher.close()
        session.close()
    return summary
