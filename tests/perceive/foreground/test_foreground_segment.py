"""Algorithm 3 details: background boxes, fragments, supports."""

import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundConfig
from hiper_cli.perceive.foreground.background_filter import inside_boxes
from hiper_cli.perceive.foreground.segment import Blob, cell_inverse, segment, support_below
from tests.fg_constants import patched
from tests.fg_scene import CAMERA, SceneBox, background_instances, make_frame, person, pose_looking_x, room


def test_inside_boxes_rotated_box_and_per_point_margin():
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    box = Box3D(np.array([1.0, 0.0, 0.0]), np.array([2.0, 0.2, 0.2]), R)
    pts = np.array([[1 + 0.9 * c, 0.9 * s, 0.0], [1.0, 0.0, 0.15], [1.0, 0.0, 0.15], [3.0, 3.0, 3.0]])
    got = inside_boxes(pts, [box], np.array([0.0, 0.0, 0.06, 10.0]))
    assert got.tolist() == [True, False, True, True]
    assert not inside_boxes(pts, [], 0.1).any()


def test_person_stands_on_the_floor_after_filtering(monkeypatch):
    boxes = [*room(), person(10, 3.0, 0.0)]
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = background_instances(boxes)
    floor = [i.box for i in bg.values() if i.class_name == "floor"]
    # Samples only: a block mean where a foot meets the floor may keep one floor sample.
    cfg = patched(monkeypatch, pixel_step=2, background_block_mean=False)
    (blob,), _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, [i.box for i in bg.values()], cfg, floor)
    assert blob.points_map[:, 2].min() > 0.05  # the filter cut the feet with the floor ...
    assert blob.support_z_m == pytest.approx(0.0)
    assert blob.extent_map_m[2] == pytest.approx(1.7, abs=0.05)  # ... the box reaches down again
    assert blob.center_map_m[2] == pytest.approx(0.85, abs=0.03)
    (no_support,), _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, [i.box for i in bg.values()], cfg)
    assert no_support.support_z_m is None and no_support.center_map_m[2] > 0.87


def test_a_head_above_a_gap_joins_its_body(monkeypatch):
    body = SceneBox(10, np.array([3.0, 0.0, 0.75]), np.array([0.3, 0.5, 1.5]), "person")
    head = SceneBox(11, np.array([3.0, 0.0, 1.75]), np.array([0.2, 0.2, 0.2]), "person")  # 0.4 m gap
    boxes = [*room(), body, head]
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = [i.box for i in background_instances(boxes).values()]
    cfg = ForegroundConfig(pixel_step=2, min_cluster_points=3)
    (blob,), _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, cfg)
    assert blob.points_map[:, 2].max() > 1.8
    apart, _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, patched(monkeypatch,
        pixel_step=2, min_cluster_points=3, fragment_ratio=0.0))
    assert len(apart) == 2


def test_boxes_behind_the_camera_are_skipped_and_cost_nothing():
    boxes = [*room(), person(10, 3.0, 0.0)]
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = [i.box for i in background_instances(boxes).values()]
    behind = [Box3D(np.array([-2.0, 0.0, 1.0]), np.array([0.5, 0.5, 0.5]))] * 50
    cfg = ForegroundConfig(pixel_step=2)
    blobs, stats = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg + behind, cfg)
    blobs2, stats2 = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, cfg)
    assert stats.after_background == stats2.after_background and len(blobs) == len(blobs2) == 1


def test_background_filter_matches_inside_boxes_on_rotated_boxes():
    from hiper_cli.perceive.foreground.background_filter import _filter_background
    from hiper_cli.perceive.foreground.segment import _rays

    rng = np.random.default_rng(7)
    step = 4
    rx, ry, _, _ = _rays(CAMERA, step)
    z = rng.uniform(0.5, 5.0, size=rx.shape)
    T = pose_looking_x()
    P_map = np.stack([rx * z, ry * z, z], axis=-1) @ T[:3, :3].T + T[:3, 3]
    valid = rng.random(z.shape) > 0.1
    boxes = []
    for yaw in (0.0, 0.3, np.pi / 2, 1.0):
        c, s = np.cos(yaw), np.sin(yaw)
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        boxes.append(Box3D(rng.uniform([1.5, -1, 0.5], [4, 1, 1.5]), rng.uniform(0.3, 1.5, 3), R))
    margin = np.full(z.shape, 0.05)
    cols = [np.ascontiguousarray(P_map[..., k].ravel()) for k in range(3)]
    got = _filter_background(valid, cols, margin, boxes, CAMERA, T, step, ForegroundConfig())
    expected = valid & ~inside_boxes(P_map.reshape(-1, 3), boxes, 0.05).reshape(z.shape)
    assert (got == expected).all() and (expected != valid).sum() > 20


def test_boxes_reaching_behind_the_camera_filter_exactly_and_visit_only_their_view():
    from hiper_cli.perceive.foreground.background_filter import _box_rois, _filter_background
    from hiper_cli.perceive.foreground.segment import _rays

    rng = np.random.default_rng(11)
    step = 4
    rx, ry, _, _ = _rays(CAMERA, step)
    z = rng.uniform(0.3, 5.0, size=rx.shape)
    T = pose_looking_x()  # at (0, 0, 1) looking along +x
    P_map = np.stack([rx * z, ry * z, z], axis=-1) @ T[:3, :3].T + T[:3, 3]
    valid = rng.random(z.shape) > 0.1
    c, s = np.cos(0.4), np.sin(0.4)
    yawed = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    boxes = [
        Box3D(np.array([0.0, 1.8, 1.5]), np.array([8.0, 1.0, 3.0])),  # a wall beside and behind
        Box3D(np.array([1.0, 0.0, -0.2]), np.array([6.0, 6.0, 0.6])),  # the floor under the camera
        Box3D(np.array([0.5, -1.2, 0.8]), np.array([3.0, 1.0, 1.0]), yawed),
    ]
    margin = np.full(z.shape, 0.05)
    cols = [np.ascontiguousarray(P_map[..., k].ravel()) for k in range(3)]
    got = _filter_background(valid, cols, margin, boxes, CAMERA, T, step, ForegroundConfig())
    expected = valid & ~inside_boxes(P_map.reshape(-1, 3), boxes, 0.05).reshape(z.shape)
    assert (got == expected).all()
    for box in boxes:  # each box takes points of the frame
        assert (valid & inside_boxes(P_map.reshape(-1, 3), [box], 0.05).reshape(z.shape)).sum() > 20
    T_cam_map = np.linalg.inv(T)
    _, cols_ = _box_rois(boxes[:1], 0.05, CAMERA, T_cam_map, step, z.shape, ForegroundConfig())[0]
    # the wall on the left is cut at the camera: it covers the left part of the image, not all
    assert cols_.start == 0 and cols_.stop < z.shape[1] * 0.75


def test_a_blob_whose_base_is_cut_by_the_lower_image_edge_stands_on_nothing_known():
    boxes = [*room(), person(10, 3.0, 0.0)]
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = background_instances(boxes)
    floor = [i.box for i in bg.values() if i.class_name == "floor"]
    cfg = ForegroundConfig(pixel_step=2)
    (blob,), _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, [i.box for i in bg.values()], cfg, floor)
    assert support_below(blob, floor, cfg, CAMERA.height) == pytest.approx(0.0)
    z = blob.points_map[:, 2]
    edge_v = CAMERA.height - 1
    # the lowest points at the image's lower edge: the feet are out of view
    feet = blob.pixels_uv.copy()
    feet[z <= z.min() + 0.005, 1] = edge_v
    cut = Blob(blob.points_cam, blob.points_map, feet, np.array([*blob.image_box_xyxy[:3], CAMERA.height]))
    assert support_below(cut, floor, cfg, CAMERA.height) is None
    # a higher part at the edge (a chair's front legs cut, its back feet in view): it still stands
    head = blob.pixels_uv.copy()
    head[z >= z.max() - 0.05, 1] = edge_v
    part = Blob(blob.points_cam, blob.points_map, head, np.array([*blob.image_box_xyxy[:3], CAMERA.height]))
    assert support_below(part, floor, cfg, CAMERA.height) == pytest.approx(0.0)


def test_cell_inverse_numbers_cells_like_unique_rows():
    rng = np.random.default_rng(5)
    for n in (1, 7, 300):
        xy = rng.normal(0.0, 2.0, (n, 2))
        _, expected = np.unique(np.floor(xy / 0.05).astype(np.int64), axis=0, return_inverse=True)
        assert np.array_equal(cell_inverse(xy, 0.05), expected.reshape(-1))


def test_a_cluster_too_long_for_one_object_is_kept_aside_for_the_static_map():
    # a rack 3.6 m long seen across the room: too long to be tracked as one object
    rack = SceneBox(20, np.array([3.4, 0.0, 0.75]), np.array([0.8, 3.6, 1.5]), "shelf")
    boxes = [*room(), rack, person(10, 1.8, -1.1)]
    frame = make_frame(boxes, pose_looking_x(z=2.0), 0.0, 0)
    bg = [i.box for i in background_instances(boxes).values()]
    blobs, stats = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, ForegroundConfig(pixel_step=2))
    assert len(blobs) == 1 and blobs[0].points_map[:, 0].max() < 2.0  # the person only
    assert stats.large and stats.rejected_clusters == len(stats.large)
    for large in stats.large:  # the rack's front and top, each longer than 3 m
        lo, hi = large.bounds_map
        assert hi[1] - lo[1] > 3.0 and lo[0] > 2.9
