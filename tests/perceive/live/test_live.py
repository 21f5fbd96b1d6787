"""Live mode: rmw_zenoh conventions, frame assembly, replay -> perceive, readers during a run,
a publisher that dies and returns, and an independent rmw_zenoh publisher (zenoh-ros2-sdk).

Everything runs on loopback endpoints with free ports; the tests that need the Zenoh binding
skip with the reason when it is absent (pip install 'hiper[live]').
"""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import sqlite3
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.live.rmw import TYPE_HASHES, Attachment, parse_endpoint, topic_key
from tests.live_helpers import FIXTURE, ROOT, free_port, hiper, instances, wait_listening

HAS_ZENOH = importlib.util.find_spec("zenoh") is not None
needs_zenoh = pytest.mark.skipif(not HAS_ZENOH,
                                 reason="the Zenoh binding is absent: pip install 'hiper[live]'")


def _has_yolox() -> bool:
    from hiper_cli.perceive.detect.yolox import find_yolox_model

    try:
        find_yolox_model()
    except ConfigError:
        return False
    return True


needs_yolox = pytest.mark.skipif(not _has_yolox(), reason="YOLOX-Nano model absent (set HIPER_MODELS)")


# --- conventions (no network) ---------------------------------------------------------------
def test_key_expressions_follow_rmw_zenoh():
    assert topic_key("/camera/color/image_raw", "sensor_msgs/msg/Image") == (
        "0/camera/color/image_raw/sensor_msgs::msg::dds_::Image_/" + TYPE_HASHES["sensor_msgs/msg/Image"])
    assert topic_key("/tf", "tf2_msgs/msg/TFMessage", domain_id=7, type_hash="*") == (
        "7/tf/tf2_msgs::msg::dds_::TFMessage_/*")


def test_attachment_layout_is_sequence_time_gid():
    data = Attachment(3, 1_700_000_000_123_456_789, bytes(range(16))).to_bytes()
    assert data[:8] == (3).to_bytes(8, "little")
    assert data[8:16] == (1_700_000_000_123_456_789).to_bytes(8, "little")
    assert data[16] == 16 and data[17:] == bytes(range(16))
    assert Attachment.from_bytes(data) == Attachment(3, 1_700_000_000_123_456_789, bytes(range(16)))
    assert Attachment.from_bytes(data[:20]) is None


@pytest.mark.parametrize(("url", "endpoint"), [
    ("zenoh://tcp/127.0.0.1:7447", "tcp/127.0.0.1:7447"),
    ("zenoh:/tcp/10.0.0.2:7448", "tcp/10.0.0.2:7448"),  # what a shell path argument becomes
    ("zenoh://", "tcp/127.0.0.1:7447"),
])
def test_endpoints(url, endpoint):
    assert parse_endpoint(url) == endpoint


@pytest.mark.parametrize("url", ["zenoh://localhost", "zenoh://tcp/127.0.0.1", "http://x:1"])
def test_bad_endpoints_say_what_is_expected(url):
    with pytest.raises(ConfigError, match="zenoh://tcp/HOST:PORT"):
        parse_endpoint(url)


def test_without_zenoh_the_error_names_the_extra(monkeypatch):
    from hiper_cli.perceive.live.rmw import zenoh_module

    monkeypatch.setitem(sys.modules, "zenoh", None)
    with pytest.raises(ConfigError, match=r"pip install 'hiper\[live\]'"):
        zenoh_module()


def test_a_bad_live_url_is_one_line_and_makes_no_kb(tmp_path):
    proc = hiper("perceive", "zenoh://localhost", "--kb", str(tmp_path / "kb"))
    out, _ = proc.communicate(timeout=60)
    assert proc.returncode != 0 and "expected zenoh://tcp/HOST:PORT" in out and "Traceback" not in out
    assert not (tmp_path / "kb").exists()


@pytest.mark.parametrize(("source", "flag"), [("zenoh://", "--view"), ("zenoh://", "--resume"),
                                            (str(FIXTURE), "--stats"), (str(FIXTURE), "--look-ahead")])
def test_flags_of_the_other_kind_of_source_are_refused(tmp_path, source, flag):
    proc = hiper("perceive", source, "--kb", str(tmp_path / "kb"), flag)
    out, _ = proc.communicate(timeout=60)
    assert proc.returncode != 0 and f"{flag} is for" in out and "Traceback" not in out
    assert not (tmp_path / "kb").exists()


# --- zenoh-ros2-sdk as the reference --------------------------------------------------------
@pytest.fixture(scope="module")
def msg_dir(tmp_path_factory):
    """The .msg files of the published types (rosbags' ROS 2 definitions), so no network is needed."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    out = tmp_path_factory.mktemp("msgs")
    for msgtype in TYPE_HASHES:
        text, _ = store.generate_msgdef(msgtype, ros_version=2)
        for k, part in enumerate(text.split("=" * 80 + "\n")):
            name = msgtype
            if k:
                first, _, part = part.partition("\n")
                name = first.removeprefix("MSG: ")
            package, leaf = name.split("/")[0], name.split("/")[-1]
            path = out / package / "msg" / f"{leaf}.msg"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(part)
    return out


def test_type_hashes_match_zenoh_ros2_sdk(msg_dir):
    pytest.importorskip("zenoh_ros2_sdk", reason="zenoh-ros2-sdk is absent: pip install 'hiper[dev]'")
    from zenoh_ros2_sdk.message_registry import MessageRegistry
    from zenoh_ros2_sdk.utils import get_type_hash, load_dependencies_recursive, ros2_to_dds_type

    registry = MessageRegistry(str(msg_dir))
    for msgtype, expected in TYPE_HASHES.items():
        text = (msg_dir / msgtype.split("/")[0] / "msg" / f"{msgtype.split('/')[-1]}.msg").read_text()
        deps = load_dependencies_recursive(msgtype, text, registry)
        assert get_type_hash(msgtype, msg_definition=text, dependencies=deps) == expected, msgtype
        assert topic_key("/x", msgtype).split("/")[2] == ros2_to_dds_type(msgtype)


# zenoh-ros2-sdk 0.1.8 declares its publishers without a congestion control on zenoh 1.x (it
# looks for zenoh.qos.CongestionControl), so Zenoh's default applies: drop a message when the
# send queue stays full for 1 ms, which lost 1 to 3 of 60 frames per run on this loaded machine.
# Its sessions read ZENOH_CONFIG_OVERRIDE: let a full queue wait 200 ms before dropping.
SDK_NO_DROP = "transport/link/tx/queue/congestion_control/drop/wait_before_drop=200000"


@needs_zenoh
@needs_yolox
def test_sdk_publisher_builds_the_same_kb_as_the_log(tmp_path, msg_dir):
    """(a) an independent rmw_zenoh publisher, hiper perceive zenoh:// vs the log itself."""
    pytest.importorskip("zenoh_ros2_sdk", reason="zenoh-ros2-sdk is absent: pip install 'hiper[dev]'")
    port = free_port()
    live = hiper("perceive", f"zenoh://tcp/127.0.0.1:{port}", "--kb", str(tmp_path / "live"),
                 "--queue", "200", "--look-ahead", "--idle-timeout", "4", "--json")
    direct = hiper("perceive", str(FIXTURE), "--kb", str(tmp_path / "direct"), "--json",
                   stdout=subprocess.DEVNULL)
    wait_listening(port)
    script = str(ROOT / "tests" / "live_sdk_publisher.py")
    pub = subprocess.run([sys.executable, script, str(FIXTURE), str(port), str(msg_dir), "5"], cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": str(ROOT), "ZENOH_CONFIG_OVERRIDE": SDK_NO_DROP},
                         capture_output=True, text=True, timeout=120)
    assert pub.returncode == 0, pub.stderr
    assert "published 60" in pub.stdout
    out, _ = live.communicate(timeout=180)
    assert live.returncode == 0, out
    assert direct.wait(timeout=180) == 0
    summary = json.loads(out[out.index("{"):])
    live_report = json.dumps(summary["live"])
    assert summary["frames_read"] == 60 and summary["live"]["frames_dropped"] == 0, live_report
    got, want = instances(tmp_path / "live"), instances(tmp_path / "direct")
    assert [(layer, cls) for layer, cls, _ in got] == [(layer, cls) for layer, cls, _ in want]
    gaps = [float(np.linalg.norm(a[2] - b[2])) for a, b in zip(got, want, strict=True)]
    assert max(gaps) <= 0.01, gaps


@needs_zenoh
def test_sdk_subscriber_decodes_what_replay_publishes(msg_dir):
    """Our key expressions, type hashes, CDR and attachments, read by zenoh-ros2-sdk's subscriber."""
    pytest.importorskip("zenoh_ros2_sdk", reason="zenoh-ros2-sdk is absent: pip install 'hiper[dev]'")
    from hiper_cli.perceive.live.replay import replay_frames
    from hiper_cli.perceive.logs import open_log

    port = free_port()
    script = str(ROOT / "tests" / "live_sdk_subscriber.py")
    sub = subprocess.Popen([sys.executable, script, str(port), str(msg_dir), "9"], cwd=ROOT, text=True,
                           env={**os.environ, "PYTHONPATH": str(ROOT)}, stdout=subprocess.PIPE)
    reader = open_log(FIXTURE)
    frames = [f for k, f in enumerate(reader) if k < 10]
    summary = replay_frames(frames, reader.info().camera, f"tcp/127.0.0.1:{port}", hz=5.0, start_delay_s=4.0)
    out, _ = sub.communicate(timeout=60)
    assert summary.how == "listening" and sub.returncode == 0, out
    seen = json.loads(out.strip().splitlines()[-1])
    assert {name: seen[name]["count"] for name in ("rgb", "depth", "info", "tf")} == dict.fromkeys(
        ("rgb", "depth", "info", "tf"), 10)
    first = frames[0]
    assert seen["rgb"]["first"] == {"stamp": [0, 0], "frame_id": "camera_color_optical_frame",
                                    "encoding": "rgb8", "size": [256, 192], "bytes": 256 * 192 * 3}
    assert seen["depth"]["first"]["encoding"] == "32FC1" and seen["depth"]["first"]["bytes"] == 256 * 192 * 4
    assert seen["info"]["first"]["k"] == pytest.approx(first.camera.K.reshape(-1).tolist())
    tf = seen["tf"]["first"]
    assert tf["parent"] == "map" and tf["child"] == "camera_color_optical_frame"
    assert tf["x"] == pytest.approx(float(first.T_map_cam[0, 3]))


# --- replay -> perceive ---------------------------------------------------------------------
@needs_zenoh
def test_replay_delivers_the_log_frames_unchanged():
    """(b) every frame, pixel for pixel, with its stamp and pose, through rmw_zenoh messages."""
    from hiper_cli.perceive.live.replay import replay_frames
    from hiper_cli.perceive.live.source import LiveSource
    from hiper_cli.perceive.logs import LogOptions, open_log

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    source = LiveSource(endpoint, LogOptions(), capacity=100, idle_timeout_s=2.0, silence_s=1.0)
    source.start()
    reader = open_log(FIXTURE)
    thread = threading.Thread(target=replay_frames, args=(reader, reader.info().camera, endpoint),
                              kwargs={"hz": 30.0}, daemon=True)
    thread.start()
    try:
        frames = list(source)
    finally:
        source.close()
    thread.join(timeout=30)
    want = list(open_log(FIXTURE))
    assert len(frames) == len(want) == 60
    assert source.sync.dropped == 0 and source.counts.bad_messages == 0
    for got, ref in zip(frames, want, strict=True):
        assert got.stamp_s == pytest.approx(ref.stamp_s, abs=1e-6)
        assert np.array_equal(got.rgb, ref.rgb) and np.array_equal(got.depth_m, ref.depth_m)
        assert np.allclose(got.T_map_cam, ref.T_map_cam, atol=1e-9)
        assert got.extras["sent_s"] == pytest.approx(time.time(), abs=60)


@needs_zenoh
@pytest.mark.parametrize("variant", ["compressed", "odometry", "base_frame", "late_subscriber"])
def test_other_topic_layouts_are_read_live(variant):
    """PNG CompressedImage colour (on <topic>/compressed, as image_transport names it); poses
    from nav_msgs/Odometry; /tf to a base frame plus a static base -> camera on /tf_static."""
    from dataclasses import replace

    from hiper_cli.perceive.live.replay import REPLAY_LAYOUT, replay_frames
    from hiper_cli.perceive.live.source import LiveSource
    from hiper_cli.perceive.logs import LogOptions, open_log

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    layout, options = REPLAY_LAYOUT, LogOptions()
    if variant == "compressed":
        layout = replace(layout, rgb_format="png")
        options = LogOptions(rgb_topic="/camera/color/image_raw/compressed")
    elif variant == "odometry":
        layout = replace(layout, pose_as="odometry", pose_topic="/odom")
        options = LogOptions(pose_topic="/odom")
    else:
        layout = replace(layout, base_frame="base_link")
    source = LiveSource(endpoint, options, capacity=100, idle_timeout_s=2.0, silence_s=1.0)
    reader = open_log(FIXTURE)
    frames = [f for k, f in enumerate(reader) if k < 10]
    late = variant == "late_subscriber"  # /tf_static went out before the subscriber started
    if not late:
        source.start()
    thread = threading.Thread(target=replay_frames, args=(frames, reader.info().camera, endpoint),
                              kwargs={"hz": 4.0 if late else 20.0, "layout": layout}, daemon=True)
    thread.start()
    if late:
        time.sleep(2.0)
        source.start()
    try:
        got = list(source)
    finally:
        source.close()
    thread.join(timeout=30)
    if late:  # the frames from the subscriber's start on, with poses through the cached static tf
        assert 2 <= len(got) < 10
        frames = frames[len(frames) - len(got):]
    assert len(got) == len(frames) and not source.skipped
    assert all(np.array_equal(a.rgb, b.rgb) for a, b in zip(got, frames, strict=True))
    assert all(np.allclose(a.T_map_cam, b.T_map_cam, atol=1e-9) for a, b in zip(got, frames, strict=True))


def _snapshot(db: Path) -> tuple[int, int, list[tuple[int, int]]]:
    """In one read transaction: frames the session row says, pose rows, and per frame stamp
    (µs) the observations written with it."""
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, isolation_level=None)
    try:
        con.execute("BEGIN")
        said = con.execute("SELECT COALESCE(SUM(frames), 0) FROM sessions").fetchone()[0]
        poses = con.execute("SELECT COUNT(*) FROM poses").fetchone()[0]
        per_stamp = con.execute("SELECT CAST(ROUND(stamp_s * 1e6) AS INTEGER), COUNT(*) FROM docs "
                                "WHERE type = 'observation' GROUP BY 1").fetchall()
        con.execute("COMMIT")
    finally:
        con.close()
    return int(said), int(poses), [(int(a), int(b)) for a, b in per_stamp]


@needs_zenoh
@needs_yolox
def test_queries_during_a_live_run_see_only_whole_frames(tmp_path):
    """(c) a reader asking every 100 ms while hiper replay -> hiper perceive runs."""
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.query import ask

    port, kb = free_port(), tmp_path / "kb"
    # every observation kept: the final per-frame counts are those written (summarising at the
    # end of the session would drop some after the run; test_memory_compact covers it)
    live = hiper("perceive", f"zenoh://tcp/127.0.0.1:{port}", "--kb", str(kb), "--idle-timeout", "3",
                 "--keep-observations", "all", "--json")
    wait_listening(port)
    replay = hiper("replay", str(FIXTURE), f"zenoh://tcp/127.0.0.1:{port}", "--hz", "10",
                   stdout=subprocess.DEVNULL)
    errors: list[str] = []
    snapshots = []
    answers = 0
    held = None  # a reader open for the whole run, as hiper serve and hiper mcp are
    held_counts: list[int] = []
    count = "SELECT (COUNT(*) AS ?n) WHERE { ?s ?p ?o }"
    while live.poll() is None:
        time.sleep(0.1)
        db = kb / "documents.sqlite"
        if not _has_schema(db):
            continue
        try:
            snapshots.append(_snapshot(db))
            with open_kb_for_reading(str(kb)) as knowledge:
                ask(knowledge, "chairs")
            answers += 1
            if held is None and snapshots[-1][1] > 0:
                held = open_kb_for_reading(str(kb))
            if held is not None:
                body = json.loads(held.run_readonly(count)[0])
                held_counts.append(int(body["results"]["bindings"][0]["n"]["value"]))
        except Exception as err:  # any reader error fails the test
            errors.append(f"{type(err).__name__}: {err}")
    if held is not None:
        held.close()
    out = live.stdout.read() if live.stdout else ""
    assert replay.wait(timeout=30) == 0 and live.returncode == 0, out
    assert not errors, "\n".join(errors[:3])
    assert answers >= 10
    assert held_counts and held_counts[-1] > held_counts[0]  # the held reader follows the run
    final = dict(_snapshot(kb / "documents.sqlite")[2])
    during = [s for s in snapshots if s[1] > 0]
    assert len(during) >= 10
    for said, poses, per_stamp in during:
        assert said == poses  # the session's progress and its pose rows are written together
        for stamp, count in per_stamp:  # each frame's observations are all there, or none
            assert count == final.get(stamp), (stamp, count, final.get(stamp))


@needs_zenoh
@needs_yolox
def test_publisher_killed_mid_run_then_back(tmp_path):
    """(d) the silence is reported, the knowledge base stays consistent, the run resumes."""
    from hiper_cli.graph import open_kb

    port, kb = free_port(), tmp_path / "kb"
    url = f"zenoh://tcp/127.0.0.1:{port}"
    live = hiper("perceive", url, "--kb", str(kb), "--idle-timeout", "10")
    wait_listening(port)
    first = hiper("replay", str(FIXTURE), url, "--hz", "10", stdout=subprocess.DEVNULL)
    time.sleep(4.0)
    first.send_signal(signal.SIGKILL)
    first.wait(timeout=10)
    time.sleep(3.0)  # the silence is reported after 2 s; the idle timeout leaves room for a restart
    second = hiper("replay", str(FIXTURE), url, "--hz", "10", stdout=subprocess.DEVNULL)
    assert second.wait(timeout=60) == 0
    out, _ = live.communicate(timeout=60)
    assert live.returncode == 0, out
    assert "silent: no frames for" in out and "resumed: frames again after" in out, out
    flat = " ".join(out.split())
    assert "ended by idle timeout" in flat, out
    with open_kb(str(kb)) as knowledge:
        report = knowledge.check(repair=False)
        session = knowledge.docs.find(type="environment")
    assert not report.problems, report.problems
    assert session
    said, poses, _ = _snapshot(kb / "documents.sqlite")
    assert said == poses, out
    con = sqlite3.connect(f"file:{kb / 'documents.sqlite'}?mode=ro", uri=True)
    stamps = [row[0] for row in con.execute("SELECT stamp_s FROM poses ORDER BY pose_id")]
    con.close()
    # the second replay starts the log over: its frames follow the first run's, stamps restart
    restart = [k for k in range(1, len(stamps)) if stamps[k] < stamps[k - 1]]
    assert len(restart) == 1 and 0 < restart[0] < len(stamps) - 1, stamps


@needs_zenoh
@needs_yolox
def test_ctrl_c_ends_the_session_with_everything_written(tmp_path):
    """SIGINT: the frame in hand is finished, the session closed, the summary printed."""
    from hiper_cli.graph import open_kb

    port, kb = free_port(), tmp_path / "kb"
    url = f"zenoh://tcp/127.0.0.1:{port}"
    live = hiper("perceive", url, "--kb", str(kb), "--json")
    wait_listening(port)
    replay = hiper("replay", str(FIXTURE), url, "--hz", "10", stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and _snapshot_or_none(kb) < 3:
        time.sleep(0.2)
    live.send_signal(signal.SIGINT)
    out, _ = live.communicate(timeout=60)
    replay.kill()
    replay.wait(timeout=10)
    assert live.returncode == 0, out
    summary = json.loads(out[out.index("{"):])
    assert summary["live"]["stopped_by"] == "interrupt" and summary["frames_read"] >= 3
    with open_kb(str(kb)) as knowledge:
        assert not knowledge.check(repair=False).problems
    con = sqlite3.connect(f"file:{kb / 'documents.sqlite'}?mode=ro", uri=True)
    ended, frames = con.execute("SELECT ended_s, frames FROM sessions").fetchone()
    con.close()
    assert ended is not None and frames == summary["frames_read"]


def _has_schema(db: Path) -> bool:
    """The store exists and its tables are committed (the file appears before the writer's
    first transaction creates them)."""
    if not db.exists():
        return False
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        return con.execute("SELECT 1 FROM sqlite_master WHERE name = 'sessions'").fetchone() is not None
    finally:
        con.close()


def _snapshot_or_none(kb: Path) -> int:
    db = kb / "documents.sqlite"
    return _snapshot(db)[1] if _has_schema(db) else 0
