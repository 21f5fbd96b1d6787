"""Walkers are held level (``walker_level``): no vertical velocity, so a person's height is
never extrapolated below the floor or above it."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker

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
    assert _rising_person(TrackerConfig(walker_level=False)).velocity[2] > 0.3

