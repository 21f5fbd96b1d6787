"""rosbag1, rosbag2 (sqlite3 or MCAP) and bare MCAP logs through ``rosbags.highlevel.AnyReader``.

Topics are found by message type unless ``BagTopics`` names them: colour and depth are
``sensor_msgs/Image`` or ``CompressedImage`` topics told apart by their first message's
encoding; intrinsics come from ``sensor_msgs/CameraInfo``; poses from ``/tf`` (+
``/tf_static``, the chain from ``map_frame`` to the camera frame composed), else a
``nav_msgs/Odometry`` or ``geometry_msgs/PoseStamped`` topic; detections from
``vision_msgs/Detection2DArray``. Frames take the colour images' header stamps; depth,
detections and poses are associated or interpolated to them within ``max_dt_s``.

Indexing reads only the headers of image messages; iterating streams the bag once.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.base import FrameEntry, IndexedLog
from hiper_cli.perceive.logs.images import DEPTH_ENCODINGS, RGB_ENCODINGS, decode_image_msg
from hiper_cli.perceive.logs.ros_types import typestore
from hiper_cli.perceive.logs.tf import TfTree, pose_msg_to_matrix, transform_msg_to_matrix
from hiper_cli.perceive.logs.topics import BagTopics
from hiper_cli.perceive.logs.trajectory import Trajectory
from hiper_cli.perceive.logs.tum import associate
from hiper_cli.types import CameraIntrinsics, Detections

__all__ = ["BagReader", "camera_from_info", "open_bag"]

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED = "sensor_msgs/msg/CompressedImage"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
TF = "tf2_msgs/msg/TFMessage"
ODOMETRY = "nav_msgs/msg/Odometry"
POSE_TYPES = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PoseWithCovarianceStamped")
DETECTIONS = "vision_msgs/msg/Detection2DArray"

ImagePair = tuple[NDArray[np.uint8], NDArray[np.float32]]


def _bag_errors() -> tuple[type[BaseException], ...]:
    from rosbags.highlevel import AnyReaderError
    from rosbags.rosbag1 import ReaderError as ReaderError1
    from rosbags.rosbag2 import ReaderError as ReaderError2
    from rosbags.serde import SerdeError

    # damaged bytes surface from the parsers as any of these
    return (AnyReaderError, ReaderError1, ReaderError2, SerdeError, OSError, struct.error, ValueError,
            EOFError, OverflowError, IndexError, KeyError, zlib.error)


def _open_reader(path: Path, ros1: bool) -> Any:
    from rosbags.highlevel import AnyReader

    try:
        reader = AnyReader([path], default_typestore=typestore(ros1))
        reader.open()
    except _bag_errors() as err:
        raise LogError(f"{path}: cannot open the bag ({err}); is it a complete rosbag1/rosbag2/MCAP file?"
                       ) from err
    return reader


def _stamp(header: Any) -> float:
    return float(header.stamp.sec) + float(header.stamp.nanosec) * 1e-9


def _header_prefix(raw: bytes | memoryview, ros1: bool) -> tuple[float, str]:
    """(stamp_s, frame_id) from the serialized bytes of a message that starts with a Header."""
    data = bytes(raw[:512])
    if ros1:  # seq uint32, stamp (uint32 sec, uint32 nsec), string frame_id
        _, sec, nsec, length = struct.unpack_from("<IIII", data, 0)
        frame_id = data[16:16 + length].decode(errors="replace")
    else:  # CDR: 4-byte encapsulation, int32 sec, uint32 nanosec, string (with NUL)
        order = "<" if data[1] == 1 else ">"
        sec, nsec, length = struct.unpack_from(order + "iII", data, 4)
        frame_id = data[16:16 + max(length - 1, 0)].decode(errors="replace")
    return sec + nsec * 1e-9, frame_id.lstrip("/")


def _is_depth(msgtype: str, msg: Any, topic: str) -> bool:
    if msgtype == IMAGE:
        return str(msg.encoding).upper() in ("16UC1", "MONO16", "32FC1")
    fmt = str(msg.format).lower()
    return "compresseddepth" in fmt or "16uc1" in fmt or "32fc1" in fmt or "depth" in topic.lower()


@dataclass
class _Topic:
    topic: str
    msgtype: str
    count: int
    first: Any = None


def _check_encoding(topic: _Topic, role: str, path: Path) -> None:
    if topic.msgtype not in (IMAGE, COMPRESSED):
        raise LogError(f"{path}: topic '{topic.topic}' is {topic.msgtype}, not an image; pass "
                       f"--{role}-topic with a sensor_msgs/Image or CompressedImage topic")
    if topic.msgtype == IMAGE and topic.first is not None:
        enc = str(topic.first.encoding)
        known = RGB_ENCODINGS if role == "rgb" else DEPTH_ENCODINGS
        if enc.lower() not in [k.lower() for k in known]:
            raise LogError(f"{path}: topic '{topic.topic}' has unknown {role} encoding '{enc}'; expected one "
                           f"of {', '.join(known)} (or pass the right --{role}-topic)")


def _pick(path: Path, topics: dict[str, _Topic], wanted: str | None, types: tuple[str, ...], role: str,
          candidates: list[str] | None = None) -> str | None:
    if wanted is not None:
        if wanted not in topics:
            listing = ", ".join(f"{t.topic} ({t.msgtype})" for t in topics.values()) or "none"
            raise LogError(f"{path}: topic '{wanted}' is not in the bag (it has: {listing}); pass an "
                           "existing "
                           f"--{role}-topic")
        if topics[wanted].msgtype not in types:
            raise LogError(f"{path}: topic '{wanted}' is {topics[wanted].msgtype}; --{role}-topic expects "
                           f"{' or '.join(types)}")
        return wanted
    found = candidates if candidates is not None else [t.topic for t in topics.values() if t.msgtype in types]
    return sorted(found, key=lambda name: (-topics[name].count, name))[0] if found else None


def _near(reference: str, options: list[str]) -> list[str]:
    """``options`` sorted by the length of the prefix they share with ``reference`` (longest first)."""
    def shared(name: str) -> int:
        n = 0
        for a, b in zip(reference, name, strict=False):
            if a != b:
                break
            n += 1
        return n
    return sorted(options, key=lambda name: (-shared(name), name))


def camera_from_info(msg: Any, depth_scale: float, source: str) -> CameraIntrinsics:
    """A ``sensor_msgs/CameraInfo`` (ROS 1 ``K``/``D`` or ROS 2 ``k``/``d``) as intrinsics, from a
    bag or a live topic; ``source`` names it in the error when its K is not a camera's."""
    K = np.asarray(getattr(msg, "K", None) if hasattr(msg, "K") else msg.k, dtype=np.float64).reshape(-1)
    D = np.asarray(getattr(msg, "D", None) if hasattr(msg, "D") else msg.d, dtype=np.float64).reshape(-1)
    if len(K) != 9 or K[0] <= 0 or K[4] <= 0:
        raise LogError(f"{source}: CameraInfo has no valid K ({K.tolist()}); pass --camera camera.json")
    distortion = tuple(float(v) for v in D) if np.any(D != 0) else ()
    return CameraIntrinsics(int(msg.width), int(msg.height), float(K[0]), float(K[4]), float(K[2]),
                            float(K[5]),
                            depth_scale, distortion)


def _detections_from_msg(msg: Any) -> Detections:
    records = []
    for det in msg.detections:
        name, score = "unknown", 1.0
        if det.results:
            best = max(det.results, key=lambda r: float(getattr(getattr(r, "hypothesis", r), "score", 0.0)))
            hyp = getattr(best, "hypothesis", best)
            name = str(getattr(hyp, "class_id", getattr(hyp, "id", "unknown")))
            score = float(getattr(hyp, "score", 1.0))
        center = det.bbox.center
        position = getattr(center, "position", center)
        cx, cy = float(position.x), float(position.y)
        sx, sy = float(det.bbox.size_x), float(det.bbox.size_y)
        records.append({"xyxy": [cx - sx / 2, cy - sy / 2, cx + sx / 2, cy + sy / 2], "class": name,
                        "score": min(max(score, 0.0), 1.0)})
    return Detections.from_records(records)


@dataclass(eq=False)
class BagReader(IndexedLog):
    """Reader of one bag (see the module docstring).

    An entry's ``locator`` holds, for colour then depth, ``(topic, index, bag_time_ns, rank)``:
    the message's index on its topic, its bag time and its rank among that topic's messages
    with the same bag time (for random access).
    """

    bag: Path = field(default_factory=Path)
    ros1: bool = False
    rgb_topic: str = ""
    depth_topic: str = ""
    depth_scale: float = 1000.0

    def _decode(self, reader: Any, conn: Any, raw: bytes, role: str, index: int) -> Any:
        where = f"{self.bag} {conn.topic} #{index}"
        try:
            msg = reader.deserialize(raw, conn.msgtype)
        except _bag_errors() as err:
            raise LogError(f"{where}: cannot deserialize the message ({err})") from err
        return decode_image_msg(msg, conn.msgtype == COMPRESSED, role, where, self.depth_scale)

    def _decoded(self) -> Iterator[tuple[int, ImagePair | LogError]]:
        need: dict[tuple[str, int], list[tuple[int, str]]] = {}
        kept = self.kept_ids()
        for k in kept:
            for role, (topic, index, _, _) in zip(("rgb", "depth"), self.entries[k].locator, strict=True):
                need.setdefault((topic, index), []).append((k, role))
        ready: dict[int, dict[str, Any]] = {}
        counters = {self.rgb_topic: 0, self.depth_topic: 0}
        next_k = 0
        reader = _open_reader(self.bag, self.ros1)
        try:
            conns = [c for c in reader.connections if c.topic in counters]
            for conn, _, raw in reader.messages(connections=conns):
                index = counters[conn.topic]
                counters[conn.topic] += 1
                for k, role in need.pop((conn.topic, index), []):
                    try:
                        ready.setdefault(k, {})[role] = self._decode(reader, conn, raw, role, index)
                    except LogError as err:
                        ready.setdefault(k, {})[role] = err
                while next_k < len(kept) and len(ready.get(kept[next_k], {})) == 2:
                    yield kept[next_k], self._pair(ready.pop(kept[next_k]))
                    next_k += 1
        except _bag_errors() as err:
            raise LogError(f"{self.bag}: the bag breaks off while reading ({err}); the frames before were "
                           "read") from err
        finally:
            reader.close()
        for k in kept[next_k:]:
            parts = ready.pop(k, {})
            if len(parts) == 2:
                yield k, self._pair(parts)
            else:
                yield k, LogError(f"{self.bag}: frame {k} ({self.entries[k].source}): image message missing")

    @staticmethod
    def _pair(parts: dict[str, Any]) -> ImagePair | LogError:
        for role in ("rgb", "depth"):
            if isinstance(parts[role], LogError):
                error: LogError = parts[role]
                return error
        return parts["rgb"], parts["depth"]

    def _read_images(self, entry: FrameEntry) -> ImagePair:
        reader = _open_reader(self.bag, self.ros1)
        try:
            images = []
            for role, (topic, index, time_ns, rank) in zip(("rgb", "depth"), entry.locator, strict=True):
                conns = [c for c in reader.connections if c.topic == topic]
                found = reader.messages(connections=conns, start=time_ns, stop=time_ns + 1)
                for i, (conn, _, raw) in enumerate(found):
                    if i == rank:
                        images.append(self._decode(reader, conn, raw, role, index))
                        break
                else:
                    raise LogError(f"{self.bag}: {topic} #{index}: image message missing")
        finally:
            reader.close()
        return images[0], images[1]


def _collect(reader: Any) -> dict[str, _Topic]:
    out: dict[str, _Topic] = {}
    for conn in reader.connections:
        entry = out.setdefault(conn.topic, _Topic(conn.topic, conn.msgtype, 0))
        entry.count += conn.msgcount
    return out


def _size(topic: _Topic) -> tuple[int, int] | None:
    """(width, height) of a raw image topic's first message; None for compressed images."""
    if topic.msgtype != IMAGE or topic.first is None:
        return None
    return int(topic.first.width), int(topic.first.height)


def _first(reader: Any, topic: str) -> Any:
    conns = [c for c in reader.connections if c.topic == topic]
    for conn, _, raw in reader.messages(connections=conns):
        return reader.deserialize(raw, conn.msgtype)
    return None


def open_bag(path: Path, kind: str, *, poses: Trajectory | None, camera: CameraIntrinsics | None,
             max_dt_s: float, topics: BagTopics) -> BagReader:
    """Index a bag; ``kind`` is ``rosbag1``, ``rosbag2`` or ``mcap``."""
    ros1 = kind == "rosbag1"
    reader = _open_reader(path, ros1)
    try:
        return _index(path, kind, reader, ros1, poses=poses, camera=camera, max_dt_s=max_dt_s, topics=topics)
    except _bag_errors() as err:
        raise LogError(f"{path}: cannot read the bag ({err}); is it complete?") from err
    finally:
        reader.close()


def _image_topics(path: Path, found: dict[str, Any], reader: Any, topics: BagTopics) -> tuple[str, str]:
    """The colour and depth image topics: as given, else the colour-looking image topic and
    the depth-looking one nearest its name; their first messages read, their encodings checked."""
    images = [t for t in found.values() if t.msgtype in (IMAGE, COMPRESSED)]
    for t in images:
        t.first = _first(reader, t.topic)
    depth_like = [t.topic for t in images if t.first is not None and _is_depth(t.msgtype, t.first, t.topic)]
    colour_like = [t.topic for t in images if t.first is not None and t.topic not in depth_like]
    rgb_topic = _pick(path, found, topics.rgb_topic, (IMAGE, COMPRESSED), "rgb", colour_like)
    if rgb_topic is None:
        raise LogError(f"{path}: no colour image topic (sensor_msgs/Image or CompressedImage with "
                       "rgb8/bgr8); "
                       "pass --rgb-topic")
    if topics.depth_topic is None:
        depth_topic = _near(rgb_topic, depth_like)[0] if depth_like else None
    else:
        depth_topic = _pick(path, found, topics.depth_topic, (IMAGE, COMPRESSED), "depth")
    if depth_topic is None:
        raise LogError(f"{path}: no depth image topic (16UC1, mono16 or 32FC1); pass --depth-topic")
    for topic, role in ((rgb_topic, "rgb"), (depth_topic, "depth")):
        if found[topic].first is None:
            found[topic].first = _first(reader, topic)
        _check_encoding(found[topic], role, path)
    return rgb_topic, depth_topic


def _intrinsics(path: Path, found: dict[str, Any], reader: Any, topics: BagTopics,
                camera: CameraIntrinsics | None, images: tuple[str, str], sources: dict[str, str]
                ) -> CameraIntrinsics:
    """The camera's intrinsics (given, else from the CameraInfo topic nearest the colour topic;
    ``sources["camera"]`` says which), checked against the sizes of the ``images`` topics."""
    rgb_topic, depth_topic = images
    if camera is None:
        infos = [t.topic for t in found.values() if t.msgtype == CAMERA_INFO]
        info_topic = _pick(path, found, topics.info_topic, (CAMERA_INFO,), "info", _near(rgb_topic, infos))
        if info_topic is None:
            raise LogError(f"{path}: missing camera intrinsics (no sensor_msgs/CameraInfo topic); pass "
                           "--info-topic, --camera camera.json or --fx/--fy/--cx/--cy/--width/--height")
        camera = camera_from_info(_first(reader, info_topic), topics.depth_scale, f"{path} {info_topic}")
        sources["camera"] = f"{path} {info_topic}"
    else:
        sources["camera"] = "flags"
    rgb_size = _size(found[rgb_topic])
    depth_size = _size(found[depth_topic])
    if rgb_size and depth_size and rgb_size != depth_size:
        raise LogError(f"{path}: depth topic '{depth_topic}' is {depth_size[0]}×{depth_size[1]} but colour "
                       f"topic '{rgb_topic}' is {rgb_size[0]}×{rgb_size[1]}; pass --depth-topic with depth "
                       "registered to the colour camera (e.g. /camera/aligned_depth_to_color/image_raw)")
    if rgb_size and rgb_size != (camera.width, camera.height):
        raise LogError(f"{path}: colour topic '{rgb_topic}' is {rgb_size[0]}×{rgb_size[1]} but the "
                       f"intrinsics ({sources['camera']}) are for {camera.width}×{camera.height}; pass "
                       "--info-topic of the colour camera or the right --camera")
    return camera


_PoseRows = dict[str, list[tuple[float, NDArray[np.float64], str]]]


def _read_headers(
    reader: Any, ros1: bool, path: Path, found: dict[str, Any], images: tuple[str, str], det_topic: str | None
) -> tuple[dict[str, list[float]], dict[str, list[tuple[int, int]]], TfTree, _PoseRows,
           list[tuple[float, Detections]]]:
    """One pass over the bag: the colour and depth stamps (headers only) and places (bag time,
    rank), the tf tree, the pose rows per topic and the detections."""
    wanted_types = {TF, ODOMETRY, DETECTIONS, *POSE_TYPES}
    stream = {t.topic for t in found.values() if t.msgtype in wanted_types} | set(images)
    stamps: dict[str, list[float]] = {topic: [] for topic in images}
    places: dict[str, list[tuple[int, int]]] = {topic: [] for topic in images}  # (bag time, rank)
    ranks: dict[tuple[str, int], int] = {}
    tf = TfTree()
    pose_rows: _PoseRows = {}
    det_rows: list[tuple[float, Detections]] = []
    conns = [c for c in reader.connections if c.topic in stream]
    for conn, time_ns, raw in reader.messages(connections=conns):
        if conn.topic in stamps:
            stamps[conn.topic].append(_header_prefix(raw, ros1)[0])
            rank = ranks[(conn.topic, time_ns)] = ranks.get((conn.topic, time_ns), -1) + 1
            places[conn.topic].append((time_ns, rank))
            continue
        msg = reader.deserialize(raw, conn.msgtype)
        where = f"{path} {conn.topic}"
        if conn.msgtype == TF:
            static = conn.topic.endswith("tf_static")
            for tr in msg.transforms:
                tf.add(tr.header.frame_id, tr.child_frame_id, _stamp(tr.header),
                       transform_msg_to_matrix(tr.transform, where), static)
        elif conn.msgtype == DETECTIONS and conn.topic == det_topic:
            det_rows.append((_stamp(msg.header), _detections_from_msg(msg)))
        elif conn.msgtype == ODOMETRY:
            pose_rows.setdefault(conn.topic, []).append(
                (_stamp(msg.header), pose_msg_to_matrix(msg.pose.pose, where), str(msg.child_frame_id)))
        elif conn.msgtype in POSE_TYPES:
            pose = msg.pose.pose if hasattr(msg.pose, "covariance") else msg.pose
            pose_rows.setdefault(conn.topic, []).append(
                (_stamp(msg.header), pose_msg_to_matrix(pose, where), ""))
    return stamps, places, tf, pose_rows, det_rows


def _index(path: Path, kind: str, reader: Any, ros1: bool, *, poses: Trajectory | None,
           camera: CameraIntrinsics | None, max_dt_s: float, topics: BagTopics) -> BagReader:
    found = _collect(reader)
    rgb_topic, depth_topic = _image_topics(path, found, reader, topics)
    camera_frame = (topics.camera_frame or str(found[rgb_topic].first.header.frame_id)).lstrip("/")
    sources = {"rgb": f"{path} {rgb_topic}", "depth": f"{path} {depth_topic}"}
    camera = _intrinsics(path, found, reader, topics, camera, (rgb_topic, depth_topic), sources)
    det_topic = _pick(path, found, topics.detections_topic, (DETECTIONS,), "detections")
    stamps, places, tf, pose_rows, det_rows = _read_headers(reader, ros1, path, found,
                                                            (rgb_topic, depth_topic), det_topic)
    rgb_s = np.array(stamps[rgb_topic])
    depth_s = np.array(stamps[depth_topic])
    rgb_order, depth_order = np.argsort(rgb_s, kind="stable"), np.argsort(depth_s, kind="stable")
    pairs = associate(rgb_s[rgb_order], depth_s[depth_order], max_dt_s)
    if not pairs:
        raise LogError(f"{path}: no colour image on {rgb_topic} has a depth image on {depth_topic} within "
                       f"{max_dt_s} s; raise --max-dt or pick other topics")
    frame_stamps = np.array([rgb_s[rgb_order[i]] for i, _ in pairs])

    T, valid, pose_source, pose_where = _poses(path, found, topics, tf, pose_rows, poses, camera_frame,
                                               frame_stamps, max_dt_s)
    sources["poses"] = pose_where

    det_stamps = np.array([s for s, _ in det_rows])
    det_order = np.argsort(det_stamps, kind="stable")
    if det_topic is not None:
        sources["detections"] = f"{path} {det_topic}"
    entries: list[FrameEntry] = []
    index_skipped: list[tuple[str, str]] = []
    for k, (i, j) in enumerate(pairs):
        ri, di = int(rgb_order[i]), int(depth_order[j])
        source = f"{rgb_topic} #{ri} + {depth_topic} #{di}"
        stamp = float(frame_stamps[k])
        if not valid[k]:
            index_skipped.append((source, f"no pose at stamp {stamp:.6f} ({pose_source})"))
            continue
        detections = None
        if det_topic is not None:
            detections = Detections.empty()
            if len(det_stamps):
                pos = int(np.argmin(np.abs(det_stamps[det_order] - stamp)))
                if abs(det_stamps[det_order][pos] - stamp) <= max_dt_s:
                    detections = det_rows[int(det_order[pos])][1]
        locator = ((rgb_topic, ri, *places[rgb_topic][ri]), (depth_topic, di, *places[depth_topic][di]))
        entries.append(FrameEntry(stamp, T[k], source, locator, detections))
    # a damaged chunk drops its messages without an error: count them against the bag's index
    lost = {t: found[t].count - len(stamps[t]) for t in (rgb_topic, depth_topic)}
    for _ in range(max(lost.values())):
        index_skipped.append((f"{path} {rgb_topic}/{depth_topic}",
                              f"image messages unreadable ({lost[rgb_topic]} colour, "
                              f"{lost[depth_topic]} depth "
                              f"of {found[rgb_topic].count} in the bag's index): the bag is damaged"))
    if not entries:
        raise LogError(f"{path}: no colour image stamp has a pose ({pose_source}); check --pose-topic, "
                       "--map-frame/--camera-frame or pass --poses traj.txt")
    if kind == "rosbag2":
        meta = path / "metadata.yaml" if path.is_dir() else path.parent / "metadata.yaml"
        text = meta.read_text(errors="replace") if meta.is_file() else ""
        kind = "rosbag2-mcap" if "storage_identifier: mcap" in text else "rosbag2-sqlite3"
    return BagReader(
        path=str(path), format=kind, camera=camera, entries=entries, pose_source=pose_source,
        sources=sources, has_detections=det_topic is not None, index_skipped=index_skipped,
        bag=path, ros1=ros1, rgb_topic=rgb_topic, depth_topic=depth_topic, depth_scale=topics.depth_scale,
    )


def _poses(path: Path, found: dict[str, _Topic], topics: BagTopics, tf: TfTree,
           pose_rows: dict[str, list[tuple[float, NDArray[np.float64], str]]], poses: Trajectory | None,
           camera_frame: str, stamps_s: NDArray[np.float64], max_dt_s: float
           ) -> tuple[NDArray[np.float64], NDArray[np.bool_], str, str]:
    """``T_map_cam`` at ``stamps_s``, the mask of stamps with a pose, a description and the source."""
    if poses is not None:
        T, valid = poses.interpolate(stamps_s, max_extrapolation_s=max_dt_s)
        return T, valid, f"trajectory {poses.source}", poses.source
    pose_types = (TF, ODOMETRY, *POSE_TYPES)
    chosen = topics.pose_topic
    if chosen is None:
        dynamic_tf = [t.topic for t in found.values()
                      if t.msgtype == TF and not t.topic.endswith("tf_static")]
        chosen = (dynamic_tf[0] if dynamic_tf else _pick(path, found, None, (ODOMETRY,), "pose")
                  or _pick(path, found, None, POSE_TYPES, "pose"))
    else:
        _pick(path, found, chosen, pose_types, "pose")
    if chosen is None:
        raise LogError(f"{path}: no poses (no /tf, Odometry or PoseStamped topic); pass --poses traj.txt "
                       "with your SLAM trajectory in TUM format")
    if found[chosen].msgtype == TF:
        T, valid = tf.lookup(topics.map_frame, camera_frame, stamps_s, max_dt_s, f"{path} {chosen}")
        return T, valid, f"tf {topics.map_frame} -> {camera_frame}", f"{path} {chosen}"
    rows = pose_rows.get(chosen, [])
    if not rows:
        raise LogError(f"{path}: pose topic '{chosen}' has no messages; pass another --pose-topic or --poses")
    for i in range(1, len(rows)):
        if rows[i][0] < rows[i - 1][0]:
            raise LogError(f"{path} {chosen}: pose message #{i} stamp {rows[i][0]:.6f} goes back in time "
                           f"after {rows[i - 1][0]:.6f}; the recording mixes runs or clocks: cut the bag "
                           "or pass --poses traj.txt")
    keep = [0] + [i for i in range(1, len(rows)) if rows[i][0] > rows[i - 1][0]]
    trajectory = Trajectory.from_matrices(np.array([rows[i][0] for i in keep]),
                                          np.stack([rows[i][1] for i in keep]), source=f"{path} {chosen}")
    T, valid = trajectory.interpolate(stamps_s, max_extrapolation_s=max_dt_s)
    child = rows[0][2].lstrip("/")
    description = f"{found[chosen].msgtype.split('/')[-1]} {chosen}"
    if child and child != camera_frame and tf.connected(child, camera_frame):
        T_child_cam, ok = tf.lookup(child, camera_frame, stamps_s, max_dt_s, f"{path} tf")
        T = T @ T_child_cam
        valid &= ok
        description += f" composed with tf {child} -> {camera_frame}"
    return T, valid, description, f"{path} {chosen}"
