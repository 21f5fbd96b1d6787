"""Background recognition on box rooms rendered in code (paper IV-C/D, Algorithms 1 and 2)."""

import numpy as np
import pytest
from shapely.geometry import Point

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.background import BackgroundConfig, BackgroundStage, observe
from hiper_cli.perceive.background.contour import PlaneFrame, to_polygon
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import make_stage
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame

CENTER = (3.0, 2.5, 1.2)


def _survey(center=CENTER, n=16, radius=1.0):
    """Look around from ``center``: n headings, alternately tilted up and down."""
    poses = []
    for k in range(n):
        a = 2 * np.pi * k / n
        tilt = 0.5 if k % 2 == 0 else -0.5
        target = (center[0] + radius * np.cos(a), center[1] + radius * np.sin(a), center[2] + tilt)
        poses.append(look_at(center, target))
    return poses


def _run(boxes, poses, noise_m=0.001, **options):
    frames = [make_frame(boxes, T, pose_id=i, noise_m=noise_m) for i, T in enumerate(poses)]
    world, stats = run_stages(frames, [BackgroundStage(**options)])
    return world, stats


def _by_class(world):
    out = {}
    for inst in world.background.values():
        out.setdefault(inst.class_name, []).append(inst)
    return out


@pytest.fixture(scope="module")
def room_run():
    return _run(box_room(), _survey())


def test_box_room_gives_four_walls_a_floor_and_a_ceiling(room_run):
    world, _ = room_run
    classes = _by_class(world)
    assert {k: len(v) for k, v in classes.items()} == {"wall": 4, "floor": 1, "ceiling": 1}
    offsets = sorted(round(abs(i.data["plane_map"][3]), 1) for i in classes["wall"])
    assert offsets == [0.0, 0.0, 5.0, 6.0]
    assert classes["floor"][0].data["plane_map"][3] == pytest.approx(0.0, abs=0.02)
    assert classes["ceiling"][0].data["plane_map"][3] == pytest.approx(2.6, abs=0.02)


def test_instances_link_their_observations(room_run):
    world, stats = room_run
    linked = [u for i in world.background.values() for u in i.observation_uuids]
    assert len(linked) == len(set(linked)) == stats.observations


def test_table_top_at_075_m_is_a_table():
    table = SceneBox(20, "table", (2.6, 2.0, 0.71), (3.8, 2.8, 0.75))
    world, _ = _run([*box_room(), table], [look_at((1.5, 0.8, 1.3), (3.2, 2.4, 0.6))])
    tables = _by_class(world)["table"]
    assert len(tables) == 1
    plane = tables[0].data["plane_map"]
    assert plane[2] == pytest.approx(1.0, abs=0.01)
    height_at_centre = -(plane[0] * 3.2 + plane[1] * 2.4 + plane[3]) / plane[2]
    assert height_at_centre == pytest.approx(0.75, abs=0.01)
    assert tables[0].box.extent_m[:2] == pytest.approx([1.2, 0.8], abs=0.15)


def test_same_wall_from_two_poses_is_one_instance():
    poses = [look_at((2.0, 1.5, 1.2), (3.0, 5.0, 1.3)), look_at((4.5, 1.0, 1.2), (3.5, 5.0, 1.3))]
    world, _ = _run(box_room(), poses, keyframe_hz=2.0)
    walls = [i for i in world.background.values() if i.class_name == "wall" and i.data["plane_map"][1] < -0.9]
    assert len(walls) == 1
    assert len(walls[0].observation_uuids) == 2
    assert walls[0].data["plane_map"][3] == pytest.approx(5.0, abs=0.02)


def test_wall_split_by_a_doorway_keeps_the_door_open():
    boxes = box_room(door=(2.6, 3.6, 2.0))
    world, _ = _run(boxes, [look_at((3.0, 1.5, 1.2), (3.0, 5.0, 1.3))])
    walls = [i for i in world.background.values() if i.class_name == "wall" and i.data["plane_map"][1] < -0.9]
    assert len(walls) == 1
    frame = PlaneFrame(np.array(walls[0].data["plane_map"]))
    poly = to_polygon(np.array(walls[0].data["contour_map"]), frame)
    inside = lambda p: poly.contains(Point(frame.to_2d(np.array(p))[0]))  # noqa: E731
    assert inside((1.8, 5.0, 1.0)) and inside((4.4, 5.0, 1.0)) and inside((3.1, 5.0, 2.3))
    assert not inside((3.1, 5.0, 1.0))  # the doorway


def test_person_standing_still_is_not_a_wall():
    person = SceneBox(30, "person", (2.75, 3.2, 0.0), (3.25, 3.5, 1.75))
    world, _ = _run([*box_room(), person], [look_at((3.0, 1.0, 1.2), (3.0, 5.0, 1.2))])
    for inst in world.background.values():
        if inst.class_name == "wall":
            assert abs(inst.data["plane_map"][3]) > 4.5 or abs(inst.data["plane_map"][3]) < 0.1, inst.data


def test_keyframes_at_the_mapping_rate():
    boxes = box_room()
    T = look_at(CENTER, (6.0, 2.5, 1.2))
    stage = BackgroundStage()
    world = run_stages([], [])[0]
    results = [stage.process(make_frame(boxes, T, pose_id=i, stamp_s=0.1 * i), world) for i in range(7)]
    assert [r.skipped is None for r in results] == [True, False, False, False, False, True, False]
    assert set(results[0].timings_s) == {"background_s", "background_cpu_s"}
    assert results[0].observations and all(
        o.data["keyframe_s"] == results[0].timings_s["background_s"] for o in results[0].observations
    )


def test_the_last_frame_of_a_run_is_a_keyframe():
    """What the robot saw last is in the map: through ``run_stages`` (which hands each stage the
    next frame ahead), the log's last frame is a keyframe whatever the mapping rate says."""
    T = look_at(CENTER, (6.0, 2.5, 1.2))
    frames = [make_frame(box_room(), T, pose_id=i, stamp_s=0.1 * i) for i in range(7)]
    seen: list[bool] = []
    run_stages(iter(frames), [BackgroundStage()], on_frame=lambda f, r: seen.append(bool(r.observations))
               if f is not None else None)
    assert seen == [True, False, False, False, False, True, True]


def test_ransac_method_finds_the_same_planes():
    frame = make_frame(box_room(), look_at((1.0, 1.0, 1.2), (5.0, 4.0, 1.0)), noise_m=0.001)
    fast = sorted(o.class_name for o in observe(frame, BackgroundConfig()))
    ransac = sorted(o.class_name for o in observe(frame, BackgroundConfig(method="ransac")))
    assert fast == ransac == ["ceiling", "floor", "wall", "wall"]


def test_observation_data_for_evaluators():
    frame = make_frame(box_room(), look_at((1.0, 1.0, 1.2), (5.0, 4.0, 1.0)))
    obs = observe(frame, BackgroundConfig())
    for o in obs:
        assert o.pose_id == 0 and o.layer == "background"
        assert set(o.data) >= {"plane_cam", "contour_cam", "pixels_uv"}
        uv = np.array(o.data["pixels_uv"])
        ids = frame.extras["gt_ids"][uv[:, 1], uv[:, 0]]
        assert np.mean(ids == np.bincount(ids).argmax()) >= 0.95  # the samples lie on one surface


def test_unknown_option_names_the_choices():
    with pytest.raises(ConfigError, match="expected one of"):
        BackgroundStage(colour="red")
    with pytest.raises(ConfigError, match="expected one of fast, ransac"):
        make_stage("background", method="magic")
    assert make_stage("background", log_path="x", stride_px=8).config.stride_px == 8


@pytest.mark.parametrize("method", ["fast", "ransac"])
def test_frame_without_depth_gives_nothing(method):
    frame = make_frame(box_room(), look_at(CENTER, (6.0, 2.5, 1.2)))
    empty = type(frame)(**{**frame.__dict__, "depth_m": np.zeros_like(frame.depth_m)})
    nan = type(frame)(**{**frame.__dict__, "depth_m": np.full_like(frame.depth_m, np.nan)})
    assert observe(empty, BackgroundConfig(method=method)) == []
    assert observe(nan, BackgroundConfig(method=method)) == []


def test_a_chair_back_behind_the_table_at_its_height_is_not_part_of_the_top():
    table = SceneBox(20, "table", (2.6, 2.0, 0.71), (3.8, 2.8, 0.75))
    back = SceneBox(21, "chair", (2.8, 3.0, 0.62), (3.6, 3.04, 0.90))  # 0.2 m behind the far edge
    pose = look_at((1.5, 0.8, 1.3), (3.2, 2.4, 0.6))

    def table_far_edge_y(**options):
        world, _ = _run([*box_room(), table, back], [pose], **options)
        (top,) = _by_class(world)["table"]
        return top.box.aabb()[1][1]

    assert table_far_edge_y() == pytest.approx(2.8, abs=0.05)
    assert table_far_edge_y(join_jump_frac=0.0) > 2.95  # without the rule the top takes the back's strip
