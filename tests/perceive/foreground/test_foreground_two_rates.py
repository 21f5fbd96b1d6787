"""Two rates (``keyframes.py``, ``held.py``): every frame is tracked, the detector looks ten times a
second (every third frame of a 30 Hz log) and at every keyframe; the frames between hold the last
look's names, moved with the camera, and count as those frames' own."""

import numpy as np

from hiper_cli.perceive.detect.recorded import LogDetector
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.held import HeldDetections
from hiper_cli.perceive.foreground.keyframes import KeyframeLook
from hiper_cli.perceive.stage import World
from tests import REPO_ROOT
from tests.fg_constants import set_constants
from tests.fg_scene import CAMERA, background_instances, chair, make_frame, pose_looking_x, room


class CountingDetector:
    """The frames' own (true) detections, as a detector that looks at the image would give them:
    records the frames it looked at."""

    name = "counting"

    def __init__(self):
        self.inner = LogDetector()
        self.looked = []

    def detect(self, frame):
        if frame.width == CAMERA.width:  # a keyframe's tiles are not the quick look
            self.looked.append(frame.pose_id)
        return self.inner.detect(frame)


def _schedule(rate_hz, n, closer_look_s=0.0, monkeypatch=None):
    set_constants(monkeypatch, closer_look_s=closer_look_s)
    look = KeyframeLook(CountingDetector(), "counting", detector_hz=10.0)
    frames = [make_frame(room(), pose_looking_x(), k / rate_hz, k) for k in range(n)]
    return [f.pose_id for f in frames if look.schedule(f)[0]]


def test_the_quick_look_runs_ten_times_a_second(monkeypatch):
    assert _schedule(30.0, 12, monkeypatch=monkeypatch) == [0, 3, 6, 9]
    assert _schedule(20.0, 8, monkeypatch=monkeypatch) == [0, 2, 4, 6]
    assert _schedule(15.0, 4, monkeypatch=monkeypatch) == [0, 1, 2, 3]  # every frame: 15 Hz is near 10
    assert _schedule(60.0, 14, monkeypatch=monkeypatch) == [0, 6, 12]


def test_detector_hz_0_looks_at_every_frame(monkeypatch):
    set_constants(monkeypatch, closer_look_s=0.0)
    look = KeyframeLook(CountingDetector(), "counting", detector_hz=0.0)
    assert all(look.schedule(make_frame(room(), pose_looking_x(), k / 30.0, k))[0] for k in range(6))


def test_every_keyframe_gets_the_quick_look(monkeypatch):
    # keyframes 0.2 s apart: frames 0, 6, 12 (each then every third frame after it)
    assert _schedule(30.0, 14, closer_look_s=0.2, monkeypatch=monkeypatch) == [0, 3, 6, 9, 12]
    assert _schedule(30.0, 14, closer_look_s=0.15, monkeypatch=monkeypatch) == [0, 3, 5, 8, 10, 13]


def test_a_replayed_detector_is_read_on_every_frame(monkeypatch):
    set_constants(monkeypatch, closer_look_s=0.0)
    look = KeyframeLook(LogDetector(), "log", detector_hz=10.0)
    assert all(look.schedule(make_frame(room(), pose_looking_x(), k / 30.0, k))[0] for k in range(6))


def test_held_boxes_move_with_the_camera():
    """A chair 4 m ahead (its front face at 3.75 m), the camera then 0.2 m to its left: the box
    lies 100 × 0.2 / 3.75 = 5.3 px further right in the image, its size unchanged."""
    boxes = [*room(), chair(11, 4.0, 0.0)]
    first = make_frame(boxes, pose_looking_x(), 0.0, 0)
    later = make_frame(boxes, pose_looking_x(y=0.2), 1 / 30, 1)
    held = HeldDetections()
    assert len(held.at(later)) == 0  # nothing held before the first look
    held.keep(first, first.detections)
    (moved,) = held.at(later).xyxy
    shift = moved - first.detections.xyxy[0]
    assert np.allclose(shift[[0, 2]], 100 * 0.2 / 3.75, atol=0.1)
    assert np.allclose(shift[[1, 3]], 0.0)
    assert np.allclose(moved, later.detections.xyxy[0], atol=1.5)  # where the detector would see it


def _run_by_hand(frames, stage):
    """Each frame through the stage in order (no finish: the live tracks stay to be read)."""
    world = World(background=background_instances(room()))
    observations = []
    for frame in frames:
        result = stage.process(frame, world)
        world.apply(result)
        observations.extend(result.observations)
    return observations


def _passing_chair():
    """The camera passes a chair 4 m away at 3 m/s (2.5 px a frame in the image)."""
    return [make_frame([*room(), chair(11, 4.0, -1.0)], pose_looking_x(y=-0.1 * k), k / 30.0, k)
            for k in range(30)]


def test_a_track_keeps_its_class_between_looks(monkeypatch):
    """The frames the detector does not look at name the chair by the last look's box, moved
    with the camera: the track's tallies are those of a detector that looked at every frame."""
    set_constants(monkeypatch, closer_look_s=0.0)
    detector = CountingDetector()
    stage = ForegroundStage(detector_instance=detector, pixel_step=2, detector_hz=10.0)
    observations = _run_by_hand(_passing_chair(), stage)
    assert detector.looked == list(range(0, 30, 3))
    (track,) = stage.tracker.tracks
    assert track.hits == 30 and track.class_name == "chair"
    assert [o.class_name for o in observations] == ["chair"] * 30
    held = [o.pose_id for o in observations if o.data["detection"].get("held")]
    assert held == [k for k in range(30) if k % 3]
    every = CountingDetector()  # the detector on every frame (detector_hz 0, the default)
    looked_all = ForegroundStage(detector_instance=every, pixel_step=2)
    _run_by_hand(_passing_chair(), looked_all)
    assert every.looked == list(range(30))
    (same,) = looked_all.tracker.tracks
    assert track.class_counts == same.class_counts == {"chair": 30}
    assert track.full_views == same.full_views and track.full_named == same.full_named


def test_without_moving_them_the_held_boxes_would_miss_the_chair(monkeypatch):
    """The same pass with boxes held where the last look saw them: 5 px off two frames later, the
    chair's blob no longer overlaps its box by the IoU the match asks (the move is what holds)."""
    import hiper_cli.perceive.foreground.held as held

    set_constants(monkeypatch, closer_look_s=0.0)
    monkeypatch.setattr(held, "_moved", lambda box, *_: box)
    observations = _run_by_hand(_passing_chair(), ForegroundStage(detector_instance=CountingDetector(),
                                                                  pixel_step=2, detector_hz=10.0))
    assert "unknown" in [o.class_name for o in observations]


def test_perceive_detector_hz_sets_the_foreground_rate_and_refuses_a_negative_one(tmp_path):
    from typer.testing import CliRunner

    from hiper_cli.cli import app
    from hiper_cli.cmdline.perceive import perceive_options

    flags = dict(stages=None, option=None, env=None, resume=False, replace=False, again=False, align="auto",
                 keep_observations="0", detector=None, no_background_filter=False, classes=None,
                 exclude_classes=None, mapping_hz=None)
    assert perceive_options(**flags, detector_hz=10.0).stage_options["foreground"] == {"detector_hz": 10.0}
    assert "detector_hz" not in perceive_options(**flags).stage_options.get("foreground", {})
    result = CliRunner().invoke(app, ["perceive", str(REPO_ROOT / "fixtures" / "house_small"),
                                      "--kb", str(tmp_path / "kb"), "--detector-hz", "-1"])
    assert result.exit_code != 0 and "--detector-hz -1" in result.output
    assert not (tmp_path / "kb").exists()
