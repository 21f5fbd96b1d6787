"""Unknown instances need whole evidence (``whole.py``, ``Tracker._evidence_enough``): a blob
no detector named becomes an instance only when seen whole, solid and compact, for a while."""

import numpy as np

from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker
from hiper_cli.perceive.foreground.whole import seen_whole, thickness_m
from hiper_cli.types import CameraIntrinsics

CAMERA = CameraIntrinsics(width=640, height=480, fx=525.0, fy=525.0, cx=319.5, cy=239.5)
RATE_HZ = 15.0


def _blob(points_cam, box):
    uv = np.zeros((len(points_cam), 2), np.int32)
    return Blob(points_cam, points_cam.copy(), uv, np.asarray(box, float))


def _cube(n=400, size=0.3, depth=2.0, seed=0):
    return np.random.default_rng(seed).uniform(-size / 2, size / 2, (n, 3)) + np.array([0.0, 0.0, depth])


def test_a_cube_in_the_middle_of_the_image_is_whole():
    assert seen_whole(_blob(_cube(), [300, 200, 340, 240]), ForegroundConfig(), CAMERA)


def test_a_blob_at_the_image_border_is_not_whole():
    assert not seen_whole(_blob(_cube(), [0, 200, 40, 240]), ForegroundConfig(), CAMERA)


def test_a_flat_patch_is_not_whole():
    patch = _cube()
    patch[:, 2] = 2.0 + np.random.default_rng(1).normal(0.0, 0.002, len(patch))
    assert thickness_m(patch) < 0.005
    assert not seen_whole(_blob(patch, [300, 200, 340, 240]), ForegroundConfig(), CAMERA)


def test_a_large_blob_is_not_whole():
    assert not seen_whole(_blob(_cube(size=1.5), [200, 100, 440, 380]), ForegroundConfig(), CAMERA)


def _track(config, frames, whole=True, cls="unknown"):
    tracker = Tracker(config)
    confirmed = False
    for k in range(frames):
        score = 0.0 if cls == "unknown" else 0.9
        centre, extent = np.array([1.0, 2.0, 0.5]), np.array([0.3, 0.3, 0.3])
        m = Measurement(centre, extent, cls, score, f"o{k}", whole=whole)
        changed, _ = tracker.step(k / RATE_HZ, [m])
        confirmed |= bool(changed)
    return confirmed


def test_an_unknown_track_needs_whole_observations_over_half_a_second():
    cfg = ForegroundConfig()
    assert not _track(cfg, 5)  # 0.27 s: too short
    assert _track(cfg, 10)  # 0.6 s of whole views
    assert not _track(cfg, 30, whole=False)  # always cut by the border: a piece of something


def test_without_the_rule_three_hits_make_an_unknown_instance():
    assert _track(ForegroundConfig(unknown_confirm_whole=0), 5, whole=False)


def test_a_detected_object_keeps_the_usual_evidence():
    assert _track(ForegroundConfig(), 5, whole=False, cls="chair")
