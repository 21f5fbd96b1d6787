"""A table top goes on behind what stands on it (``hidden.py``): a desk that each view sees only
in part, the rest hidden behind a box standing across it, is one table; two desks that stand
apart, the floor seen between them, stay two."""

import numpy as np

from hiper_cli.perceive.background import BackgroundConfig, BackgroundStage
from hiper_cli.perceive.background.hidden import hidden_points
from hiper_cli.perceive.background.planes import extract_planes
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame

TOP_M = 0.76


def _desk(x0, x1, y0=2.4, y1=3.1, first_id=50, leg=0.05):
    boxes = [SceneBox(first_id, "table", (x0, y0, TOP_M - 0.04), (x1, y1, TOP_M))]
    for k, (x, y) in enumerate(((x0, y0), (x1 - leg, y0), (x0, y1 - leg), (x1 - leg, y1 - leg))):
        boxes.append(SceneBox(first_id + 1 + k, "table", (x, y, 0.0), (x + leg, y + leg, TOP_M - 0.04)))
    return boxes


# a box 0.3 m wide, 0.5 m tall (its top above table heights) standing across the middle of a
# 1.6 m desk: from either end of the desk the view sees the near part of the top, not the far one
BOX = SceneBox(60, "other", (2.85, 2.4, TOP_M), (3.15, 3.1, TOP_M + 0.5))
FROM_ENDS = [look_at((0.9, 2.75, 1.2), (3.0, 2.75, 0.5)), look_at((5.1, 2.75, 1.2), (3.0, 2.75, 0.5))]


def _tables(boxes, poses, **options):
    frames = [make_frame([*box_room(), *boxes], T, pose_id=i, noise_m=0.001) for i, T in enumerate(poses)]
    world, _ = run_stages(frames, [BackgroundStage(**options)])
    return sorted((i for i in world.background.values() if i.class_name == "table"),
                  key=lambda i: float(i.box.center_m[0]))


def _x_span(inst):
    lo, hi = inst.box.aabb()
    return float(lo[0]), float(hi[0])


def test_each_view_sees_half_the_desk_and_a_gap_the_merge_margin_does_not_close():
    pieces = _tables([*_desk(2.2, 3.8), BOX], FROM_ENDS, table_bridge_m=0.0)
    assert len(pieces) == 2
    (_, left_end), (right_start, _) = _x_span(pieces[0]), _x_span(pieces[1])
    assert right_start - left_end > BackgroundConfig().merge_contour_margin_m


def test_the_desk_behind_the_board_is_one_table_as_long_as_the_desk():
    (desk,) = _tables([*_desk(2.2, 3.8), BOX], FROM_ENDS)
    x0, x1 = _x_span(desk)
    assert abs(x0 - 2.2) < 0.1 and abs(x1 - 3.8) < 0.1


def test_two_desks_with_the_floor_seen_between_them_stay_two():
    apart = [*_desk(2.0, 2.9), *_desk(3.2, 4.1, first_id=70)]  # 0.3 m apart, nothing between
    above = [look_at((3.05, 1.2, 1.6), (3.05, 2.75, 0.6)), look_at((3.05, 4.4, 1.6), (3.05, 2.75, 0.6))]
    assert len(_tables(apart, above)) == 2


def test_hidden_points_lie_on_the_plane_behind_the_board_and_nowhere_past_the_reach():
    cfg = BackgroundConfig()
    frame = make_frame([*box_room(), *_desk(2.2, 3.8), BOX], FROM_ENDS[0], noise_m=0.001)
    grid, segments = extract_planes(frame.depth_m, frame.camera, cfg)
    T = frame.T_map_cam
    heights = [float(np.median(grid.points_cam[s.mask] @ T[2, :3] + T[2, 3])) for s in segments]
    top = segments[int(np.argmin([abs(h - TOP_M) for h in heights]))]
    points = hidden_points(grid, frame.camera, top, cfg)
    assert len(points) > 0
    on_map = points @ T[:3, :3].T + T[:3, 3]
    assert np.allclose(on_map[:, 2], TOP_M, atol=0.02)
    seen_x = float((grid.points_cam[top.mask] @ T[0, :3] + T[0, 3]).max())
    assert on_map[:, 0].max() <= seen_x + cfg.table_bridge_m + 0.02
    assert on_map[:, 0].max() > 2.95  # behind the box's near face
    assert len(hidden_points(grid, frame.camera, top, BackgroundConfig(table_bridge_m=0.0))) == 0
