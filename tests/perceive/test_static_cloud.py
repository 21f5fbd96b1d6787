"""The place's cloud keeps what stands still: a person who walked through, or a flying pixel in
mid-air, seen through from another view, does not stay in it (a later addition there would be
refused as "something stood there"); a wall seen from one view, or at an edge, stays."""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.static_cloud import StaticCloud
from hiper_cli.session_align import MapCloudGrower
from hiper_cli.types import CameraIntrinsics, Frame

W, H = 120, 90
CAMERA = CameraIntrinsics(width=W, height=H, fx=100.0, fy=100.0, cx=W / 2, cy=H / 2)


def _frame(depth_m: np.ndarray, stamp_s: float, x_m: float = 0.0) -> Frame:
    """A camera looking along +z of the map from (x_m, 0, 0)."""
    T = np.eye(4)
    T[0, 3] = x_m
    return Frame(stamp_s=stamp_s, rgb=np.zeros((H, W, 3), np.uint8), depth_m=depth_m.astype(np.float32),
                 camera=CAMERA, T_map_cam=T, pose_id=int(stamp_s))


def _wall(z_m: float = 3.0) -> np.ndarray:
    return np.full((H, W), z_m)


def _inside(points: np.ndarray, lo, hi) -> int:
    return int(np.all((points >= lo) & (points <= hi), axis=1).sum())


PERSON = (slice(30, 60), slice(50, 70))  # pixels a person 1.5 m away covers in the first view
PERSON_LO, PERSON_HI = (-0.4, -0.4, 1.3), (0.4, 0.4, 1.7)


def test_a_person_seen_through_later_leaves_the_cloud_and_the_wall_stays():
    with_person = _wall()
    with_person[PERSON] = 1.5
    cloud = StaticCloud()
    cloud.add_frame(_frame(with_person, 0.0))
    cloud.add_frame(_frame(_wall(), 1.0))  # the person has gone: the wall behind them is seen
    points = cloud.points()
    assert _inside(points, PERSON_LO, PERSON_HI) == 0
    alone = StaticCloud()
    alone.add_frame(_frame(_wall(), 0.0))
    wall = points[np.abs(points[:, 2] - 3.0) < 0.1]
    assert len(wall) >= 0.95 * len(alone.points())


def test_a_person_never_seen_through_stays():
    """Nothing says the space was free: what stood there stays (a chair, or a person who stood
    there all the time the robot looked)."""
    with_person = _wall()
    with_person[PERSON] = 1.5
    cloud = StaticCloud()
    cloud.add_frame(_frame(with_person, 0.0))
    cloud.add_frame(_frame(with_person, 1.0))
    assert _inside(cloud.points(), PERSON_LO, PERSON_HI) > 0


def test_a_flying_pixel_in_mid_air_is_seen_through_from_the_next_view():
    flying = _wall()
    flying[44:46, 59:61] = 2.0  # a return between an edge and the wall behind it, in one view only
    cloud = StaticCloud()
    cloud.add_frame(_frame(flying, 0.0))
    cloud.add_frame(_frame(_wall(), 1.0, x_m=0.2))
    assert _inside(cloud.points(), (-0.3, -0.3, 1.8), (0.3, 0.3, 2.2)) == 0


def test_an_edge_seen_beside_the_wall_behind_it_stays():
    """A box's side seen edge-on: the blocks at its edge mix it and the wall; they measure the
    nearest return, so the edge is not carved by the wall seen beside it."""
    box = _wall()
    box[:, 60:] = 1.5  # a cupboard's front fills the right half of the view
    cloud = StaticCloud()
    cloud.add_frame(_frame(box, 0.0))
    cloud.add_frame(_frame(box, 1.0, x_m=0.03))
    front = cloud.points()
    front = front[np.abs(front[:, 2] - 1.5) < 0.1]
    assert front[:, 0].min() < 0.05  # the voxels at the edge (x = 0) stay


def test_the_earlier_sessions_points_stay_unless_this_session_saw_through_them_twice():
    """A chair an earlier session stored 1.5 m in front of the wall: seen through from one
    view (a stray ray, noise), it stays; from two, it was moved or taken away and leaves the
    cloud, so the next session finds its space free; seen there again, it stays."""
    earlier = np.array([[0.0, 0.0, 1.5], [0.1, 0.0, 1.5]])
    once = StaticCloud(earlier)
    once.add_frame(_frame(_wall(), 0.0))
    assert _inside(once.points(), PERSON_LO, PERSON_HI) == 2
    twice = StaticCloud(earlier)
    twice.add_frame(_frame(_wall(), 0.0))
    twice.add_frame(_frame(_wall(), 1.0))
    assert _inside(twice.points(), PERSON_LO, PERSON_HI) == 0
    assert len(twice.points()) > 100  # the wall this session saw is added
    chair = _wall()
    chair[40:50, 55:70] = 1.5  # the chair still there, seen from both views
    there = StaticCloud(earlier)
    there.add_frame(_frame(chair, 0.0))
    there.add_frame(_frame(chair, 1.0))
    kept = there.points()
    assert _inside(kept, PERSON_LO, PERSON_HI) >= 2
    assert all(np.isclose(kept, p).all(axis=1).any() for p in earlier)  # where they were


class _Place:
    """The two methods of a knowledge base the grower uses."""

    def __init__(self) -> None:
        self.stored: np.ndarray | None = None

    def map_cloud(self, env):
        return self.stored

    def store_map_cloud(self, env, points):
        self.stored = np.asarray(points)
        return len(points)


def test_the_stored_place_holds_no_person_who_walked_through():
    place = _Place()
    grower = MapCloudGrower(place, env=None)  # type: ignore[arg-type]
    with_person = _wall()
    with_person[PERSON] = 1.5
    for k, depth in enumerate([_wall(), with_person, _wall(), _wall()]):
        grower.add(_frame(depth, float(k)))
    grower.store()
    assert place.stored is not None and len(place.stored) > 100
    assert _inside(place.stored, PERSON_LO, PERSON_HI) == 0
