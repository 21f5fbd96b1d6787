"""How rmw_zenoh (ROS 2 over Zenoh) names topics and frames messages, and opening a session.

A ROS 2 message on topic ``/camera/color/image_raw`` of domain 0 travels on the Zenoh key
expression ``0/camera/color/image_raw/sensor_msgs::msg::dds_::Image_/RIHS01_<sha256>``
(``<domain_id>/<topic without leading slash>/<DDS type name>/<type hash>``). The payload is
the CDR serialisation with its 4-byte encapsulation header (what ``rosbags``'
``serialize_cdr`` writes); the attachment holds the publisher's sequence number (u64), its
source timestamp in nanoseconds (u64) and its GID (u8 length, then bytes), little-endian.
Subscribers here match any type hash (``*``), so robots on other ROS 2 releases are heard too.
"""

from __future__ import annotations

import json
import re
import struct
import time
from dataclasses import dataclass
from typing import Any

from hiper_cli.errors import ConfigError, LogError

__all__ = [
    "DEFAULT_ENDPOINT",
    "TYPE_HASHES",
    "Attachment",
    "dds_type_name",
    "open_session",
    "parse_endpoint",
    "topic_key",
    "zenoh_module",
]

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"  # where rmw_zenohd, the ROS 2 Zenoh router, listens
# RIHS01 type hashes (REP 2011) of the message definitions of ROS 2 Jazzy and later; a test
# checks them against zenoh-ros2-sdk's hashing of the same definitions.
TYPE_HASHES = {
    "sensor_msgs/msg/Image": "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    "sensor_msgs/msg/CameraInfo": "RIHS01_b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275",
    "tf2_msgs/msg/TFMessage": "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    "nav_msgs/msg/Odometry": "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
}
_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|unixsock-stream)/\S+$")
CONNECT_TIMEOUT_MS = 1000


def zenoh_module() -> Any:
    """The ``zenoh`` binding; ``ConfigError`` naming the extra to install when it is absent."""
    try:
        import zenoh
    except ImportError as err:
        raise ConfigError("live mode needs the Zenoh binding: pip install 'hiper[live]' "
                          "(eclipse-zenoh)") from err
    return zenoh


def dds_type_name(msgtype: str) -> str:
    """``sensor_msgs/msg/Image`` -> ``sensor_msgs::msg::dds_::Image_`` (rmw_zenoh's type name)."""
    package, kind, name = msgtype.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def topic_key(topic: str, msgtype: str, *, domain_id: int = 0, type_hash: str | None = None) -> str:
    """The key expression of ``topic`` (``type_hash=None``: the known hash, else ``*``)."""
    hash_part = type_hash if type_hash is not None else TYPE_HASHES.get(msgtype, "*")
    return f"{domain_id}/{topic.strip('/')}/{dds_type_name(msgtype)}/{hash_part}"


@dataclass(frozen=True)
class Attachment:
    """rmw_zenoh's per-message attachment: sequence number, source time, publisher GID."""

    sequence: int
    source_ns: int
    gid: bytes

    def to_bytes(self) -> bytes:
        return struct.pack("<QQB", self.sequence, self.source_ns, len(self.gid)) + self.gid

    @classmethod
    def from_bytes(cls, data: bytes) -> Attachment | None:
        """The attachment, or ``None`` when ``data`` is not one (too short, bad length)."""
        if len(data) < 17 or len(data) < 17 + data[16]:
            return None
        sequence, source_ns, size = struct.unpack_from("<QQB", data, 0)
        return cls(sequence, source_ns, bytes(data[17:17 + size]))


def parse_endpoint(url: str) -> str:
    """``zenoh://tcp/HOST:PORT`` (or ``zenoh://`` for the default) -> ``tcp/HOST:PORT``.

    Also accepts the single-slash form a shell path gives (``zenoh:/tcp/...``).
    """
    if not url.startswith("zenoh:"):
        raise ConfigError(f"{url}: not a live source; expected zenoh://tcp/HOST:PORT")
    rest = url[len("zenoh:"):].lstrip("/")
    if not rest:
        return DEFAULT_ENDPOINT
    if not _ENDPOINT.match(rest) or ":" not in rest.split("/", 1)[1]:
        raise ConfigError(f"{url}: expected zenoh://tcp/HOST:PORT (e.g. zenoh://{DEFAULT_ENDPOINT}) "
                          "or zenoh:// for the local ROS 2 Zenoh router")
    return rest


def _config(zenoh: Any, endpoint: str, listen: bool) -> Any:
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps("peer"))
    config.insert_json5("scouting/multicast/enabled", "false")  # loopback and routed networks only
    config.insert_json5("timestamping/enabled", "true")  # as rmw_zenoh: transient-local caches need it
    if listen:
        config.insert_json5("listen/endpoints", json.dumps([endpoint]))
    else:
        config.insert_json5("listen/endpoints", json.dumps([]))
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        config.insert_json5("connect/timeout_ms", str(CONNECT_TIMEOUT_MS))
        config.insert_json5("connect/exit_on_failure", "true")
    return config


def open_session(endpoint: str, *, wait_s: float, stop: Any = None) -> tuple[Any, str]:
    """A Zenoh peer session on ``endpoint`` and how it got there (``listening``/``connected``).

    It listens there when the address is free (so two hiper processes need no router), else
    connects to whoever listens (rmw_zenohd on a robot, or another hiper process), retrying
    for ``wait_s`` seconds or until ``stop`` (an Event) is set. Once connected, Zenoh
    re-establishes the link by itself when the other side goes away and comes back.
    """
    zenoh = zenoh_module()
    deadline = time.monotonic() + wait_s
    last = ""
    while True:
        try:
            return zenoh.open(_config(zenoh, endpoint, listen=True)), "listening"
        except zenoh.ZError as err:
            last = str(err)
            if "in use" not in last and "Address" not in last:
                raise ConfigError(f"zenoh://{endpoint}: cannot listen there ({last.split(' at ')[0]}); "
                                  "pass another endpoint") from err
        try:
            return zenoh.open(_config(zenoh, endpoint, listen=False)), "connected"
        except zenoh.ZError as err:
            last = str(err)
        if time.monotonic() >= deadline or (stop is not None and stop.is_set()):
            raise LogError(f"zenoh://{endpoint}: nobody answers there and the address cannot be listened "
                           f"on ({last.split(' at ')[0]}); start the robot's Zenoh router or pass another "
                           "endpoint")
        time.sleep(0.2)
