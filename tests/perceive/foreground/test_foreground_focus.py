"""The focused look (``focus.py``): a crop around a track the every-frame look named a class too
seldom to show; the crops' answers confirm that class, or leave the track ``unknown``."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground import focus as fo
from hiper_cli.perceive.foreground.class_vote import FOCUS_MIN_LOOKS, record_focus, shown_class
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import World
from hiper_cli.types import Detections
from tests.fg_constants import set_constants
from tests.fg_scene import CAMERA, SceneBox, background_instances, chair, make_frame, pose_looking_x, room

RATE_HZ = 30.0
INPUT_PX = 96  # the stand-in detector's input: the 160 px image shrinks to 0.6
LEAST_PX = 12  # ... and it names what is still this many of its input pixels across


class CropDetector:
    """Stands for a detector of fixed input size on a small thing: the truth's boxes of the image
    it is given (a crop's found by the shift of its principal point), kept where they lie whole
    in that image and are ``LEAST_PX`` across once the image is shrunk to ``INPUT_PX``. On the
    whole image it still names the small thing one frame in ``every`` (a detector's luck), and
    ``crop_class`` renames what a crop names (a crop's own confusion)."""

    name = "crop-stand-in"
    class_names = ("suitcase", "chair", "person", "bench")

    def __init__(self, frames, every=10, crop_class=None):
        self.truth = {f.stamp_s: f.detections for f in frames}
        self.pose = {f.stamp_s: f.pose_id for f in frames}
        self.every, self.crop_class = every, crop_class
        self.crops = 0

    def detect(self, frame):
        truth = self.truth[frame.stamp_s]
        shift = np.array([CAMERA.cx - frame.camera.cx, CAMERA.cy - frame.camera.cy] * 2)
        xyxy = truth.xyxy - shift
        scale = INPUT_PX / max(frame.width, frame.height)
        inside = (xyxy[:, :2] >= 0).all(axis=1) & (xyxy[:, 2] <= frame.width) & (xyxy[:, 3] <= frame.height)
        across = np.maximum(xyxy[:, 2] - xyxy[:, 0], xyxy[:, 3] - xyxy[:, 1]) * scale
        whole_image = frame.width == CAMERA.width
        lucky = whole_image and self.pose[frame.stamp_s] % self.every == 0
        keep = inside & ((across >= LEAST_PX) | lucky)
        names = tuple(n for n, k in zip(truth.class_names, keep, strict=True) if k)
        if not whole_image:
            self.crops += 1
            if self.crop_class:
                names = tuple(self.crop_class if n == "suitcase" else n for n in names)
        return Detections(xyxy[keep], names, truth.scores[keep])


def suitcase():
    """A 0.4 m suitcase on the floor 3 m ahead, left: 13 px across, 8 in the detector's input."""
    return SceneBox(12, np.array([3.0, 0.8, 0.2]), np.array([0.4, 0.4, 0.4]), "suitcase")


def frames(n=90):
    return [make_frame([*room(), suitcase(), chair(11, 4.0, -1.0)], pose_looking_x(), k / RATE_HZ, k)
            for k in range(n)]


def run(log, detector):
    stage = ForegroundStage(detector_instance=detector, pixel_step=2)
    world, _ = run_stages(log, [stage], World(background=background_instances(room())))
    return sorted(i.class_name for i in world.foreground.values())


@pytest.fixture
def small_image(monkeypatch):
    # the test camera's image is 160 × 120: crops of 40 px at least (192 of a 640 × 480 image),
    # no tiled closer look (its tiles would name the suitcase on their own)
    set_constants(monkeypatch, focus_min_side_px=40.0, focus_max_box_px=50.0, closer_look_s=0.0)


@pytest.mark.usefixtures("small_image")
def test_focused_looks_confirm_what_the_every_frame_look_named_seldom():
    log = frames()
    detector = CropDetector(log)
    # named in 9 of 90 frames, silent in the rest: the every-frame vote shows nothing
    assert run(log, detector) == ["chair", "suitcase"]
    assert FOCUS_MIN_LOOKS <= detector.crops <= fo.FOCUS_MAX_LOOKS  # a few crops, not one a frame


@pytest.mark.usefixtures("small_image")
def test_without_focused_looks_the_seldom_named_thing_stays_unknown(monkeypatch):
    set_constants(monkeypatch, focus_per_s=0.0)
    log = frames()
    detector = CropDetector(log)
    assert run(log, detector) == ["chair", "unknown"]
    assert detector.crops == 0


@pytest.mark.usefixtures("small_image")
def test_a_class_only_the_crops_give_names_nothing():
    # the crops call the suitcase a bench, the whole image (seldom) a suitcase: the two looks
    # disagree, so the object stays unknown
    log = frames()
    assert run(log, CropDetector(log, crop_class="bench")) == ["chair", "unknown"]


@pytest.mark.usefixtures("small_image")
def test_a_thing_the_every_frame_look_never_named_gets_no_focused_look():
    log = frames()
    detector = CropDetector(log, every=1000)  # named only in frame 0
    assert run(log, detector) == ["chair", "unknown"]
    assert detector.crops == 0


def _question(named=6, silent=60):
    """A track named ``suitcase`` in ``named`` of its views (score 0.5), silent in the others."""
    tracker = Tracker(TrackerConfig())
    centre, extent = np.array([3.0, 0.8, 0.2]), np.array([0.4, 0.4, 0.4])
    for k in range(named + silent):
        is_named = k % ((named + silent) // named) == 0 and k // ((named + silent) // named) < named
        m = Measurement(centre, extent, "suitcase" if is_named else "unknown", 0.5 if is_named else 0.0,
                        f"o{k}", whole=False, detection_index=0 if is_named else None)
        tracker.step(k / RATE_HZ, [m])
    return tracker.tracks[0]


@pytest.mark.parametrize(("answers", "expected"), [
    (["suitcase"] * 3, "suitcase"),
    (["suitcase"] * 2, "unknown"),  # fewer than FOCUS_MIN_LOOKS
    (["suitcase"] * 3 + ["unknown"] * 4, "unknown"),  # the crops' silence outweighs them
    (["suitcase"] * 3 + ["unknown"] * 3, "suitcase"),
    (["bench"] * 5, "unknown"),  # a class the every-frame look never gave
])
def test_the_focused_vote(answers, expected):
    track = _question()
    assert shown_class(track) == "unknown"
    for answer in answers:
        record_focus(track, answer)
    assert shown_class(track) == expected


def test_the_crop_is_a_square_around_the_box_inside_the_image():
    box = fo.focus_box(np.array([300.0, 200.0, 340.0, 260.0]), 640, 480)
    assert box == (224, 134, 416, 326)  # 192 px, the box in its middle
    assert fo.focus_box(np.array([0.0, 400.0, 120.0, 480.0]), 640, 480) == (0, 240, 240, 480)  # 2 × 120
    assert fo.focus_box(np.array([0.0, 0.0, 300.0, 100.0]), 640, 480) is None  # large: seen closely enough


def test_focused_looks_a_few_times_a_second_the_least_looked_at_first():
    look = fo.FocusedLook(CropDetector([]), enabled=True)
    budgets = [look.due(k / RATE_HZ) for k in range(31)]
    assert budgets[0] == 1 and sum(budgets) == 31  # nothing spent: the credit stays
    look = fo.FocusedLook(CropDetector([]), enabled=True)
    box = np.zeros(4)
    spent = 0
    for k in range(31):
        qs = [fo.Question("a", 3, box), fo.Question("b", 1, box), fo.Question("c", fo.FOCUS_MAX_LOOKS, box)]
        chosen = look.pick(qs, look.due(k / RATE_HZ))
        assert [q.uuid for q in chosen] in ([], ["b"])
        spent += len(chosen)
    assert spent == 1 + int(fo.FOCUS_PER_S)  # the first frame, then FOCUS_PER_S a second
    assert not fo.FocusedLook(CropDetector([]), enabled=False).due(0.0)
