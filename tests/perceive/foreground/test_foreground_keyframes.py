"""Two rates (``keyframes.py``): keyframes get a closer look, tiled, one tile a frame; a small
thing the every-frame look cannot name is named by the closer looks' own vote."""

import numpy as np

from hiper_cli.perceive.detect.tiled import tile_boxes
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground import keyframes as kf
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import World
from hiper_cli.types import Detections
from tests.fg_constants import set_constants
from tests.fg_scene import CAMERA, SceneBox, background_instances, chair, make_frame, pose_looking_x, room

RATE_HZ = 30.0
INPUT_PX = 96  # the stand-in detector's input: the 160 px image shrinks to 0.6, a tile to 1.04
LEAST_PX = 12  # ... and it names what is still this many of its input pixels across


class FixedInputDetector:
    """Stands for a detector of fixed input size: the truth's boxes of the image it is given (a
    tile's found by the shift of its principal point), kept where they lie whole in that image
    and are ``LEAST_PX`` across once the image is shrunk to ``INPUT_PX``. Records the width of
    each image it was given and the frame it came from."""

    name = "fixed-input"
    class_names = ("suitcase", "chair", "person")

    def __init__(self, frames):
        self.truth = {f.stamp_s: f.detections for f in frames}
        self.calls = []

    def detect(self, frame):
        self.calls.append((frame.pose_id, frame.width))
        truth = self.truth[frame.stamp_s]
        shift = np.array([CAMERA.cx - frame.camera.cx, CAMERA.cy - frame.camera.cy] * 2)
        xyxy = truth.xyxy - shift
        scale = INPUT_PX / max(frame.width, frame.height)
        inside = (xyxy[:, :2] >= 0).all(axis=1) & (xyxy[:, 2] <= frame.width) & (xyxy[:, 3] <= frame.height)
        across = np.maximum(xyxy[:, 2] - xyxy[:, 0], xyxy[:, 3] - xyxy[:, 1]) * scale
        keep = inside & (across >= LEAST_PX)
        return Detections(xyxy[keep], tuple(n for n, k in zip(truth.class_names, keep, strict=True) if k),
                          truth.scores[keep])


def suitcase():
    """A 0.4 m suitcase on the floor 3 m ahead, left: 13 px across, in the bottom-left tile."""
    return SceneBox(12, np.array([3.0, 0.8, 0.2]), np.array([0.4, 0.4, 0.4]), "suitcase")


def run(frames, detector, detector_hz=0.0):
    stage = ForegroundStage(detector_instance=detector, pixel_step=2, detector_hz=detector_hz)
    world, _ = run_stages(frames, [stage], World(background=background_instances(room())))
    return sorted(i.class_name for i in world.foreground.values())


def still_frames(n=60):
    return [make_frame([*room(), suitcase(), chair(11, 4.0, -1.0)], pose_looking_x(), k / RATE_HZ, k)
            for k in range(n)]


def test_a_keyframes_closer_look_names_what_the_every_frame_look_misses(monkeypatch):
    set_constants(monkeypatch, closer_look_s=0.5)
    frames = still_frames()
    detector = FixedInputDetector(frames)
    assert len(detector.detect(frames[0])) == 1  # the every-frame look: the chair, not the suitcase
    assert run(frames, detector, detector_hz=10.0) == ["chair", "suitcase"]
    # four keyframes, 0.5 s apart (the first on frame 1, handed to the detector before frame 0):
    # each and the frames beside it get one tile each
    tiled = sorted(pose for pose, width in detector.calls if width < CAMERA.width)
    assert tiled == [0, 1, 2, 3, 16, 17, 18, 19, 31, 32, 33, 34, 46, 47, 48, 49]
    # the quick look: every third frame (ten looks a second) and every keyframe; the first frame
    # (handed over after the second) too
    looked = sorted(pose for pose, width in detector.calls if width == CAMERA.width)[1:]  # - the check above
    assert looked == [0, 1, 3, 6, 9, 12, 15, 16, 19, 22, 25, 28, 31, 34, 37, 40, 43, 46, 49, 52, 55, 58]


def test_without_keyframes_the_small_thing_stays_unnamed(monkeypatch):
    set_constants(monkeypatch, closer_look_s=0.0)
    frames = still_frames()
    detector = FixedInputDetector(frames)
    assert "suitcase" not in run(frames, detector)
    assert all(width == CAMERA.width for _, width in detector.calls)


def test_one_closer_look_is_not_enough(monkeypatch):
    # one keyframe in the 0.5 s log: the suitcase is named once, short of CLOSER_MIN_LOOKS
    set_constants(monkeypatch, closer_look_s=1.0)
    frames = still_frames(15)
    assert "suitcase" not in run(frames, FixedInputDetector(frames))


def test_keyframes_come_with_time_and_with_a_new_viewpoint(monkeypatch):
    set_constants(monkeypatch, closer_look_s=1.0)
    look = kf.KeyframeLook(FixedInputDetector([]), "yolox")

    def at(stamp_s, x=0.0):
        return make_frame(room(), pose_looking_x(x), stamp_s, 0)

    assert [look.tile_for(at(k / RATE_HZ)) for k in range(6)] == [0, 1, 2, 3, None, None]
    assert look.tile_for(at(0.9)) is None
    assert look.tile_for(at(1.0)) == 0  # a second of log after the last keyframe
    for k in range(3):
        look.tile_for(at(1.01 + k / 100))
    assert look.tile_for(at(1.1, x=0.3)) is None  # moved 0.3 m: the same view
    assert look.tile_for(at(1.2, x=0.6)) == 0  # moved 0.6 m: a new viewpoint
    assert look.keyframes == 3
    assert not kf.KeyframeLook(FixedInputDetector([]), "truth").enabled  # replays: nothing to look at


def test_a_blob_counts_as_seen_closer_only_whole_inside_its_frames_tile(monkeypatch):
    set_constants(monkeypatch, closer_look_s=1.0)
    look = kf.KeyframeLook(FixedInputDetector([]), "yolox")
    frame = make_frame(room(), pose_looking_x(), 0.0, 0)
    assert look.tile_for(frame) == 0
    x1 = tile_boxes(CAMERA.width, CAMERA.height, 2, 2, 0.25)[0][2]
    assert look.covers(frame, np.array([10.0, 10.0, 40.0, 40.0]))
    assert not look.covers(frame, np.array([10.0, 10.0, x1 + 5.0, 40.0]))  # cut by the tile's edge
    later = make_frame(room(), pose_looking_x(), 0.5, 1)
    assert not look.covers(later, np.array([10.0, 10.0, 40.0, 40.0]))  # no tile on that frame


def _tallies():
    from types import SimpleNamespace

    return SimpleNamespace(
        class_votes={}, class_counts={}, class_longest_m={}, full_views=0, full_named={},
        detected_classes=set(),
        closer_counts={}, focus_counts={}, min_class_observations=4, min_class_share=0.6, size_tolerance=None,
        refused_min_views=0, refused_max_share=0.0, _class_name=None)


def _look(closer_class):
    """A blob the every-frame look left unknown; ``closer_class``: what a closer look named it."""
    from types import SimpleNamespace

    return SimpleNamespace(class_name="unknown", score=0.0, longest_m=None, full_view=False,
                           named_within=frozenset(), detection_index=None, closer_class=closer_class,
                           cut_by_border=False)


def test_the_closer_looks_name_a_thing_only_when_most_of_them_name_it():
    from hiper_cli.perceive.foreground.class_vote import record, winner

    def vote(looks):
        track = _tallies()
        for _ in range(150):  # five seconds at 30 Hz: the every-frame look never names it
            record(track, _look(None), 0.15)
        for name in looks:
            record(track, _look(name), 0.15)
        return winner(track)

    assert vote(["cup", "cup", "cup", "unknown"]) == "cup"
    assert vote(["cup", "cup", "unknown"]) == "unknown"  # three looks at least
    assert vote(["cup"] * 4 + ["unknown"] * 4) == "unknown"  # half the looks: not most
    assert vote(["cup"] * 5 + ["unknown"] * 3) == "cup"
    assert vote(["cup", "cup", "cup", "bowl", "bowl", "unknown"]) == "unknown"  # 3 of 6


def test_a_class_the_full_views_refused_is_not_taken_back_from_the_closer_looks():
    """A walker's shoulders cut by the border look like a refrigerator to every look; full views
    that named it ``person`` refuse ``refrigerator``, and a closer look cannot undo that."""
    from hiper_cli.perceive.foreground.class_vote import record, winner

    track = _tallies()
    track.refused_min_views = 8
    for name in ["refrigerator"] * 4 + ["unknown"]:
        record(track, _look(name), 0.15)
    assert winner(track) == "refrigerator"
    track.detected_classes = {"refrigerator", "person"}
    track.full_views, track.full_named = 2, {"person": 2}
    assert winner(track) == "unknown"
