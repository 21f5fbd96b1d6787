"""Blobs refined with the detections: occluded objects joined, touching ones split, fragments."""


import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundConfig
from hiper_cli.perceive.foreground.background_filter import table_leg_boxes
from hiper_cli.perceive.foreground.refine import refine_blobs
from hiper_cli.perceive.foreground.segment import Blob, image_box, segment
from tests.fg_constants import constants, patched
from tests.fg_scene import (
    CAMERA,
    SceneBox,
    background_instances,
    chair,
    make_frame,
    person,
    pose_looking_x,
    room,
)


def _segment(boxes, cfg, keep_fragments=False):
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = [i.box for i in background_instances(boxes).values()]
    blobs, _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, cfg, keep_fragments=keep_fragments)
    return frame, blobs


def _refine(blobs, xyxy, cfg):
    return refine_blobs(blobs, np.asarray(xyxy, dtype=np.float64), cfg, CAMERA.width, CAMERA.height)


def _person_behind_a_table():
    top = SceneBox(3, np.array([2.2, 0.0, 0.68]), np.array([0.4, 1.5, 0.1]), "table", True)
    return [*room(), top, person(10, 3.0, 0.0)]


def test_a_person_cut_by_a_table_becomes_one_blob_inside_its_detection():
    cfg = ForegroundConfig(pixel_step=2)
    frame, blobs = _segment(_person_behind_a_table(), cfg)
    assert len(blobs) == 2  # torso above the table, legs below it
    (whole,) = _refine(blobs, frame.detections.xyxy, cfg)
    assert len(whole.points_cam) == sum(len(b.points_cam) for b in blobs)
    assert whole.points_map[:, 2].min() < 0.2 and whole.points_map[:, 2].max() > 1.6
    assert whole.image_box_xyxy[3] > max(b.image_box_xyxy[3] for b in blobs) - 1  # spans both
    no_join = ForegroundConfig(pixel_step=2, detection_join=False)
    assert len(_refine(blobs, frame.detections.xyxy, no_join)) == 2
    assert len(_refine(blobs, np.zeros((0, 4)), cfg)) == 2  # no detection, no change


def test_fragments_join_their_object_or_are_dropped():
    cfg = ForegroundConfig(pixel_step=2, min_cluster_points=100)  # the legs (63 points) are a fragment
    frame, plain = _segment(_person_behind_a_table(), cfg)
    assert len(plain) == 1
    _, blobs = _segment(_person_behind_a_table(), cfg, keep_fragments=True)
    assert sorted(b.fragment for b in blobs) == [False, True]
    (whole,) = _refine(blobs, frame.detections.xyxy, cfg)
    assert not whole.fragment and len(whole.points_cam) == sum(len(b.points_cam) for b in blobs)
    (alone,) = _refine(blobs, np.zeros((0, 4)), cfg)  # nothing to join: the fragment goes
    assert len(alone.points_cam) == len(plain[0].points_cam)


def test_blobs_at_different_depths_in_one_box_stay_apart(monkeypatch):
    boxes = [*room(), person(10, 3.0, 0.0), chair(11, 4.5, 0.8)]
    cfg = patched(monkeypatch, pixel_step=2, join_gap_m=5.0)
    _, blobs = _segment(boxes, cfg)
    assert len(blobs) == 2
    both = [[0.0, 0.0, 160.0, 120.0]]  # one box around everything
    assert len(_refine(blobs, both, cfg)) == 2  # 1.5 m apart in depth
    assert len(_refine(blobs, both, patched(monkeypatch, pixel_step=2, join_depth_m=5.0))) == 1


def test_touching_people_are_split_by_their_detections():
    boxes = [*room(), person(10, 3.0, -0.25), person(11, 3.0, 0.25)]
    cfg = ForegroundConfig(pixel_step=2, detection_split=True)
    frame, blobs = _segment(boxes, cfg)
    assert len(blobs) == 1  # they touch: one cluster
    out = _refine(blobs, frame.detections.xyxy, cfg)
    assert len(out) == 2
    ids = frame.extras["ids"]
    for b in out:
        hit = ids[b.pixels_uv[:, 1], b.pixels_uv[:, 0]]
        assert np.mean(hit == np.bincount(hit).argmax()) > 0.95  # each part is one person
    assert sorted(float(b.center_map_m[1]) for b in out) == pytest.approx([-0.25, 0.25], abs=0.05)
    assert len(_refine(blobs, frame.detections.xyxy, ForegroundConfig(pixel_step=2))) == 1  # off by default


def test_floor_margin_follows_the_viewing_ray(monkeypatch):
    # A low box far away: depth noise there is large along the ray but the floor is seen at a
    # grazing angle, so only a thin slice above it is noise.
    low = SceneBox(10, np.array([4.6, 0.0, 0.15]), np.array([0.4, 0.6, 0.3]), "chair")
    boxes = [*room(), low]
    cfg = patched(monkeypatch, pixel_step=2, background_margin_per_m2=0.005)
    (blob,) = _segment(boxes, cfg)[1]
    assert blob.points_map[:, 2].min() < 0.09
    with constants(background_noise_along_ray=False):
        (old,) = _segment(boxes, cfg)[1]
    assert old.points_map[:, 2].min() > 0.14  # 0.05 + 0.005 * 4.5² of the box's base is lost


def test_block_mean_keeps_a_head_board_in_front_of_a_noisy_wall(monkeypatch):
    # A bed's head board 5 cm in front of a wall 3 m away, with the simulator's depth noise
    # (sigma 1.4 cm there): single samples of it fall into the wall's margin, the means of
    # their pixel blocks do not.
    board = SceneBox(10, np.array([5.975, 0.0, 0.5]), np.array([0.05, 1.0, 1.0]), "bed")
    boxes = [*room(), board]
    frame = make_frame(boxes, pose_looking_x(x=3.0), 0.0, 0)
    z = frame.depth_m.astype(np.float64)
    sigma = 0.0012 + 0.0019 * (z - 0.4) ** 2
    rng = np.random.default_rng(1)
    noisy = np.where(z > 0, z + rng.normal(0.0, 1.0, z.shape) * sigma, 0.0).astype(np.float32)
    bg = [i.box for i in background_instances(boxes).values()]
    ids = frame.extras["ids"]
    on_board = int((ids[2::4, 2::4] == 10).sum())

    def board_points(cfg):
        (blob,) = segment(noisy, CAMERA, frame.T_map_cam, bg, cfg)[0]
        return int((ids[blob.pixels_uv[:, 1], blob.pixels_uv[:, 0]] == 10).sum())

    assert board_points(ForegroundConfig()) == on_board
    assert board_points(patched(monkeypatch, background_block_mean=False)) < 0.95 * on_board


def test_noisy_floor_far_away_leaves_no_blobs():
    rng = np.random.default_rng(3)
    frame = make_frame(room(), pose_looking_x(), 0.0, 0)
    z = frame.depth_m.astype(np.float64)
    noisy = (z + rng.normal(0.0, 0.0015, z.shape) * z * z).astype(np.float32)  # σ = 1.5 mm · z²
    bg = [i.box for i in background_instances(room()).values()]
    blobs, _ = segment(noisy, CAMERA, frame.T_map_cam, bg, ForegroundConfig(pixel_step=2))
    assert blobs == []


def test_table_leg_boxes_cover_the_perimeter_under_the_top():
    top = Box3D(np.array([2.0, 1.0, 0.73]), np.array([1.6, 0.8, 0.04]))
    legs = table_leg_boxes(top, 0.12)
    assert len(legs) == 4

    def inside(p):
        return any(np.all(np.abs(np.asarray(p) - b.center_m) <= b.extent_m / 2 + 1e-9) for b in legs)

    assert inside([1.25, 0.65, 0.3])  # a leg at a corner
    assert inside([2.0, 1.35, 0.05])  # under a long edge
    assert not inside([2.0, 1.0, 0.3])  # a chair pushed under the middle
    assert not inside([2.0, 1.5, 0.3])  # a chair beside the table
    assert not inside([1.25, 0.65, 0.8])  # above the top
    assert table_leg_boxes(top, 0.0) == []


def test_a_leg_beside_a_chair_is_trimmed_to_the_chair_detection(monkeypatch):
    pole = SceneBox(12, np.array([3.0, 0.4, 0.4]), np.array([0.05, 0.05, 0.8]), "leg")  # 0.13 m away
    boxes = [*room(), chair(11, 3.0, 0.0), pole]
    # Samples only: a block mean where a foot meets the floor may keep one floor sample.
    cfg = patched(monkeypatch, pixel_step=2, background_block_mean=False)
    frame, (blob,) = _segment(boxes, cfg)
    ids = frame.extras["ids"]
    assert np.any(ids[blob.pixels_uv[:, 1], blob.pixels_uv[:, 0]] == 12)  # one cluster with the leg
    ys, xs = np.nonzero(ids == 11)
    chair_box = [[xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]]
    (trimmed,) = _refine([blob], chair_box, cfg)
    assert not np.any(ids[trimmed.pixels_uv[:, 1], trimmed.pixels_uv[:, 0]] == 12)
    assert len(trimmed.points_cam) == int(np.sum(ids[blob.pixels_uv[:, 1], blob.pixels_uv[:, 0]] == 11))
    with constants(trim_iou=1.0):  # off
        (kept,) = _refine([blob], chair_box, cfg)
    assert len(kept.points_cam) == len(blob.points_cam)


def test_a_detection_box_jittered_smaller_does_not_cut_the_head_off(monkeypatch):
    boxes = [*room(), person(10, 3.0, 0.0)]
    cfg = ForegroundConfig(pixel_step=2)
    frame, (blob,) = _segment(boxes, cfg)
    x0, y0, x1, y1 = frame.detections.xyxy[0]
    short = [[x0, y0 + 0.05 * (y1 - y0), x1, y1]]  # the top edge 5 % of the height too low
    (kept,) = _refine([blob], short, cfg)
    assert len(kept.points_cam) == len(blob.points_cam)
    (cut,) = _refine([blob], short, patched(monkeypatch, pixel_step=2, trim_margin_frac=0.0))
    assert len(cut.points_cam) < len(blob.points_cam)
    assert kept.points_map[:, 2].max() - cut.points_map[:, 2].max() > 0.05


def test_a_pole_behind_the_chair_just_outside_its_box_is_trimmed(monkeypatch):
    # beside the chair, 0.35 m behind it
    pole = SceneBox(12, np.array([3.6, 0.45, 0.4]), np.array([0.05, 0.05, 0.8]), "leg")
    boxes = [*room(), chair(11, 3.0, 0.0), pole]
    cfg = ForegroundConfig(pixel_step=2, cluster_tolerance_m=0.8)  # one cluster with the pole
    frame, (blob,) = _segment(boxes, cfg)
    ids = frame.extras["ids"]
    assert np.any(ids[blob.pixels_uv[:, 1], blob.pixels_uv[:, 0]] == 12)
    ys, xs = np.nonzero(ids == 11)
    (trimmed,) = _refine([blob], [[xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]], cfg)
    assert not np.any(ids[trimmed.pixels_uv[:, 1], trimmed.pixels_uv[:, 0]] == 12)
    # without the depth test the grown box would keep it
    (kept,) = _refine([blob], [[xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]],
                      patched(monkeypatch, pixel_step=2, cluster_tolerance_m=0.8, trim_depth_m=1.0))
    assert np.any(ids[kept.pixels_uv[:, 1], kept.pixels_uv[:, 0]] == 12)


def _synthetic_blob(depths_m, u0, v0):
    """A blob of points at these depths, one pixel column per point starting at (u0, v0)."""
    z = np.asarray(depths_m, dtype=np.float64)
    uv = np.stack([np.full(len(z), u0), v0 + 2 * np.arange(len(z))], axis=1).astype(np.int32)
    x = (uv[:, 0] - CAMERA.cx) * z / CAMERA.fx
    pts = np.stack([x, (uv[:, 1] - CAMERA.cy) * z / CAMERA.fy, z], axis=1)
    box = np.array([uv[:, 0].min() - 1.0, uv[:, 1].min() - 1.0, uv[:, 0].max() + 1.0, uv[:, 1].max() + 1.0])
    return Blob(pts, pts.copy(), uv, box)


def test_a_chair_back_leg_deeper_than_the_chair_median_joins_it(monkeypatch):
    cfg = patched(monkeypatch, pixel_step=2, trim_iou=1.0)
    front = _synthetic_blob(np.linspace(2.5, 2.9, 30), 80, 20)  # seat and back: 2.5-2.9 m deep
    leg = _synthetic_blob(np.full(20, 3.0), 81, 80)  # a back leg 0.4 m behind the front's median
    box = [[70.0, 10.0, 95.0, 125.0]]
    (joined,) = _refine([front, leg], box, cfg)
    assert len(joined.points_cam) == 50
    far = _synthetic_blob(np.full(20, 3.3), 81, 80)  # 0.4 m behind the deepest point: apart
    assert len(_refine([front, far], box, patched(monkeypatch, pixel_step=2, join_gap_m=1.0))) == 2


def _flat_blob(x0, y0, x1, y1, depth_m, step=4):
    us, vs = np.meshgrid(np.arange(x0 + 2, x1, step), np.arange(y0 + 2, y1, step))
    uv = np.stack([us.ravel(), vs.ravel()], axis=1).astype(np.int32)
    z = np.full(len(uv), depth_m)
    cam = np.stack([(uv[:, 0] - 320.0) * z / 525.0, (uv[:, 1] - 240.0) * z / 525.0, z], axis=1)
    return Blob(cam, cam.copy(), uv, image_box(uv, step, 640, 480))


def test_a_piece_that_makes_the_blob_fit_its_detection_worse_is_not_joined():
    chair = _flat_blob(424, 244, 560, 444, 2.5)
    table_piece = _flat_blob(410, 232, 488, 280, 2.6)  # inside the grown box, beside the chair
    detection = [[425.0, 252.0, 567.0, 451.0]]
    cfg = ForegroundConfig()
    kept = refine_blobs([chair, table_piece], np.asarray(detection), cfg, 640, 480)
    sizes = sorted([len(table_piece.points_cam), len(chair.points_cam)])
    assert sorted(len(b.points_cam) for b in kept) == sizes
    with constants(join_max_iou_loss=1.0):
        (joined,) = refine_blobs([chair, table_piece], np.asarray(detection), cfg, 640, 480)
    assert len(joined.points_cam) == len(chair.points_cam) + len(table_piece.points_cam)


def test_two_chairs_side_by_side_in_one_blob_come_apart_by_their_boxes():
    """Office 42: two meeting-room chairs 0.26 m apart at 4-5 m made one blob (the clustering
    tolerance grows with depth) and then one chair instance."""
    boxes = [*room(), chair(11, 4.0, 0.0), chair(12, 4.0, 0.55)]
    cfg = ForegroundConfig(pixel_step=2, cluster_tolerance_m=0.2)
    frame, blobs = _segment(boxes, cfg)
    assert len(blobs) == 1  # the clustering joined them
    ids = frame.extras["ids"]
    dets = frame.detections
    names = list(dets.class_names)

    def refined(cfg, xyxy, classes):
        return refine_blobs(blobs, xyxy, cfg, CAMERA.width, CAMERA.height, classes=classes)

    split = refined(cfg, dets.xyxy, names)
    owners = sorted(int(np.bincount(ids[b.pixels_uv[:, 1], b.pixels_uv[:, 0]]).argmax()) for b in split)
    assert owners == [11, 12]
    with constants(split_twins=False):
        assert len(refined(cfg, dets.xyxy, names)) == 1
    assert len(refined(cfg, dets.xyxy, ["person", "chair"])) == 1  # a person and a chair: no twins


def _one_blob(*parts):
    uv = np.concatenate([p.pixels_uv for p in parts])
    cam = np.concatenate([p.points_cam for p in parts])
    return Blob(cam, cam.copy(), uv, image_box(uv, 4, 640, 480))


def test_two_chairs_one_behind_the_other_come_apart_and_one_chairs_two_boxes_do_not():
    """Office 45: two chairs at a table's far end, seen along the row, made one blob whose
    boxes overlapped by 0.6 (the nearer hides most of the farther): one chair instance."""
    near = _flat_blob(100, 200, 160, 400, 3.9)
    far = _flat_blob(160, 190, 185, 380, 4.6)  # the part of the farther chair the nearer leaves
    boxes = np.array([[100.0, 200.0, 160.0, 400.0], [115.0, 190.0, 185.0, 380.0]])  # 0.61 shared
    cfg = ForegroundConfig()

    def split(blob, cfg):
        return refine_blobs([blob], boxes, cfg, 640, 480, classes=["chair", "chair"])

    parts = split(_one_blob(near, far), cfg)
    assert sorted(len(b.points_cam) for b in parts) == sorted([len(near.points_cam), len(far.points_cam)])
    with constants(twin_depth_gap_m=0.0):
        assert len(split(_one_blob(near, far), cfg)) == 1
    back = _flat_blob(160, 190, 185, 380, 4.2)  # 0.3 m behind: a chair's back, its second box
    assert len(split(_one_blob(near, back), cfg)) == 1


def test_a_cup_beside_a_bottle_in_one_blob_are_two_things():
    """Small things side by side are twins whatever their classes (hospital 73: a cup 0.23 m
    from a bottle was one blob, named bottle); a person beside a chair stays one blob."""
    bottle = _flat_blob(300, 200, 320, 260, 2.0)
    cup = _flat_blob(328, 236, 348, 260, 2.0)
    boxes = np.array([[300.0, 200.0, 320.0, 260.0], [328.0, 236.0, 348.0, 260.0]])
    cfg = ForegroundConfig()

    def split(classes):
        return refine_blobs([_one_blob(bottle, cup)], boxes, cfg, 640, 480, classes=classes)

    parts = split(["bottle", "cup"])
    assert sorted(len(b.points_cam) for b in parts) == sorted([len(bottle.points_cam), len(cup.points_cam)])
    assert len(split(["person", "chair"])) == 1
