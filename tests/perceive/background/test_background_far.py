"""Far walls on noisy depth (``planes._grow_angle``): cells join within the tilt their noise explains."""

import numpy as np
import pytest

from hiper_cli.perceive.background import BackgroundStage
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import box_room, look_at, make_frame

# 4.8 m from the wall at y = 6, 1.2 m high, pitched 15 degrees down (the realistic worlds' camera)
POSE = look_at((3.0, 1.2, 1.2), (3.0, 6.0, 1.2 - 4.8 * np.tan(np.radians(15.0))))


def _far_walls(noise_m, **options):
    frames = [make_frame(box_room(size=(6.0, 6.0, 3.0)), POSE, noise_m=noise_m)]
    # every view counts: this is the plane extraction at range, not the wall's evidence
    # (``wall_range.py`` withdraws a wall seen from 4.8 m only when the log ends)
    world, _ = run_stages(frames, [BackgroundStage(**{"wall_view_max_noise_m": 0.0, **options})])
    return [i for i in world.background.values() if i.class_name == "wall" and i.data["plane_map"][1] < -0.9]


@pytest.mark.parametrize("noise_m", [0.002, 0.003])  # 4.6 and 6.9 cm at 4.8 m
def test_a_far_wall_on_noisy_depth_is_found(noise_m):
    walls = _far_walls(noise_m)
    assert walls and all(abs(abs(w.data["plane_map"][3]) - 6.0) < 0.05 for w in walls)


def test_with_a_fixed_grow_angle_it_splits_or_is_lost():
    assert len(_far_walls(0.002)) == 1
    assert len(_far_walls(0.002, grow_noise_angle=False)) == 2
    assert _far_walls(0.003, grow_noise_angle=False) == []
