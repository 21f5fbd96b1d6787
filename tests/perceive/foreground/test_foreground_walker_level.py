"""Walkers are held level (``walker_level``): no vertical velocity, so a person's height is
never extrapolated below the floor or above it; and path speeds are robust to jitter."""

import numpy as np
import pytest

from hiper_cli.learned import path_speed_mps
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker
from tests.fg_constants import constants

RATE_HZ = 30.0


def _rising_person(config, frames=20, cls="person"):
    tracker = Tracker(config)
    for k in range(frames):
        t = k / RATE_HZ
        centre = np.array([0.6 * t, 0.0, 0.5 + 0.6 * t])  # a blob that grows upwards
        tracker.step(t, [Measurement(centre, np.array([0.4, 0.4, 1.0]), cls, 0.9, f"o{k}")])
    return tracker.tracks[0]


def test_a_person_has_no_vertical_velocity():
    track = _rising_person(TrackerConfig())
    assert track.velocity[2] == 0.0
    assert track.velocity[0] == pytest.approx(0.6, abs=0.1)
    assert all(row[6] == 0.0 for row in track.trajectory[1:])


def test_other_classes_and_the_switch_keep_it():
    assert _rising_person(TrackerConfig(), cls="chair").velocity[2] > 0.3
    with constants(walker_level=False):
        assert _rising_person(TrackerConfig()).velocity[2] > 0.3


def test_path_speed_ignores_jitter_and_gaps():
    t = np.arange(0.0, 10.0, 1.0 / RATE_HZ)
    jitter = np.random.default_rng(0).normal(0.0, 0.01, (len(t), 3))  # 1 cm per axis
    rows = np.c_[t, np.c_[0.6 * t, 0 * t, 0 * t] + jitter]
    assert path_speed_mps(rows) == pytest.approx(0.6, abs=0.03)  # row to row: 0.86
    gap = rows.copy()
    gap[150:, 0] += 10.0  # unseen for 10 s, then picked up where it was
    assert path_speed_mps(gap) == pytest.approx(0.6, abs=0.02)
    back_and_forth = np.abs((0.6 * t) % 4.8 - 2.4)
    assert path_speed_mps(np.c_[t, back_and_forth, 0 * t, 0 * t]) == pytest.approx(0.6, abs=0.03)


def test_a_person_blob_high_above_the_floor_is_no_walker():
    from hiper_cli.model import Box3D, Instance
    from hiper_cli.perceive.foreground.segment import Blob
    from hiper_cli.perceive.foreground.stage import ForegroundStage
    from hiper_cli.perceive.foreground.supports import floor_height_m

    floor = Instance(layer="background", class_name="floor", first_seen_s=0.0, last_seen_s=0.0,
                     box=Box3D(np.array([0.0, 0.0, 0.0]), np.array([5.0, 5.0, 0.02])))
    assert floor_height_m([floor]) == pytest.approx(0.01)
    assert floor_height_m([]) == 0.0
    stage = ForegroundStage(detector="log")

    def blob(z0):
        pts = np.random.default_rng(0).uniform([0, 0, z0], [0.3, 0.3, z0 + 0.4], (50, 3))
        return Blob(pts, pts, np.zeros((50, 2), np.int32), np.array([0.0, 0.0, 10.0, 10.0]))

    assert stage._stands("person", blob(0.9))  # the upper body behind a counter
    assert not stage._stands("person", blob(1.5))  # on a shelf's top
    assert stage._stands("book", blob(1.5))
