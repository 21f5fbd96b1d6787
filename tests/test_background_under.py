"""A table top stands on legs (``under.py``): the top of a solid block at table height is not a table."""

from _bg_scenes import SceneBox, box_room, look_at, make_frame

from hiper_cli.perceive.background import BackgroundStage
from hiper_cli.perceive.runner import run_stages

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
