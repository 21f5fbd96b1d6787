"""The speed of a trajectory (``learned.typical_speed_mps``): a walker's pace, also where it
walks back and forth and its filter slows down at each end."""

import numpy as np
import pytest

from hiper_cli.learned import path_speed_mps, typical_speed_mps


def _back_and_forth(speed_mps=0.9, leg_m=2.5, rate_hz=15.0, legs=4, turn_s=0.4):
    """Rows of a filter on a walker that reverses: it slows to 0 over ``turn_s`` at each end
    and cuts the end of the path."""
    rows, x, t, direction = [], 0.0, 0.0, 1.0
    dt = 1.0 / rate_hz
    for _ in range(legs):
        walked = 0.0
        while walked < leg_m:
            left = leg_m - walked
            v = speed_mps * min(1.0, left / (speed_mps * turn_s))  # slowing into the turn
            v = max(v, 0.05)
            rows.append([t, x, 0.0, 0.85, direction * v, 0.0, 0.0])
            x += direction * v * dt
            walked += speed_mps * dt  # the walker goes all the way; the filter falls short
            t += dt
        direction = -direction
    return rows


def test_a_walker_going_back_and_forth_reads_its_pace():
    rows = _back_and_forth()
    assert path_speed_mps(rows) < 0.85  # the path cut short at the ends reads low
    assert typical_speed_mps(rows) == pytest.approx(0.9, abs=0.01)


def test_rows_without_velocities_use_the_path():
    rows = [[0.1 * k, 0.4 * 0.1 * k, 0.0, 0.0, 0.0, 0.0, 0.0] for k in range(20)]
    assert typical_speed_mps(rows) == pytest.approx(path_speed_mps(rows)) == pytest.approx(0.4)
    assert typical_speed_mps([r[:4] for r in rows]) == pytest.approx(0.4)
    assert typical_speed_mps([]) is None
    assert typical_speed_mps([[0.0, "x"]]) is None


def test_a_static_object_jitter_is_near_zero():
    rng = np.random.default_rng(0)
    rows = [[0.1 * k, *rng.normal(0, 0.01, 3), *rng.normal(0, 0.02, 3)] for k in range(50)]
    assert typical_speed_mps(rows) < 0.05
