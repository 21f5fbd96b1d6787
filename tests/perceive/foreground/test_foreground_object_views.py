"""An unnamed object takes the name its views give it (``object_views.py``): a static ``unknown``
that the detector named in enough of the views that showed it takes that class at the end of
the session; one named in too few views, hidden behind something nearer in them, or whose boxes
a named object in front explains better, stays ``unknown``."""

from __future__ import annotations

import numpy as np

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.object_views import ObjectViews, name_by_views
from hiper_cli.perceive.foreground.table_views import Scene, View
from hiper_cli.perceive.stage import World
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAMERA = CameraIntrinsics(640, 480, 525.0, 525.0, 319.5, 239.5)
CONFIG = ForegroundConfig()
NEED = CONFIG.min_class_observations
GLANCE_S = 0.4  # the views' spacing in log time: NEED of them span more than a glance


def _looking_along_y() -> np.ndarray:
    """T_map_cam of a camera at (2, 0, 1.2) looking along +y, slightly down (10°)."""
    down = np.radians(10.0)
    forward = np.array([0.0, np.cos(down), -np.sin(down)])
    right = np.array([1.0, 0.0, 0.0])
    T = np.eye(4)
    T[:3, :3] = np.column_stack([right, np.cross(forward, right), forward])
    T[:3, 3] = [2.0, 0.0, 1.2]
    return T


def _object(name: str, ahead_m: float, size_m: tuple[float, float, float] = (0.5, 0.5, 0.9)) -> Instance:
    """A static instance standing on the floor ``ahead_m`` in front of the camera, its surface the
    face turned to the camera."""
    extent = np.array(size_m)
    box = Box3D(np.array([2.0, ahead_m, extent[2] / 2.0]), extent)
    xs, zs = np.meshgrid(np.linspace(-0.2, 0.2, 5) * extent[0] / 0.5, np.linspace(0.05, extent[2], 6))
    face = np.column_stack([2.0 + xs.ravel(), np.full(xs.size, ahead_m - extent[1] / 2.0), zs.ravel()])
    inst = Instance("foreground", name, box, 0.0, 9.0)
    inst.data["surface_map"] = face.round(3).tolist()
    return inst


def _image_box(inst: Instance) -> np.ndarray:
    view = View(np.linalg.inv(_looking_along_y()), CAMERA, np.zeros((60, 80), np.float32), np.zeros((0, 4)))
    boxes, shown, _ = Scene([(inst.box, inst.box.corners())]).seen_in(view)
    assert shown[0]
    return boxes[0]


def _frame(stamp_s: float, depth_m: float) -> Frame:
    depth = np.full((480, 640), depth_m, dtype=np.float32)
    rgb = np.zeros((480, 640, 3), np.uint8)
    return Frame(stamp_s, rgb, depth, CAMERA, _looking_along_y(), int(stamp_s * 10))


def _views(named: int, shown: int = 0, over: Instance | None = None, name: str = "chair",
           depth_m: float = 0.0) -> ObjectViews:
    """``named`` views in which the detector named ``over`` (its image box) ``name``, then
    ``shown`` views without a box; a depth of 0 measures nothing (nothing hides the object)."""
    views = ObjectViews(min_score=0.3, walker_classes=("person",))
    xyxy = _image_box(over if over is not None else _object("unknown", 3.0))
    for k in range(named + shown):
        dets = (Detections(xyxy.reshape(1, 4), (name,), np.array([0.8])) if k < named
                else Detections(np.zeros((0, 4)), (), np.zeros(0)))
        views.add(_frame(GLANCE_S * k, depth_m), dets)
    return views


def _named(views: ObjectViews, *instances: Instance) -> list[str]:
    name_by_views(views, instances, World(), [], CONFIG)
    return [i.class_name for i in instances]


def test_an_unknown_named_in_enough_views_takes_the_name() -> None:
    unknown = _object("unknown", 3.0)
    assert name_by_views(_views(NEED), [unknown], World(), [], CONFIG) == [unknown]
    assert unknown.class_name == "chair"
    assert unknown.data["view_names"] == {"seen": NEED, "whole": NEED, "chair": NEED}
    assert _named(_views(NEED, shown=2), _object("unknown", 3.0)) == ["chair"]  # most views that showed it


def test_named_in_too_few_views_it_stays_unknown() -> None:
    assert _named(_views(NEED - 1), _object("unknown", 3.0)) == ["unknown"]
    # named in enough views among many more that showed it and named nothing: weakly supported
    assert _named(_views(NEED, shown=4 * NEED), _object("unknown", 3.0)) == ["unknown"]
    # two classes that swap: neither holds the share a name needs
    views = _views(NEED)
    for view, _, _, stamp_s in list(views._views):
        views._views.append((view, ("couch",), np.array([0.8]), stamp_s))
    assert _named(views, _object("unknown", 3.0)) == ["unknown"]


def test_named_in_one_glance_it_stays_unknown() -> None:
    views = ObjectViews(min_score=0.3)
    xyxy = _image_box(_object("unknown", 3.0))
    for k in range(NEED + 1):  # a view every 0.2 s, within 0.8 s: the views of one glance
        views.add(_frame(0.2 * k, 0.0), Detections(xyxy.reshape(1, 4), ("chair",), np.array([0.8])))
    unknown = _object("unknown", 3.0)
    assert _named(views, unknown) == ["unknown"] and unknown.data["view_spans_s"] == {"chair": 0.8}
    assert _named(_views(NEED), _object("unknown", 3.0)) == ["chair"]  # 1.2 s apart


def test_hidden_behind_a_nearer_surface_the_views_do_not_count() -> None:
    unknown = _object("unknown", 3.0)
    assert _named(_views(2 * NEED, depth_m=1.5), unknown) == ["unknown"]  # a wall of boxes at 1.5 m
    assert unknown.data["view_names"] == {"seen": 0, "whole": 0}
    assert _named(_views(2 * NEED, depth_m=6.0), _object("unknown", 3.0)) == ["chair"]  # the wall behind it


def test_a_named_object_in_front_explains_the_boxes() -> None:
    chair = _object("chair", 2.0)  # straight in front of it: the boxes fit the chair best
    views = _views(2 * NEED, over=chair)
    assert _named(views, _object("unknown", 3.0)) == ["chair"]  # alone, the boxes overlap it enough
    assert _named(views, chair, _object("unknown", 3.0)) == ["chair", "unknown"]


def test_no_second_instance_of_a_class_in_its_place_nor_an_implausible_class() -> None:
    chair = _object("chair", 3.3)  # the same chair, a piece of it left unnamed
    assert _named(_views(NEED), chair, _object("unknown", 3.0)) == ["chair", "unknown"]
    couch = _object("unknown", 3.0, (2.2, 0.9, 0.9))  # far longer than any cup
    assert _named(_views(NEED, over=couch, name="cup"), couch) == ["unknown"]
    assert len(_views(NEED, name="person")) == NEED  # the views count, a walker's box names nothing
    assert _named(_views(NEED, name="person"), _object("unknown", 3.0)) == ["unknown"]


def test_the_stage_names_its_unknowns_at_the_end_of_the_session() -> None:
    class Chairs:
        name = "chairs"

        def detect(self, frame: Frame) -> Detections:
            return Detections(_image_box(_object("unknown", 3.0)).reshape(1, 4), ("chair",), np.array([0.8]))

    stage = ForegroundStage(detector="log", detector_instance=Chairs(), detector_threads=False)
    for k in range(4 * NEED):
        stage._detections(_frame(0.1 * k, 0.0), None)
    assert len(stage._views) == 2 * NEED  # one view every 0.2 s of log time
    unknown = _object("unknown", 3.0)
    stage._instances[unknown.uuid] = unknown  # closed earlier: the world holds it already
    result = stage.finish(World(foreground={unknown.uuid: unknown}))
    assert [(i.uuid, i.class_name) for i in result.instances] == [(unknown.uuid, "chair")]  # written anew


def test_the_table_boxes_the_class_filters_drop_name_an_unnamed_table() -> None:
    class Tables:
        name = "tables"

        def detect(self, frame: Frame) -> Detections:
            desk = _image_box(_object("unknown", 3.0, (1.2, 0.7, 0.75)))
            return Detections(desk.reshape(1, 4), ("dining table",), np.array([0.8]))

    stage = ForegroundStage(detector="log", detector_instance=Tables(), detector_threads=False)
    for k in range(4 * NEED):
        dets, _ = stage._detections(_frame(0.1 * k, 0.0), None)
        assert len(dets) == 0  # no track takes a table box
    desk = _object("unknown", 3.0, (1.2, 0.7, 0.75))
    assert _named(stage._views, desk) == ["table"]
