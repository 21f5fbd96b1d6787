"""A mapped table's body takes the name its views give it (``table_views.py``): ``table`` once the
detector named it in as many views as a track's class needs, ``unknown`` before; a table box
hidden behind a nearer surface, or over another table, is no evidence for it. The body is linked
to the background's table instance (``data["same_object_as"]``): one real table."""

from __future__ import annotations

import numpy as np

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.supports import table_bodies
from hiper_cli.perceive.foreground.table_views import TableViews
from hiper_cli.perceive.stage import World
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAMERA = CameraIntrinsics(640, 480, 525.0, 525.0, 319.5, 239.5)


def _background(name: str, centre: list[float], extent: list[float]) -> Instance:
    inst = Instance("background", name, Box3D(np.array(centre), np.array(extent)), 2.0, 9.0)
    inst.data["plane_map"] = [0.0, 0.0, 1.0, -(centre[2] + extent[2] / 2.0)]
    return inst


FLOOR = _background("floor", [2.0, 2.0, -0.01], [8.0, 8.0, 0.02])
TABLE = _background("table", [2.0, 3.0, 0.74], [1.6, 0.9, 0.02])  # top at 0.75 m, 3 m ahead


def _looking_along_y(height_m: float = 1.2) -> np.ndarray:
    """T_map_cam of a camera at (2, 0, height) looking along +y, slightly down (10°)."""
    down = np.radians(10.0)
    forward = np.array([0.0, np.cos(down), -np.sin(down)])
    right = np.array([1.0, 0.0, 0.0])
    T = np.eye(4)
    T[:3, :3] = np.column_stack([right, np.cross(forward, right), forward])  # x right, y down, z ahead
    T[:3, 3] = [2.0, 0.0, height_m]
    return T


def _frame(depth_m: float, pose_id: int = 0) -> Frame:
    depth = np.full((480, 640), depth_m, dtype=np.float32)
    rgb = np.zeros((480, 640, 3), np.uint8)
    return Frame(float(pose_id), rgb, depth, CAMERA, _looking_along_y(), pose_id)


def _body_image_box() -> np.ndarray:
    """Where the table's body (floor to top) lies in the image: its projected corners."""
    ((_, box, _),) = table_bodies([FLOOR, TABLE], 0.0, [], [])
    p = box.corners() @ np.linalg.inv(_looking_along_y())[:3, :3].T + np.linalg.inv(_looking_along_y())[:3, 3]
    u, v = CAMERA.fx * p[:, 0] / p[:, 2] + CAMERA.cx, CAMERA.fy * p[:, 1] / p[:, 2] + CAMERA.cy
    return np.array([u.min(), v.min(), u.max(), v.max()])


def _table_detection(xyxy: np.ndarray, name: str = "dining table", score: float = 0.4) -> Detections:
    return Detections(xyxy.reshape(1, 4), (name,), np.array([score]))


def _views(n: int, depth_m: float = 0.0, name: str = "dining table", shift_px: float = 0.0) -> TableViews:
    views = TableViews(min_score=0.3)
    box = _body_image_box() + np.array([shift_px, 0.0, shift_px, 0.0])
    for k in range(n):
        views.add(_frame(depth_m, k), _table_detection(box, name))
    return views


def _bodies() -> list[tuple[Box3D, np.ndarray]]:
    return [(box, top) for _, box, top in table_bodies([FLOOR, TABLE], 0.0, [], [])]


def test_views_that_name_the_table_count_for_its_body() -> None:
    assert _views(3).named_views(_bodies()) == [3]
    assert _views(3, depth_m=6.0).named_views(_bodies()) == [3]  # the wall behind it: seen


def test_a_table_box_elsewhere_hidden_or_of_another_class_is_no_evidence() -> None:
    assert _views(3, shift_px=400.0).named_views(_bodies()) == [0]  # the box lies beside it
    assert _views(3, depth_m=1.0).named_views(_bodies()) == [0]  # a surface 1 m ahead hides it
    assert _views(3, name="chair").named_views(_bodies()) == [0]
    assert len(_views(3, name="chair")) == 0  # such frames are not even kept


def test_one_table_box_names_one_body() -> None:
    behind = _background("table", [2.0, 6.0, 0.74], [1.6, 0.9, 0.02])  # straight behind it, further
    bodies = [(box, top) for _, box, top in table_bodies([FLOOR, TABLE, behind], 0.0, [], [])]
    views = _views(2, depth_m=0.0)
    ahead_m = [round(float(b.center_m[1]), 1) for b, _ in bodies]
    named = dict(zip(ahead_m, views.named_views(bodies), strict=True))
    assert named == {3.0: 2, 6.0: 0}


def test_the_stage_names_the_body_a_table_once_enough_views_named_it() -> None:
    stage = ForegroundStage(detector="log")
    world = World(background={i.uuid: i for i in (FLOOR, TABLE)})
    need = stage.config.min_class_observations
    stage._table_views = _views(need - 1)
    (body,) = stage._geometry_only(world, [])
    assert body.class_name == "unknown" and body.data["named_views"] == need - 1
    assert body.data["same_object_as"] == TABLE.uuid  # still the same real object as the top
    stage._table_views = _views(need)
    (body,) = stage._geometry_only(world, [])
    assert body.class_name == "table" and body.layer == "foreground"
    assert body.data["same_object_as"] == TABLE.uuid and body.state == "static"


def test_the_stage_keeps_the_views_its_detector_named_a_table_in() -> None:
    from hiper_cli.perceive.foreground.table_views import TABLE_DETECTOR_CLASSES

    class TableDetector:
        name = "tables"

        def detect(self, frame: Frame) -> Detections:
            return _table_detection(_body_image_box(), TABLE_DETECTOR_CLASSES[0])

    stage = ForegroundStage(detector="log", detector_instance=TableDetector(), detector_threads=False)
    dets, _ = stage._detections(_frame(0.0), None)
    assert len(stage._table_views) == 1
    assert TABLE_DETECTOR_CLASSES[0] not in dets.class_names  # the frame's own detections drop it


def test_an_unnamed_instance_that_holds_the_table_is_that_table() -> None:
    stage = ForegroundStage(detector="log")
    world = World(background={i.uuid: i for i in (FLOOR, TABLE)})
    ((_, body_box, _),) = table_bodies([FLOOR, TABLE], 0.0, [], [])
    held = Instance("foreground", "unknown", Box3D(body_box.center_m, body_box.extent_m * 0.95), 1.0, 9.0)
    chair_box = Box3D(np.array([2.0, 2.3, 0.45]), np.array([0.5, 0.5, 0.9]))
    chair = Instance("foreground", "chair", chair_box, 1.0, 9.0)
    stage._table_views = _views(stage.config.min_class_observations)
    (back,) = stage._geometry_only(world, [held, chair])  # no body of its own: the instance holds it
    assert back is held and held.class_name == "table" and held.data["same_object_as"] == TABLE.uuid
    assert chair.class_name == "chair" and "same_object_as" not in chair.data
    stage._table_views = TableViews(min_score=0.3)  # no view named it: the same object, unnamed
    other = Instance("foreground", "unknown", Box3D(body_box.center_m, body_box.extent_m * 0.95), 1.0, 9.0)
    (back,) = stage._geometry_only(world, [other])
    assert back.class_name == "unknown" and back.data["same_object_as"] == TABLE.uuid


def test_chairs_in_a_row_beside_the_table_are_not_the_table() -> None:
    # a piece along the table's side (reaching its top's height there) that stands mostly
    # beside the top: the row of chairs at the table, fused as one unnamed piece
    stage = ForegroundStage(detector="log")
    world = World(background={i.uuid: i for i in (FLOOR, TABLE)})
    row = Instance("foreground", "unknown", Box3D(np.array([2.0, 2.15, 0.45]), np.array([1.6, 1.0, 0.9])),
                   1.0, 9.0)
    stage._table_views = _views(stage.config.min_class_observations)
    assert stage._geometry_only(world, [row]) == []  # the row holds no body, nor is it the table
    assert row.class_name == "unknown" and "same_object_as" not in row.data
