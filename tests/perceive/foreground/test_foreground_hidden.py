"""The visible part of an object hidden in part, named by the detection box that holds it."""

import numpy as np

from hiper_cli.perceive.foreground.hidden import name_hidden
from hiper_cli.perceive.foreground.match import Match
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAMERA = CameraIntrinsics(width=640, height=480, fx=525.0, fy=525.0, cx=319.5, cy=239.5)
STEP = 4
CHAIR_BOX = [300.0, 200.0, 380.0, 360.0]  # 0.6 m x 1.2 m at 4 m
UNKNOWN = Match("unknown", 0.0, None, 0.0)
T_MAP_CAM = np.array([[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0],
                      [0.0, -1.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0]])
"""The camera 1 m above the floor (z = 0), looking along the map's x axis."""


def _grid(u0, v0, u1, v1):
    """The segmentation's sample pixels (every STEP-th from STEP // 2) inside [u0, u1) x [v0, v1)."""
    us = np.arange(STEP // 2, CAMERA.width, STEP)
    vs = np.arange(STEP // 2, CAMERA.height, STEP)
    us, vs = us[(us >= u0) & (us < u1)], vs[(vs >= v0) & (vs < v1)]
    U, V = np.meshgrid(us, vs)
    return np.stack([U.ravel(), V.ravel()], axis=1).astype(np.int32)


def _scene(front_m=3.0, back_m=4.0, wall_m=6.0):
    """A chair's back (rows 200-250 of its box, at ``back_m``) above a table top that hides the
    rest of its box (``front_m``), a wall behind (``wall_m``)."""
    depth = np.full((CAMERA.height, CAMERA.width), wall_m, dtype=np.float32)
    depth[250:, 250:430] = front_m
    depth[200:250, 300:380] = back_m
    back = _grid(300, 200, 380, 250)
    return depth, back


def _name(blobs, depth, boxes=(("chair", CHAIR_BOX),), matches=None, floor_z_m=None):
    dets = Detections.from_records([{"xyxy": b, "class": c, "score": 0.9} for c, b in boxes])
    uvs = [uv for uv, _ in blobs]
    depths = [np.full(len(uv), z) for uv, z in blobs]
    rgb = np.zeros((CAMERA.height, CAMERA.width, 3), dtype=np.uint8)
    frame = Frame(0.0, rgb, depth, CAMERA, T_MAP_CAM, 0)
    return name_hidden(matches or [UNKNOWN] * len(blobs), uvs, depths, dets, frame, STEP, min_score=0.3,
                       floor_z_m=floor_z_m)


def test_a_chair_back_above_a_table_takes_the_chairs_box():
    depth, back = _scene()
    (m,) = _name([(back, 4.0)], depth)
    assert m.class_name == "chair" and m.detection_index == 0 and 0.0 < m.iou < 0.5


def test_nothing_nearer_hides_the_rest_of_the_box_no_name():
    depth, back = _scene(front_m=6.0)  # the box's rest is wall behind: a part in plain view
    assert _name([(back, 4.0)], depth)[0].class_name == "unknown"


def test_a_thing_in_front_does_not_take_the_name_of_the_box_behind():
    depth, back = _scene()
    cup = _grid(330, 204, 350, 230)
    depth[204:230, 330:350] = 3.5  # a cup on the table, in front of the chair's back
    back = np.array([p for p in back if not (330 <= p[0] < 350 and 204 <= p[1] < 230)], dtype=np.int32)
    cup_m, back_m = _name([(cup, 3.5), (back, 4.0)], depth)
    assert cup_m.class_name == "unknown" and back_m.class_name == "chair"
    alone = _name([(cup, 3.5)], depth)[0]  # the chair's back not segmented: the cup is no top across
    assert alone.class_name == "unknown"


def test_a_part_at_the_bottom_of_the_box_is_not_its_object():
    depth, _ = _scene()
    depth[:, :] = 3.0
    depth[330:360, 300:380] = 4.0  # a patch of floor behind the object's lower part
    patch = _grid(300, 330, 380, 360)
    assert _name([(patch, 4.0)], depth)[0].class_name == "unknown"


def test_a_box_too_large_for_its_class_at_the_blobs_depth_names_nothing():
    depth, back = _scene(front_m=8.0, back_m=9.0, wall_m=12.0)  # the box is 2.7 m tall at 9 m
    assert _name([(back, 9.0)], depth)[0].class_name == "unknown"


def test_a_box_that_named_a_blob_by_iou_names_no_other():
    depth, back = _scene()
    other = _grid(300, 250, 380, 360)
    named = Match("chair", 0.9, 0, 0.7)
    out = _name([(other, 3.0), (back, 4.0)], depth, matches=[named, UNKNOWN])
    assert out[1].class_name == "unknown"


def test_a_blob_in_two_boxes_takes_the_one_it_fills_most():
    depth, back = _scene()
    couch = [280.0, 190.0, 420.0, 400.0]  # a larger box around the chair's
    out = _name([(back, 4.0)], depth, boxes=(("couch", couch), ("chair", CHAIR_BOX)))
    assert out[0].class_name == "chair" and out[0].detection_index == 1


def test_the_box_placed_at_the_blobs_depth_stands_no_lower_than_the_floor():
    depth, back = _scene()  # the box's bottom at 4 m lies 0.08 m above the floor
    assert _name([(back, 4.0)], depth, floor_z_m=0.0)[0].class_name == "chair"
    # a floor 0.5 m higher: the object would stand 0.42 m under it (a patch of floor past a bed)
    assert _name([(back, 4.0)], depth, floor_z_m=0.5)[0].class_name == "unknown"
