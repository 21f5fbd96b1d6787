"""Large furniture seen in part gets the depth the camera could not see (``amodal.py``): a bed
seen from its side as a strip is as wide as a bed, behind the strip and never through a wall;
what was seen whole, or from along the strip, or is of a class without a width, keeps its box."""

import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.amodal import complete_footprint
from hiper_cli.perceive.foreground.seen_box import SeenBox
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import World
from tests.fg_constants import constants
from tests.fg_scene import SceneBox, background_instances, make_frame, pose_looking_x, room

STRIP = (np.array([10.0, 4.0, 0.0]), np.array([11.0, 4.26, 0.6]))  # a bed's side, 0.26 m deep


def _frames(*things):
    """20 frames of ``things`` in the test room, seen from the origin along +x, 1 m high."""
    return [make_frame([*room(), *things], pose_looking_x(), k / 30.0, k) for k in range(20)]


def _foreground(frames, **options):
    """The foreground instances a ``ForegroundStage`` (the frames' own detections) makes of
    ``frames``, with ``options``."""
    with constants(**options) as fields:
        stage = ForegroundStage(detector="log", pixel_step=2, **fields)
        world, _ = run_stages(frames, [stage], World(background=background_instances(room())))
    return list(world.foreground.values())


def _complete(cls, view, walls=()):
    lower, upper = complete_footprint(*STRIP, cls, None if view is None else np.array(view, float), walls)
    return lower, upper


def test_a_bed_seen_from_its_side_is_as_deep_as_a_bed_behind_what_was_seen():
    lower, upper = _complete("bed", [6.0, 1.3, 1.2])  # the camera lies beyond the strip on -y
    assert np.allclose(lower, STRIP[0])  # the face it saw stays where it was seen
    assert np.allclose(upper, [11.0, 4.9, 0.6])  # the rest lies behind it, 0.9 m in all
    lower, upper = _complete("bed", [12.0, 7.0, 1.2])  # seen from the other side: it lies in front
    assert np.allclose(lower, [10.0, 4.26 - 0.9, 0.0]) and np.allclose(upper, STRIP[1])


def test_the_depth_stops_at_a_wall_behind_the_object():
    wall = Box3D(np.array([10.5, 4.6, 1.2]), np.array([3.0, 2.4, 0.02]),
                 R=np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))  # normal along y
    lower, upper = _complete("bed", [6.0, 1.3, 1.2], [wall])
    assert np.isclose(upper[1], 4.58) and np.isclose(lower[1], 4.0)
    aside = Box3D(np.array([14.0, 4.6, 1.2]), np.array([3.0, 2.4, 0.02]), R=wall.R)  # not behind it
    assert np.isclose(_complete("bed", [6.0, 1.3, 1.2], [aside])[1][1], 4.9)


def test_what_was_seen_along_its_thin_side_or_whole_or_has_no_width_is_unchanged():
    along = [10.5, 4.1, 1.2]  # within the strip's y slab: the camera looked along it, not across
    for cls, view in (("bed", along), ("chair", [6.0, 1.3, 1.2]), ("bed", None)):
        lower, upper = _complete(cls, view)
        assert np.allclose(lower, STRIP[0]) and np.allclose(upper, STRIP[1]), (cls, view)
    whole = (np.array([0.0, 0.0, 0.0]), np.array([2.0, 1.0, 0.9]))
    lower, upper = complete_footprint(*whole, "bed", np.array([1.0, -3.0, 1.2]))
    assert np.allclose(lower, whole[0]) and np.allclose(upper, whole[1])


def test_the_seen_box_remembers_where_its_named_blobs_were_seen_from():
    box = SeenBox()
    assert box.viewpoint() is None
    box.add(np.zeros(3), np.ones(3), named=False)  # no viewpoint given
    assert box.viewpoint() is None
    for k in range(5):
        box.add(np.zeros(3), np.ones(3), named=True, viewpoint_m=np.array([k, 0.0, 1.2]))
    box.add(np.zeros(3), np.ones(3), named=False, viewpoint_m=np.array([50.0, 0.0, 1.2]))  # unnamed
    assert np.allclose(box.viewpoint(), [2.0, 0.0, 1.2])
    both = SeenBox()
    both.extend(box)
    assert np.allclose(both.viewpoint(), box.viewpoint())


def test_a_refrigerator_seen_from_the_front_is_as_deep_as_one_in_the_knowledge_base():
    # 0.7 m deep, taller than the camera: only its front (and the handles' relief) is in view
    fridge = SceneBox(10, np.array([2.9, 0.0, 0.9]), np.array([0.7, 0.7, 1.8]), "refrigerator", relief_m=0.1)
    frames = _frames(fridge)

    def centre_x(**options):
        (inst,) = _foreground(frames, **options)
        assert inst.class_name == "refrigerator"
        return inst.box.center_m[0], inst.box.extent_m[0]

    seen_x, seen_depth = centre_x(complete_footprints=False)
    assert seen_depth < 0.2 and 2.9 - seen_x > 0.3  # the front only: its centre far before the fridge's
    x, depth = centre_x()
    assert depth == pytest.approx(0.55)  # a refrigerator's least depth, behind the front it saw
    assert x - depth / 2 == pytest.approx(seen_x - seen_depth / 2) and 2.9 - x < (2.9 - seen_x) / 2


def _one_view_in_ten_is_noise(hidden_flag, seen):
    """One view in ten that showed the part is noise; three in twelve are as many as the box's
    quantile takes."""
    box = SeenBox()
    for k in range(10):
        box.add(np.zeros(3), np.ones(3), named=True, **{hidden_flag: k > 0})
    assert not seen(box)
    for _ in range(2):
        box.add(np.zeros(3), np.ones(3), named=True, **{hidden_flag: False})
    assert seen(box)


def test_a_chair_whose_top_no_view_showed_is_as_tall_as_a_chair():
    from hiper_cli.perceive.foreground.amodal import complete_height

    lower, upper = np.array([0.0, 0.0, 0.0]), np.array([0.45, 0.4, 0.52])  # a seat under a desk's top
    assert complete_height(lower, upper, "chair", top_seen=False)[1][2] == pytest.approx(0.7)
    for cls, seen in (("chair", True), ("bed", False)):  # its top in view; a class with no height
        assert np.allclose(complete_height(lower, upper, cls, top_seen=seen)[1], upper)
    _one_view_in_ten_is_noise("top_hidden", SeenBox.top_seen)


def test_a_chair_behind_a_panel_is_raised_to_a_chairs_height_in_the_knowledge_base():
    chair = SceneBox(10, np.array([3.5, 0.0, 0.45]), np.array([0.5, 0.5, 0.9]), "chair", relief_m=0.1)
    # a desk's front, 2 m before it, from 0.6 m up: the camera (1 m high) sees the chair's legs only
    panel = SceneBox(11, np.array([2.0, 0.0, 0.9]), np.array([0.05, 2.0, 0.6]), "other")
    frames = _frames(chair, panel)

    def chair_box(**options):
        (inst,) = [i for i in _foreground(frames, **options) if i.class_name == "chair"]
        return inst.box.center_m[2] - inst.box.extent_m[2] / 2, inst.box.extent_m[2]

    bottom, seen_height = chair_box(complete_footprints=False)
    assert seen_height < 0.45
    assert chair_box() == pytest.approx((bottom, 0.7))


def test_a_chair_whose_base_no_view_showed_stands_on_the_floor():
    from hiper_cli.perceive.foreground.amodal import complete_base

    lower, upper = np.array([0.0, 0.0, 0.66]), np.array([0.44, 0.17, 0.92])  # a back above a table
    base_lower, base_upper = complete_base(lower, upper, "chair", bottom_seen=False, floor_z_m=0.02)
    assert np.allclose(base_lower, [0.0, 0.0, 0.02]) and np.allclose(base_upper, upper)
    for cls, seen in (("chair", True), ("bottle", False)):  # its base in view; a class on tables too
        assert np.allclose(complete_base(lower, upper, cls, bottom_seen=seen, floor_z_m=0.02)[0], lower)
    _one_view_in_ten_is_noise("bottom_hidden", SeenBox.bottom_seen)


def _behind_a_counter(obstacle_class, **options):
    """The box (bottom, height) of an object 0.9 m tall 3.5 m before the camera (1 m high), with
    a counter's front 0.75 m high 2 m before the camera: only the object's upper part is in view."""
    thing = SceneBox(10, np.array([3.5, 0.0, 0.45]), np.array([0.5, 0.5, 0.9]), obstacle_class, relief_m=0.1)
    counter = SceneBox(11, np.array([2.0, 0.0, 0.375]), np.array([0.05, 2.0, 0.75]), "other")
    (inst,) = [i for i in _foreground(_frames(thing, counter), **options) if i.class_name == obstacle_class]
    return inst.box.center_m[2] - inst.box.extent_m[2] / 2, inst.box.extent_m[2]


def test_a_chair_behind_a_counter_reaches_down_to_the_floor_in_the_knowledge_base():
    seen_bottom, seen_height = _behind_a_counter("chair", complete_footprints=False)
    assert seen_bottom > 0.4 and seen_height < 0.5  # the back above the counter only
    bottom, height = _behind_a_counter("chair")
    assert bottom == pytest.approx(0.0, abs=0.01) and height == pytest.approx(seen_bottom + seen_height)


def test_what_may_stand_on_a_table_keeps_the_base_it_was_seen_with():
    seen = _behind_a_counter("potted plant", complete_footprints=False)
    assert seen[0] > 0.4
    assert _behind_a_counter("potted plant") == pytest.approx(seen)


def test_a_chair_seen_standing_keeps_its_box():
    chair = SceneBox(10, np.array([3.5, 0.0, 0.45]), np.array([0.5, 0.5, 0.9]), "chair", relief_m=0.1)
    frames = _frames(chair)

    def box(**options):
        (inst,) = _foreground(frames, **options)
        return np.concatenate([inst.box.center_m, inst.box.extent_m])

    assert np.allclose(box(), box(complete_footprints=False))


def test_a_base_is_hidden_by_something_nearer_below_it_not_by_what_it_stands_on():
    from hiper_cli.perceive.foreground.segment import Blob
    from hiper_cli.perceive.foreground.whole import bottom_hidden

    v, u = np.mgrid[100:200:2, 300:340:2]
    uv = np.stack([u.ravel(), v.ravel()], axis=1).astype(np.int32)
    points = np.column_stack([np.zeros(len(uv)), np.zeros(len(uv)), np.full(len(uv), 3.5)])
    blob = Blob(points, points.copy(), uv, np.array([299.0, 99.0, 341.0, 201.0]))
    depth = np.zeros((480, 640), np.float32)
    depth[201:, :] = 3.45  # the floor it stands on, just before its base
    assert not bottom_hidden(blob, depth, 2)
    depth[201:, :] = 2.0  # a counter's front 1.5 m before it
    assert bottom_hidden(blob, depth, 2)
    depth[201:, :] = 0.0  # no return below it
    assert not bottom_hidden(blob, depth, 2)
    lower_uv = uv + np.array([0, 280], np.int32)
    low = Blob(points, points.copy(), lower_uv, np.array([299.0, 379.0, 341.0, 480.0]))
    assert bottom_hidden(low, depth, 2)  # cut by the image's bottom edge
