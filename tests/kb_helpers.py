"""Helpers for the knowledge-base tests: tiny frames built in code and a deterministic stage."""

from __future__ import annotations

import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from hiper_cli.model import Box3D, Instance, Observation
from hiper_cli.perceive.stage import FrameResult, World
from hiper_cli.types import CameraIntrinsics, Frame

CAMERA = CameraIntrinsics(width=8, height=6, fx=5.0, fy=5.0, cx=4.0, cy=3.0)


def make_frame(pose_id: int, x_m: float = 0.0) -> Frame:
    T = np.eye(4)
    T[0, 3] = x_m
    return Frame(
        stamp_s=10.0 + 0.1 * pose_id,
        rgb=np.zeros((6, 8, 3), np.uint8),
        depth_m=np.ones((6, 8), np.float32),
        camera=CAMERA,
        T_map_cam=T,
        pose_id=pose_id,
        source=f"frame{pose_id}",
    )


class FrameList:
    """A minimal log reader over frames built in code."""

    def __init__(self, frames: list[Frame], path: str = "/logs/codelog") -> None:
        self.frames = frames
        self.path = path
        self.skipped: list[tuple[str, str]] = [("frame-x", "unreadable png (test)")]

    def __iter__(self) -> Any:
        return iter(self.frames)

    def __len__(self) -> int:
        return len(self.frames)

    def info(self) -> Any:
        from types import SimpleNamespace

        return SimpleNamespace(path=self.path)


class ProbeStage:
    """Deterministic stage: one background 'floor' instance fed by one observation per frame,
    and foreground 'cup' tracks of 4 frames; every 6th frame merges the previous track away."""

    name = "probe"

    def __init__(self, log_path: Path | None = None, track_frames: int = 4, **_: Any) -> None:
        self.log_path = log_path
        self.track_frames = int(track_frames)
        self.track: Instance | None = None
        self.previous: Instance | None = None
        self.frames = 0

    def process(self, frame: Frame, world: World) -> FrameResult:
        self.frames += 1
        result = FrameResult()
        floor = next(iter(world.background.values()), None)
        o_bg = Observation("background", "floor", 0.9, frame.stamp_s, frame.pose_id,
                           Box3D(np.array([0.0, 1.0, 2.0]), np.array([4.0, 0.02, 4.0])))
        if floor is None:
            floor = Instance("background", "floor", Box3D(np.zeros(3), np.array([4.0, 4.0, 0.02])),
                             frame.stamp_s, frame.stamp_s)
        floor.observation_uuids.append(o_bg.uuid)
        floor.last_seen_s = frame.stamp_s
        o_bg.instance_uuid = floor.uuid
        if self.track is None or frame.pose_id % self.track_frames == 0:
            self.previous, self.track = self.track, Instance(
                "foreground", "cup", Box3D(np.zeros(3), np.full(3, 0.1)), frame.stamp_s, frame.stamp_s,
                state="dynamic")
        center_cam = np.array([0.1 * frame.pose_id, 0.0, 1.0])
        o_fg = Observation("foreground", "cup", 0.8, frame.stamp_s, frame.pose_id,
                           Box3D(center_cam, np.full(3, 0.1)), instance_uuid=self.track.uuid,
                           data={"image_box_xyxy": [1.0, 1.0, 3.0, 3.0]})
        T = frame.T_map_cam
        self.track.box = Box3D(T[:3, :3] @ center_cam + T[:3, 3], np.full(3, 0.1))
        self.track.observation_uuids.append(o_fg.uuid)
        self.track.last_seen_s = frame.stamp_s
        row = [frame.stamp_s, *self.track.box.center_m.tolist(), 0.0, 0.0, 0.0]
        self.track.data.setdefault("trajectory", []).append(row)
        result.observations += [o_bg, o_fg]
        result.instances += [floor, self.track]
        if frame.pose_id % 6 == 5 and self.previous is not None:
            result.deleted_instances.append(self.previous.uuid)
            self.previous = None
        return result

    def finish(self, world: World) -> FrameResult:
        return FrameResult()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def oxigraph_binary() -> str | None:
    import shutil

    local = Path(sys.executable).parent / "oxigraph"
    return str(local) if local.exists() else shutil.which("oxigraph")


def start_oxigraph(location: Path) -> tuple[subprocess.Popen[bytes], str]:
    binary = oxigraph_binary()
    assert binary is not None
    port = free_port()
    proc = subprocess.Popen([binary, "serve", "--location", str(location), "--bind", f"127.0.0.1:{port}"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        try:
            req = urllib.request.Request(url + "/query", data=b"ASK {}", method="POST",
                                         headers={"Content-Type": "application/sparql-query"})
            urllib.request.urlopen(req, timeout=1).read()
            return proc, url
        except OSError:
            if proc.poll() is not None:
                raise RuntimeError("oxigraph server exited at start") from None
            time.sleep(0.1)
    proc.kill()
    raise RuntimeError("oxigraph server did not answer within 20 s")


@pytest.fixture(scope="module")
def sparql_url(tmp_path_factory):
    if oxigraph_binary() is None:
        pytest.skip("the oxigraph server (pip install oxigraph, in the dev extra) is not installed")
    proc, url = start_oxigraph(tmp_path_factory.mktemp("oxigraph"))
    yield url
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture(params=["local", "sparql"])
def kb_location(request, tmp_path):
    """(location, docs_dir) for open_kb: a directory, or the server URL plus a documents dir."""
    if request.param == "local":
        return str(tmp_path / "scene.hiper"), None
    return request.getfixturevalue("sparql_url"), tmp_path / "docs.hiper"


def small_kb(root: Path) -> Any:
    """An open knowledge base of one session (log "/logs/flat", place "flat") of three frames at
    0, 1 and 2 s: a chair seen in each, a person walking along x at 0.5 m/s, a floor."""
    from hiper_cli.graph import open_kb

    kb = open_kb(root)
    env = kb.environment("flat")
    session = kb.start_session(env, "/logs/flat", ["background", "foreground"])
    chair = Instance("foreground", "chair", Box3D(np.array([1.0, 2.0, 0.45]), np.array([0.5, 0.5, 0.9])),
                     0.0, 0.0)
    person = Instance("foreground", "person", Box3D(np.array([3.0, 1.0, 0.9]), np.array([0.5, 0.4, 1.7])),
                      0.0, 0.0, state="dynamic")
    floor = Instance("background", "floor", Box3D(np.array([2.0, 2.0, -0.01]), np.array([6.0, 6.0, 0.02])),
                     0.0, 0.0)
    rows = []
    for k in range(3):
        stamp_s = float(k)
        rows.append([stamp_s, 3.0 + 0.5 * k, 1.0, 0.9, 0.5, 0.0, 0.0])
        seen = Observation("foreground", "chair", 0.9, stamp_s, k, Box3D(np.array([1.0, 2.0, 2.0]),
                                                                       np.array([0.5, 0.5, 0.9])),
                           instance_uuid=chair.uuid)
        chair.observation_uuids.append(seen.uuid)
        chair.last_seen_s = person.last_seen_s = floor.last_seen_s = stamp_s
        person.box = Box3D(np.array(rows[-1][1:4]), person.box.extent_m)
        person.data = {"trajectory": [list(r) for r in rows]}
        T_map_cam = np.eye(4)
        kb.write_frame(session, FrameResult(observations=[seen], instances=[chair, person, floor]),
                       pose_id=k, stamp_s=stamp_s, T_map_cam=T_map_cam)
    kb.end_session(session)
    kb.sync_graph()
    return kb
