"""A table top stands on legs (``under.py``): the top of a solid block at table height is not a table."""

from hiper_cli.perceive.background import BackgroundStage
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame

POSE = look_at((3.0, 0.6, 1.2), (3.0, 3.0, 0.5))


def _table(x0, y0, x1, y1, top=0.75, leg=0.05):
    boxes = [SceneBox(50, "table", (x0, y0, top - 0.04), (x1, y1, top))]
    for k, (x, y) in enumerate(((x0, y0), (x1 - leg, y0), (x0, y1 - leg), (x1 - leg, y1 - leg))):
        boxes.append(SceneBox(51 + k, "table", (x, y, 0.0), (x + leg, y + leg, top - 0.04)))
    return boxes


def _tables(boxes, **options):
    frames = [make_frame([*box_room(), *boxes], POSE, noise_m=0.001)]
    world, _ = run_stages(frames, [BackgroundStage(**options)])
    return [i for i in world.background.values() if i.class_name == "table"]


def test_a_table_on_legs_is_a_table():
    assert len(_tables(_table(2.4, 2.0, 3.6, 2.7))) == 1


def test_a_box_stack_top_at_table_height_is_not():
    stack = [SceneBox(60, "other", (2.4, 2.0, 0.0), (3.6, 2.7, 0.75))]
    assert _tables(stack) == []
    assert len(_tables(stack, table_needs_legs=False)) == 1


# a bed 1.6 m wide, 2.0 m long against the wall at y = 5: frame and mattress down to the floor,
# its top at 0.62 m (table height by the numbers), a head board
BED = [
    SceneBox(70, "bed", (2.0, 3.0, 0.0), (3.6, 5.0, 0.62)),
    SceneBox(71, "bed", (2.0, 4.92, 0.0), (3.6, 5.0, 1.1)),
]


def _pitched(x, y, tx, ty):
    dist = ((tx - x) ** 2 + (ty - y) ** 2) ** 0.5
    return look_at((x, y, 1.2), (tx, ty, 1.2 - dist * 0.268))  # 15 degrees down


def _tables_seen(boxes, poses, **options):
    frames = [make_frame([*box_room(), *boxes], T, pose_id=i, noise_m=0.001) for i, T in enumerate(poses)]
    world, _ = run_stages(frames, [BackgroundStage(**options)])
    return [i for i in world.background.values() if i.class_name == "table"]


# from 0.4 m before its foot the bed's near edge is the image's lower edge: that view cannot
# look under it; from farther, and from its side, the views see its solid sides
NEAR_FIRST = [_pitched(2.8, 2.6, 2.8, 4.8), _pitched(2.8, 1.0, 2.8, 4.8), _pitched(1.0, 2.0, 3.0, 4.0),
              _pitched(4.6, 1.5, 2.8, 4.0)]


def test_a_bed_seen_near_first_then_on_its_solid_sides_is_not_a_table():
    assert _tables_seen(BED, NEAR_FIRST[:1]) != []  # the near view alone: a table
    assert _tables_seen(BED, NEAR_FIRST) == []


def test_a_table_seen_near_first_then_on_its_legs_stays_a_table():
    assert len(_tables_seen(_table(2.0, 3.0, 3.6, 4.0), NEAR_FIRST)) == 1


def test_a_desk_with_a_front_panel_seen_from_its_sides_too_stays_a_table():
    # a front panel under the desk's near edge faces the first view (solid), its sides are open
    desk = [*_table(2.0, 3.0, 3.6, 3.8), SceneBox(58, "table", (2.0, 3.0, 0.3), (3.6, 3.02, 0.71))]
    poses = [_pitched(2.8, 1.0, 2.8, 4.0), _pitched(0.8, 3.4, 4.0, 3.4), _pitched(4.8, 3.4, 1.0, 3.4)]
    assert len(_tables_seen(desk, poses)) == 1
