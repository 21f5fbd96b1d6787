"""The tracker's swappable parts: motion models and assignment rules by name, named trajectory columns."""

import numpy as np
import pytest

from hiper_cli.errors import ConfigError, DataError
from hiper_cli.model import ROW_POSITION, ROW_STAMP, ROW_VELOCITY, TRAJECTORY_COLUMNS, TrackTrajectory
from hiper_cli.perceive.foreground.association import ASSOCIATIONS, get_association, greedy, hungarian
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.motion import ConstantVelocityKF, make_motion_model
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker


def test_unknown_names_say_what_exists():
    with pytest.raises(ConfigError, match="motion_model 'ukf': unknown; expected one of constant_velocity"):
        make_motion_model("ukf", np.zeros(3), 0.03)
    with pytest.raises(ConfigError, match="association 'jpda': unknown; expected one of hungarian, greedy"):
        get_association("jpda")
    with pytest.raises(ConfigError, match="motion_model 'ukf'"):
        Tracker(ForegroundConfig(motion_model="ukf"))


def test_constant_velocity_model_moves_by_its_velocity():
    model = ConstantVelocityKF(np.array([1.0, 2.0, 0.5]), measurement_noise_m=0.03)
    model.reset(np.array([1.0, 2.0, 0.5, 0.5, -1.0, 0.0]), np.eye(6) * 0.01)
    model.predict(2.0, q=0.0, q_vertical=0.0)
    np.testing.assert_allclose(model.x, [2.0, 0.0, 0.5, 0.5, -1.0, 0.0])
    model.decay_velocity(0.5, np.ones((6, 6)), np.zeros((6, 6)))
    np.testing.assert_allclose(model.x[3:], [0.25, -0.5, 0.0])


def test_constant_velocity_model_learns_a_steady_walk_from_its_centres():
    model = ConstantVelocityKF(np.zeros(3), measurement_noise_m=0.03)
    for k in range(1, 61):  # 0.5 m/s along x, seen at 15 Hz
        model.predict(1.0 / 15.0, q=0.5, q_vertical=0.1)
        model.update(np.array([0.5 * k / 15.0, 0.0, 0.0]))
    np.testing.assert_allclose(model.x[3:], [0.5, 0.0, 0.0], atol=0.01)
    np.testing.assert_allclose(model.x[:3], [2.0, 0.0, 0.0], atol=0.01)
    np.testing.assert_allclose(model.P, model.P.T, atol=1e-15)  # the Joseph form keeps P symmetric
    assert np.all(np.linalg.eigvalsh(model.P) > 0)
    assert model.P[0, 0] < 0.03**2  # the fused centre is surer than one measurement


def test_hungarian_minimises_the_total_greedy_takes_the_cheapest_first():
    cost = np.array([[1.0, 2.0], [1.1, 9.0]])
    allowed = np.ones_like(cost, dtype=bool)
    assert hungarian(cost, allowed) == [(0, 1), (1, 0)]  # 3.1 in total
    assert greedy(cost, allowed) == [(0, 0), (1, 1)]  # 1.0 first, then 9.0
    allowed[1, 1] = False
    assert greedy(cost, allowed) == [(0, 0)]
    assert set(ASSOCIATIONS) == {"hungarian", "greedy"}


@pytest.mark.parametrize("association", ["hungarian", "greedy"])
def test_tracker_keeps_two_walkers_apart_with_either_rule(association):
    tracker = Tracker(ForegroundConfig(association=association, confirm_hits=2))
    ids = []
    for k in range(5):
        t = 0.1 * k
        ms = [Measurement(np.array([0.5 * t, 0.0, 1.0]), np.ones(3) * 0.5, "person", 0.9, f"a{k}"),
              Measurement(np.array([3.0, 0.5 * t, 1.0]), np.ones(3) * 0.5, "person", 0.9, f"b{k}")]
        _, joined = tracker.step(t, ms)
        ids.append(joined)
    assert ids[0] == [None, None]
    assert len({j[0] for j in ids[1:]}) == 1 and len({j[1] for j in ids[1:]}) == 1
    assert ids[1][0] != ids[1][1]


def test_track_trajectory_names_its_columns():
    rows = [[0.0, 1.0, 2.0, 3.0, 0.3, 0.4, 0.0], [1.0, 1.3, 2.4, 3.0, 0.3, 0.4, 0.0]]
    path = TrackTrajectory.from_rows(rows)
    assert len(path) == 2 and TRAJECTORY_COLUMNS[ROW_STAMP] == "stamp_s"
    np.testing.assert_allclose(path.stamps_s, [0.0, 1.0])
    np.testing.assert_allclose(path.position_map_m[1], rows[1][ROW_POSITION])
    np.testing.assert_allclose(path.velocity_map_mps[0], rows[0][ROW_VELOCITY])
    np.testing.assert_allclose(path.speed_xy_mps, [0.5, 0.5])
    assert len(TrackTrajectory.from_rows(None)) == 0
    with pytest.raises(DataError, match=r"expected \(N, 7\) rows"):
        TrackTrajectory(np.zeros((2, 4)))
