"""Re-anchoring: background instances recomputed from their observations with new poses."""

import numpy as np
import pytest

from hiper_cli.errors import DataError
from hiper_cli.perceive.background import BackgroundStage, reanchor
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import box_room, look_at, make_frame

POSES = [
    look_at((2.0, 1.5, 1.2), (3.0, 5.0, 1.3)),
    look_at((4.5, 1.0, 1.2), (3.5, 5.0, 1.3)),
    look_at((3.0, 2.5, 1.2), (6.0, 2.0, 1.0)),
]


@pytest.fixture(scope="module")
def mapped():
    frames = [make_frame(box_room(), T, pose_id=i, noise_m=0.001) for i, T in enumerate(POSES)]
    observations = []
    world, _ = run_stages(frames, [BackgroundStage()], on_frame=_collect(observations))
    return world, observations


def _collect(into):
    return lambda _frame, result: into.extend(result.observations)


def _far_wall(inst):
    return inst.class_name == "wall" and inst.data["plane_map"][1] < -0.9


def _shift(T, dx):
    S = np.eye(4)
    S[:3, 3] = [dx, 0.0, 0.0]
    return S @ T


def test_same_poses_reproduce_the_instances(mapped):
    world, observations = mapped
    result = reanchor(world.background.values(), observations, dict(enumerate(POSES)))
    assert not result.deleted and not result.unchanged
    assert result.observations == len(observations)
    before = {i.uuid: i for i in world.background.values()}
    for inst in result.instances:
        old = before[inst.uuid]
        assert inst.class_name == old.class_name
        assert inst.observation_uuids == old.observation_uuids
        assert np.allclose(inst.data["plane_map"], old.data["plane_map"], atol=1e-6)
        assert np.allclose(inst.box.center_m, old.box.center_m, atol=0.05)


def test_shifted_trajectory_moves_the_instances(mapped):
    world, observations = mapped
    shifted = {i: _shift(T, 0.5) for i, T in enumerate(POSES)}
    result = reanchor(world.background.values(), observations, shifted)
    before = {i.uuid: i for i in world.background.values()}
    assert len(result.instances) == len(before)
    for inst in result.instances:
        old = before[inst.uuid]
        assert inst.box.center_m == pytest.approx(old.box.center_m + np.array([0.5, 0.0, 0.0]), abs=0.05)
        if inst.class_name == "wall" and abs(inst.data["plane_map"][0]) > 0.9:  # the wall at x = 6
            assert -inst.data["plane_map"][3] / inst.data["plane_map"][0] == pytest.approx(6.5, abs=0.02)


def test_loop_closure_merges_instances_that_now_coincide():
    # the second view's pose is wrong by 0.4 m: its wall becomes a second instance ...
    frames = [make_frame(box_room(), T, pose_id=i) for i, T in enumerate(POSES[:2])]
    frames[1] = make_frame(box_room(), POSES[1], pose_id=1)
    wrong = _shift(POSES[1], 0.0)
    wrong[1, 3] += 0.4
    frames[1] = type(frames[1])(**{**frames[1].__dict__, "T_map_cam": wrong})
    observations = []
    world, _ = run_stages(frames, [BackgroundStage()], on_frame=_collect(observations))
    far_walls = [i for i in world.background.values() if _far_wall(i)]
    assert len(far_walls) == 2
    # ... until the corrected trajectory brings them together
    result = reanchor(world.background.values(), observations, dict(enumerate(POSES)))
    walls = [i for i in result.instances if _far_wall(i)]
    assert len(walls) == 1 and len(result.deleted) >= 1
    assert len(walls[0].observation_uuids) == 2


def test_missing_pose_is_an_error(mapped):
    world, observations = mapped
    with pytest.raises(DataError, match="no pose for"):
        reanchor(world.background.values(), observations, {0: POSES[0]})
