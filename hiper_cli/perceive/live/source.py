"""``LiveSource``: the frames of a running ROS 2 robot (rmw_zenoh), read like a log.

It subscribes to the colour, depth, camera-info and pose topics on a Zenoh endpoint
(``rmw.open_session``), assembles frames (``sync.FrameSync``) and yields them to the
pipeline as a log reader does, numbering them 0, 1, 2... as perceived. Iteration ends when
``stop()`` is called (Ctrl-C) or after ``idle_timeout_s`` without a frame (``wait_s`` at
least before the first); a silence of
``silence_s`` is reported once (``on_status``) and again when frames come back.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.errors import LogError
from hiper_cli.perceive.live.rmw import Attachment, open_session
from hiper_cli.perceive.live.sync import FrameSync, RawImage, ReadyFrame
from hiper_cli.perceive.logs.bag_writer import BagLayout
from hiper_cli.perceive.logs.base import LogInfo
from hiper_cli.perceive.logs.images import decode_image_msg
from hiper_cli.perceive.logs.options import LogOptions
from hiper_cli.perceive.logs.ros_types import typestore
from hiper_cli.types import CameraIntrinsics, Frame

__all__ = ["DEFAULT_TOPICS", "LiveSource", "LiveTopics"]

DEFAULT_TOPICS = BagLayout()  # what `hiper replay` publishes and `hiper perceive zenoh://` reads
DEFAULT_SILENCE_S = 2.0
Status = Callable[[str, str], None]
Handler = Callable[[str, bytes, float], None]


COMPRESSED = "sensor_msgs/msg/CompressedImage"


def _image_type(key: str) -> str:
    """The message type of an image topic's key expression: raw or compressed."""
    if key.split("/")[-2] == "sensor_msgs::msg::dds_::CompressedImage_":
        return COMPRESSED
    if key.split("/")[-2] == "sensor_msgs::msg::dds_::Image_":
        return "sensor_msgs/msg/Image"
    raise LogError(f"{key}: not a sensor_msgs/Image or CompressedImage topic")


def _latched_subscriber(session: Any, key: str, callback: Callable[[Any], None]) -> Any:
    """A subscriber that also gets the cached history of publishers that keep one (rmw_zenoh's
    transient-local durability, as for /tf_static, uses Zenoh's advanced publisher cache)."""
    import zenoh.ext

    history = zenoh.ext.HistoryConfig(detect_late_publishers=True)
    return zenoh.ext.declare_advanced_subscriber(session, key, callback, history=history)


@dataclass(frozen=True)
class LiveTopics:
    """The topics a live run reads; ``pose`` is ``/tf`` or an Odometry/PoseStamped topic."""

    rgb: str = DEFAULT_TOPICS.rgb_topic
    depth: str = DEFAULT_TOPICS.depth_topic
    info: str = DEFAULT_TOPICS.info_topic
    pose: str = "/tf"

    @classmethod
    def from_options(cls, options: LogOptions) -> LiveTopics:
        return cls(rgb=options.rgb_topic or cls.rgb, depth=options.depth_topic or cls.depth,
                   info=options.info_topic or cls.info, pose=options.pose_topic or cls.pose)

    @property
    def pose_is_tf(self) -> bool:
        return self.pose.strip("/") == "tf"


@dataclass
class LiveCounts:
    """What a live run received and lost."""

    messages: int = 0
    frames: int = 0
    bad_messages: int = 0
    last_error: str = ""
    silences: list[dict[str, float]] = field(default_factory=list)


class LiveSource:
    """See the module docstring. ``capacity``: frames waiting to be perceived (then dropped)."""

    live = True
    # whether the pipeline takes the next frame before it perceives this one (as for logs: the
    # detector runs on it meanwhile, and the last frame of the run is known); False perceives
    # each frame as it comes
    look_ahead = False

    def __init__(self, endpoint: str, options: LogOptions, *, capacity: int = 1,
                 idle_timeout_s: float | None = None, silence_s: float = DEFAULT_SILENCE_S,
                 domain_id: int = 0, wait_s: float = 30.0, on_status: Status | None = None) -> None:
        if capacity < 1:
            raise LogError(f"queue capacity {capacity}: must be at least 1 frame")
        self.endpoint = endpoint
        self.url = f"zenoh://{endpoint}"
        self.topics = LiveTopics.from_options(options)
        self.domain_id = domain_id
        self.idle_timeout_s = idle_timeout_s
        self.silence_s = silence_s
        self.wait_s = wait_s
        self.on_status = on_status
        given = (options.camera, options.preset, options.fx_px)
        camera = options.intrinsics(Path(".")) if any(v is not None for v in given) else None
        depth_scale = options.topics().depth_scale
        self.sync = FrameSync(options.max_dt_s, capacity, "tf" if self.topics.pose_is_tf else "pose",
                              options.map_frame, options.camera_frame, camera, depth_scale)
        self.depth_scale = depth_scale
        self.counts = LiveCounts()
        self.skipped: list[tuple[str, str]] = []
        self.how = ""
        self._stop = threading.Event()
        self._session: Any = None
        self._subscribers: list[Any] = []
        self._last_message = time.monotonic()

    # --- connection ---------------------------------------------------------------------
    def start(self) -> None:
        """Open the session and subscribe (any type hash, so other ROS 2 releases are heard)."""
        self._session, self.how = open_session(self.endpoint, wait_s=self.wait_s, stop=self._stop)
        t = self.topics
        routes: list[tuple[str, Handler]] = [
            (t.rgb, lambda key, raw, sent_s: self.sync.add_image("rgb", raw, sent_s, _image_type(key))),
            (t.depth, lambda key, raw, sent_s: self.sync.add_image("depth", raw, sent_s, _image_type(key))),
            (t.info, lambda _k, raw, _s: self.sync.add_camera_info(raw)),
            ("/tf", lambda _k, raw, _s: self.sync.add_tf(raw, static=False)),
            ("/tf_static", lambda _k, raw, _s: self.sync.add_tf(raw, static=True)),
        ]
        if not t.pose_is_tf:
            routes.append((t.pose, self._pose_message))
        for topic, handle in routes:
            key = f"{self.domain_id}/{topic.strip('/')}/*/*"
            if topic == "/tf_static":  # transient local: ask publishers for what they sent before
                self._subscribers.append(_latched_subscriber(self._session, key, self._callback(handle)))
            else:
                self._subscribers.append(self._session.declare_subscriber(key, self._callback(handle)))

    def _pose_message(self, key: str, raw: bytes, _sent_s: float) -> None:
        dds = key.split("/")[-2]
        msgtype = {"nav_msgs::msg::dds_::Odometry_": "nav_msgs/msg/Odometry",
                   "geometry_msgs::msg::dds_::PoseStamped_": "geometry_msgs/msg/PoseStamped",
                   "geometry_msgs::msg::dds_::PoseWithCovarianceStamped_":
                   "geometry_msgs/msg/PoseWithCovarianceStamped"}.get(dds)
        if msgtype is None:
            raise LogError(f"pose topic {self.topics.pose} carries {dds}; expected Odometry or PoseStamped")
        self.sync.add_pose(raw, msgtype)

    def _callback(self, handle: Handler) -> Callable[[Any], None]:
        def on_sample(sample: Any) -> None:
            now = time.time()
            try:
                extra = sample.attachment
                attachment = Attachment.from_bytes(extra.to_bytes()) if extra is not None else None
                sent_s = attachment.source_ns * 1e-9 if attachment is not None else now
                self._last_message = time.monotonic()
                self.counts.messages += 1
                handle(str(sample.key_expr), sample.payload.to_bytes(), sent_s)
            except Exception as err:  # a bad message is counted, never fatal to the run
                self.counts.bad_messages += 1
                self.counts.last_error = f"{sample.key_expr}: {err}"
        return on_sample

    def stop(self) -> None:
        """End the iteration after the frame in hand (thread- and signal-safe)."""
        self._stop.set()

    def close(self) -> None:
        for sub in self._subscribers:
            sub.undeclare()
        self._subscribers = []
        if self._session is not None:
            self._session.close()
            self._session = None

    # --- the log-reader interface -------------------------------------------------------
    def __len__(self) -> int:
        return 0  # unknown: the robot decides

    def info(self) -> LogInfo:
        camera = self.sync.camera or CameraIntrinsics(1, 1, 1.0, 1.0, 0.0, 0.0)
        return LogInfo(path=self.url, format="zenoh", frames=self.counts.frames, camera=camera,
                       pose_source=f"{self.topics.pose} (live)", has_detections=False,
                       sources={"rgb": self.topics.rgb, "depth": self.topics.depth,
                                "camera": self.topics.info, "poses": self.topics.pose},
                       stamps_s=np.zeros(0), T_map_cam=np.zeros((0, 4, 4)))

    def read_frame(self, pose_id: int) -> Frame:
        raise LogError(f"{self.url}: a live source cannot re-read frame {pose_id}")

    def __iter__(self) -> Iterator[Frame]:
        last_frame = time.monotonic()
        silent = False
        while not self._stop.is_set():
            ready = self.sync.take(0.1)
            now = time.monotonic()
            if ready is None:
                if not silent and now - last_frame >= self.silence_s:
                    silent = True
                    self.counts.silences.append({"after_frame": self.counts.frames, "seconds": 0.0})
                    self._status("silent", f"no frames for {now - last_frame:.1f} s from {self.url}")
                if self._idle(now - last_frame):
                    return
                continue
            if silent:
                silent = False
                self.counts.silences[-1]["seconds"] = round(now - last_frame, 3)
                self._status("resumed", f"frames again after {now - last_frame:.1f} s")
            last_frame = now
            frame = self._decode(ready)
            if frame is not None:
                self.counts.frames += 1
                yield frame

    def _idle(self, quiet_s: float) -> bool:
        """Whether to end the run: ``idle_timeout_s`` without frames once some came, ``wait_s``
        (or the idle timeout if longer) before the first."""
        limit = self.idle_timeout_s
        if not self.counts.frames and limit is not None:
            limit = max(limit, self.wait_s)
        if limit is None or quiet_s < limit:
            return False
        self._status("idle", f"no frames for {limit:g} s: ending the run")
        return True

    def _status(self, kind: str, text: str) -> None:
        if self.on_status is not None:
            self.on_status(kind, text)

    def _decode(self, ready: ReadyFrame) -> Frame | None:
        store = typestore(False)
        images = []
        for role, image in (("rgb", ready.rgb), ("depth", ready.depth)):
            where = f"{self.url} {getattr(self.topics, role)} @ {image.stamp_s:.6f}"
            try:
                images.append(self._image(store, role, image, where))
            except Exception as err:  # damaged payload: skip the frame, say why
                self.skipped.append((where, str(err)))
                return None
        return Frame(stamp_s=ready.rgb.stamp_s, rgb=images[0], depth_m=images[1], camera=ready.camera,
                     T_map_cam=ready.T_map_cam, pose_id=self.counts.frames, source=f"{self.url} live",
                     extras={"sent_s": ready.rgb.sent_s})

    def _image(self, store: Any, role: str, image: RawImage, where: str) -> Any:
        msg = store.deserialize_cdr(image.raw, image.msgtype)
        return decode_image_msg(msg, image.msgtype == COMPRESSED, role, where, self.depth_scale)
