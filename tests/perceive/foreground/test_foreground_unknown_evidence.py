"""Unknown instances need whole evidence (``whole.py``, ``Tracker._evidence_enough``): a blob
no detector named becomes an instance only when seen whole, solid and compact, for a while."""

import numpy as np

from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker
from hiper_cli.perceive.foreground.whole import seen_whole, thickness_m
from hiper_cli.types import CameraIntrinsics
from tests.fg_constants import constants, patched

CAMERA = CameraIntrinsics(width=640, height=480, fx=525.0, fy=525.0, cx=319.5, cy=239.5)
RATE_HZ = 15.0


def _blob(points_cam, box):
    uv = np.zeros((len(points_cam), 2), np.int32)
    return Blob(points_cam, points_cam.copy(), uv, np.asarray(box, float))


def _cube(n=400, size=0.3, depth=2.0, seed=0):
    return np.random.default_rng(seed).uniform(-size / 2, size / 2, (n, 3)) + np.array([0.0, 0.0, depth])


def test_a_cube_in_the_middle_of_the_image_is_whole():
    assert seen_whole(_blob(_cube(), [300, 200, 340, 240]), ForegroundConfig(), CAMERA)


def test_a_blob_at_the_image_border_is_not_whole():
    assert not seen_whole(_blob(_cube(), [0, 200, 40, 240]), ForegroundConfig(), CAMERA)


def test_a_flat_patch_is_not_whole():
    patch = _cube()
    patch[:, 2] = 2.0 + np.random.default_rng(1).normal(0.0, 0.002, len(patch))
    assert thickness_m(patch) < 0.005
    assert not seen_whole(_blob(patch, [300, 200, 340, 240]), ForegroundConfig(), CAMERA)


def test_a_large_blob_is_not_whole():
    assert not seen_whole(_blob(_cube(size=1.5), [200, 100, 440, 380]), ForegroundConfig(), CAMERA)


def _standing_cube(camera_up_m=0.5, ahead_m=4.0, size=0.3, seed=0):
    """A cube on the floor ``ahead_m`` in front of a level camera ``camera_up_m`` high: its
    blob, the camera pose (map z up) and the depth image of the floor alone."""
    R = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # camera axes in the map
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, [0.0, 0.0, camera_up_m]
    rng = np.random.default_rng(seed)
    half = size / 2
    pts_map = rng.uniform([ahead_m - half, -half, 0.0], [ahead_m + half, half, size], (600, 3))
    pts_cam = (pts_map - T[:3, 3]) @ R
    uv = np.stack([CAMERA.cx + CAMERA.fx * pts_cam[:, 0] / pts_cam[:, 2],
                   CAMERA.cy + CAMERA.fy * pts_cam[:, 1] / pts_cam[:, 2]], axis=1).astype(np.int32)
    box = np.array([uv[:, 0].min(), uv[:, 1].min(), uv[:, 0].max(), uv[:, 1].max()], float)
    rows = np.arange(480, dtype=np.float64)[:, None] - CAMERA.cy
    floor = np.where(rows > 1.0, camera_up_m * CAMERA.fy / np.maximum(rows, 1.0), 0.0)
    depth = np.repeat(floor, 640, axis=1).astype(np.float32)
    return Blob(pts_cam, pts_map, uv, box), T, depth


def test_a_blob_over_something_nearer_tells_nothing():
    """The top of a box stack seen over a nearer stack does not show where its object stands:
    the view is no evidence either way. The floor in front of an object, nearer at a grazing
    angle, is what it stands on: the view shows it whole."""
    blob, pose, depth = _standing_cube()
    x0, _, x1, y1 = (int(v) for v in blob.image_box_xyxy)
    assert float(np.median(blob.points_cam[:, 2])) - depth[y1 + 6, x0] > 0.15  # the floor is nearer
    assert seen_whole(blob, ForegroundConfig(), CAMERA, (depth, pose)) is True
    depth[y1:, x0 - 10:x1 + 10] = 2.0  # a box 2 m away, reaching above the cube's base
    assert seen_whole(blob, ForegroundConfig(), CAMERA, (depth, pose)) is None  # cannot tell
    assert seen_whole(blob, ForegroundConfig(), CAMERA) is True  # without the view: as before


def _track(config, frames, whole=True, cls="unknown"):
    tracker = Tracker(config)
    confirmed = False
    for k in range(frames):
        score = 0.0 if cls == "unknown" else 0.9
        centre, extent = np.array([1.0, 2.0, 0.5]), np.array([0.3, 0.3, 0.3])
        m = Measurement(centre, extent, cls, score, f"o{k}", whole=whole)
        changed, _ = tracker.step(k / RATE_HZ, [m])
        confirmed |= bool(changed)
    return confirmed


def test_views_that_cannot_tell_count_neither_way():
    """Seen only over something nearer (a box stack's top), a blob is no instance; an object
    seen whole now and then, and otherwise behind a chair, is one."""
    cfg = ForegroundConfig()
    assert not _track(cfg, 30, whole=None)
    tracker, confirmed = Tracker(cfg), False
    for k in range(30):
        m = Measurement(np.array([1.0, 2.0, 0.5]), np.array([0.3, 0.3, 0.3]), "unknown", 0.0, f"o{k}",
                        whole=k % 3 == 0 or None)  # a third whole, the rest behind a chair
        changed, _ = tracker.step(k / RATE_HZ, [m])
        confirmed |= bool(changed)
    assert confirmed
    assert not _track(cfg, 30, whole=False)


def test_an_unknown_track_needs_whole_observations_over_half_a_second():
    cfg = ForegroundConfig()
    assert not _track(cfg, 5)  # 0.27 s: too short
    assert _track(cfg, 10)  # 0.6 s of whole views
    assert not _track(cfg, 30, whole=False)  # always cut by the border: a piece of something


def test_without_the_rule_three_hits_make_an_unknown_instance():
    assert _track(ForegroundConfig(unknown_confirm_whole=0), 5, whole=False)


def test_a_detected_object_keeps_the_usual_evidence():
    assert _track(ForegroundConfig(), 5, whole=False, cls="chair")


# --- the evidence holds for the class an instance carries, all its life (unknown_evidence_held)


def _feed(tracker, views, start=0):
    """One measurement per frame at one place: ``views`` a string of W (unknown, whole),
    B (unknown, cut by the border: not whole), N (named ``bed``) and P (named ``person``).
    Returns the uuids of the instances changed and withdrawn per frame."""
    changed, withdrawn = [], []
    for k, view in enumerate(views, start):
        cls = {"N": "bed", "P": "person"}.get(view, "unknown")
        m = Measurement(np.array([1.0, 2.0, 0.5]), np.array([0.3, 0.3, 0.3]), cls,
                        0.0 if cls == "unknown" else 0.9, f"o{k}", whole=view != "B")
        out, _ = tracker.step(k / RATE_HZ, [m])
        changed.append([t.uuid for t in out])
        withdrawn.append(list(tracker.withdrawn))
    return changed, withdrawn


def test_an_unknown_instance_that_then_takes_pieces_of_structure_is_withdrawn(monkeypatch):
    # seen whole for 0.67 s (an instance), then 15 views cut by the border: 10 of 25 whole
    tracker = Tracker(ForegroundConfig())
    changed, withdrawn = _feed(tracker, "W" * 10 + "B" * 15)
    (uuid,) = {u for c in changed for u in c}
    assert [k for k, w in enumerate(withdrawn) if w] == [20]  # 10 whole of 21: less than half
    assert withdrawn[20] == [uuid]
    assert tracker.close_all() == []
    old = Tracker(patched(monkeypatch, unknown_evidence_held=False))
    _feed(old, "W" * 10 + "B" * 15)
    assert len(old.close_all()) == 1


def test_a_withdrawn_track_seen_whole_again_comes_back():
    tracker = Tracker(ForegroundConfig())
    _feed(tracker, "W" * 10 + "B" * 15 + "W" * 20)  # 30 whole of 45
    (track,) = tracker.close_all()
    assert track.class_name == "unknown" and track.hits == 45


def test_two_detections_do_not_make_an_unknown_instance_of_a_desk(monkeypatch):
    # a desk named `bed` twice (confirmed on its third view, most of them named), then cut by
    # the border: the class never comes and it is never seen whole
    tracker = Tracker(ForegroundConfig())
    changed, withdrawn = _feed(tracker, "NNB" + "B" * 40)
    assert changed[2] and not any(changed[4:])
    assert withdrawn[3] == changed[2]
    assert tracker.close_all() == []
    old = Tracker(patched(monkeypatch, unknown_evidence_held=False))
    _feed(old, "NNB" + "B" * 40)
    assert [t.class_name for t in old.close_all()] == ["unknown"]


def test_a_blip_named_in_two_frames_is_no_instance_when_it_ends(monkeypatch):
    tracker = Tracker(ForegroundConfig())
    changed, _ = _feed(tracker, "NNB")
    assert changed[2]  # confirmed while it lives: a class may still come
    closed = []
    for k in range(3, 40):  # unseen for 2.5 s: closed, and withdrawn
        tracker.step(k / RATE_HZ, [])
        closed += tracker.withdrawn
    assert closed == changed[2]
    old = Tracker(patched(monkeypatch, unknown_evidence_held=False))
    _feed(old, "NNB")
    assert [t.class_name for t in old.close_all()] == ["unknown"]


def test_a_person_is_still_confirmed_on_its_third_named_view():
    tracker = Tracker(ForegroundConfig())
    changed, withdrawn = _feed(tracker, "PPP" + "P" * 10)
    assert not changed[1] and changed[2]
    assert not any(withdrawn)
    (track,) = tracker.close_all()
    assert track.class_name == "person"


def test_the_stage_deletes_the_instance_of_a_withdrawn_track():
    """A box no detector names, seen whole for 20 frames, then cut by the image's left border
    for 30 (the camera moved aside): its track's instance goes from the world and the knowledge
    base. The box stood there in every view, so the map of solid surfaces (``solid_map.py``)
    keeps it as a geometry-only ``unknown`` at the end; kept by its track, it is that one."""
    from hiper_cli.perceive.foreground import ForegroundStage
    from hiper_cli.perceive.runner import run_stages
    from hiper_cli.perceive.stage import World
    from hiper_cli.types import Detections, Frame
    from tests.fg_scene import CAMERA as SCENE_CAMERA
    from tests.fg_scene import SceneBox, background_instances, pose_looking_x, render, room

    thing = SceneBox(20, np.array([3.0, 0.0, 0.3]), np.array([0.3, 0.3, 0.3]), "other")
    frames = []
    for k in range(50):
        T = pose_looking_x(y=0.0 if k < 20 else -2.4)  # then the box lies across the left border
        depth, _ = render([*room(), thing], T)
        rgb = np.zeros((SCENE_CAMERA.height, SCENE_CAMERA.width, 3), np.uint8)
        frames.append(Frame(k / 30.0, rgb, depth, SCENE_CAMERA, T, k, detections=Detections.from_records([])))
    deleted = []

    def on_frame(frame, result):
        deleted.extend(result.deleted_instances)

    for held, expected in ((True, 0), (False, 1)):
        deleted.clear()
        with constants(unknown_evidence_held=held):
            stage = ForegroundStage(detector="log", pixel_step=2)
            world, _ = run_stages(frames, [stage], World(background=background_instances(room())), on_frame)
        tracked = [i for i in world.foreground.values() if not i.data.get("geometry_only")]
        geometry = [i for i in world.foreground.values() if i.data.get("geometry_only")]
        assert len(tracked) == expected
        assert len(deleted) == 1 - expected
        assert len(geometry) == 1 - expected
        for inst in geometry:
            assert inst.class_name == "unknown" and np.linalg.norm(inst.box.center_m[:2] - [3.0, 0.0]) < 0.2


def test_a_stitched_track_keeps_the_whole_views_of_both_in_time_order():
    from hiper_cli.perceive.foreground.stitch import DUPLICATE, REVISIT, absorb

    for kind in (DUPLICATE, REVISIT):
        old, new = Tracker(ForegroundConfig()), Tracker(ForegroundConfig())
        _feed(old, "W" * 4)
        _feed(new, "WBW", start=2)
        a, b = old.tracks[0], new.tracks[0]
        absorb(a, b, kind)
        assert a.hits == 7
        assert a.whole_stamps_s == sorted(a.whole_stamps_s) and len(a.whole_stamps_s) == 6
