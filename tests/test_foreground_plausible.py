"""A detector's class must fit the 3D object it names (``plausible.py``): common-sense sizes,
plumbing fixtures against a wall or in a counter, and what people carry is part of them
(``carried.py``)."""

import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.carried import drop_carried
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.plausible import attached, longest_m, max_longest_m, min_longest_m
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker, object_box
from hiper_cli.perceive.stage import World
from hiper_cli.types import Detections, Frame
from tests.fg_scene import SceneBox, background_instances, make_frame, person, pose_looking_x, room

RATE_HZ = 15.0


def _top_points(size_x, size_y, height, yaw_rad=0.0, n=400):
    rng = np.random.default_rng(0)
    local = rng.uniform([-size_x / 2, -size_y / 2, 0.0], [size_x / 2, size_y / 2, height], (n, 3))
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return local @ R.T


def test_the_longest_dimension_does_not_depend_on_how_the_object_is_turned():
    square = _top_points(0.86, 0.86, 0.5, yaw_rad=np.pi / 4)  # axis-aligned box: 1.2 m
    assert longest_m(square, 0.5) == pytest.approx(0.86, abs=0.03)
    assert longest_m(_top_points(0.3, 0.3, 1.0), 1.0) == pytest.approx(1.0)  # taller than wide
    assert longest_m(_top_points(2.0, 0.9, 0.6, yaw_rad=0.3), 0.6) == pytest.approx(2.0, abs=0.05)


def test_bounds_with_their_tolerance():
    assert max_longest_m("cup", 0.2) == pytest.approx(0.3)
    assert min_longest_m("bed", 0.0) >= 1.2  # the shortest beds are cribs
    assert min_longest_m("cup", 0.2) == 0.0 and max_longest_m("no such class", 0.2) == np.inf


def _track(longest, cls="bed", n=8, **options):
    tracker = Tracker(TrackerConfig(**options))
    for k in range(n):
        m = Measurement(np.array([3.0, 0.0, 0.5]), np.array([0.85, 0.85, 1.0]), cls, 0.5, f"o{k}",
                        longest_m=longest)
        tracker.step(k / RATE_HZ, [m])
    return tracker.tracks[0]


def test_a_track_seen_whole_shorter_than_any_bed_is_no_bed():
    assert _track(1.0).class_name == "unknown"  # a 1 m book display, seen inside the image
    assert _track(None).class_name == "bed"  # cut by the image's border: a part of a bed
    assert _track(2.0).class_name == "bed"
    assert _track(1.0, class_sizes=False).class_name == "bed"
    assert _track(0.3, cls="cup").class_name == "cup"  # small classes have no lower bound


def test_one_whole_view_of_the_full_length_is_enough():
    tracker = Tracker(TrackerConfig())
    for k in range(8):
        longest = 2.0 if k == 5 else 1.0  # partly hidden in all views but one
        m = Measurement(np.array([3.0, 0.0, 0.5]), np.array([1.0, 0.9, 0.6]), "bed", 0.5, f"o{k}",
                        longest_m=longest)
        tracker.step(k / RATE_HZ, [m])
    assert tracker.tracks[0].class_name == "bed"


def test_a_track_named_a_static_class_does_not_search_when_its_class_is_turned_down():
    """A book display taken for a bed, whose blob slid while the robot turned: ``unknown`` for
    its size, but no walker; lost, it does not widen its gate to take other objects, and its
    box is the union of its blobs."""
    config = TrackerConfig()
    tracker = Tracker(config)
    for k in range(12):
        centre = np.array([3.0 + 0.05 * k, 0.0, 0.5])  # the blob's centre slides with the view
        m = Measurement(centre, np.array([0.85, 0.85, 1.0]), "bed", 0.5, f"o{k}", longest_m=1.0)
        tracker.step(k / RATE_HZ, [m])
    track = tracker.tracks[0]
    assert track.class_name == "unknown" and track.search_class == "bed"
    base, gate = tracker._gate(track, 12 / RATE_HZ + 3.0)
    assert gate == base
    centre, _ = object_box(track, config)  # where its blobs were, not where the last one slid to
    assert centre[0] == pytest.approx(3.0 + 0.05 * 11 / 2, abs=0.02)
    unnamed = Tracker(config)  # the same blobs never named: may be a person not named yet
    for k in range(12):
        centre = np.array([3.0 + 0.05 * k, 0.0, 0.5])
        unnamed.step(k / RATE_HZ, [Measurement(centre, np.array([0.85, 0.85, 1.0]), "unknown", 0.0, f"o{k}")])
    base, gate = unnamed._gate(unnamed.tracks[0], 12 / RATE_HZ + 3.0)
    assert gate > base


def _cup_scene(height_m):
    """A box 0.12 m wide named ``cup`` by a detection, 1.5 m in front of the camera."""
    box = SceneBox(20, np.array([1.5, 0.0, 0.8]), np.array([0.12, 0.12, height_m]), "cup")
    frame = make_frame([*room(), box], pose_looking_x(), 0.0, 0)
    return frame, World(background=background_instances(room()))


@pytest.mark.parametrize(("height_m", "expected"), [(0.2, "cup"), (0.6, "unknown")])
def test_a_blob_longer_than_any_cup_is_no_cup(height_m, expected):
    frame, world = _cup_scene(height_m)
    r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
    assert [o.class_name for o in r.observations] == [expected]
    r = ForegroundStage(detector="log", pixel_step=2, class_sizes=False).process(frame, world)
    assert [o.class_name for o in r.observations] == ["cup"]


def test_fixtures_stand_against_a_wall_or_in_a_counter():
    wall = Box3D(np.array([4.0, 0.0, 1.5]), np.array([0.02, 6.0, 3.0]))
    counter = Box3D(np.array([1.0, 2.0, 0.9]), np.array([0.6, 2.0, 0.02]))
    basin = _top_points(0.4, 0.4, 0.2)
    assert attached(basin + np.array([3.75, 0.0, 0.7]), [wall], [], 0.3)  # a pedestal sink
    assert attached(basin + np.array([1.0, 2.3, 0.7]), [wall], [counter], 0.3)  # in the counter
    assert not attached(basin + np.array([2.0, 0.0, 0.5]), [wall], [counter], 0.3)  # a stool in the room
    assert not attached(basin + np.array([1.0, 2.3, 0.1]), [], [counter], 0.3)  # on the floor under it


@pytest.mark.parametrize(("wall", "expected"), [(True, "sink"), (False, "unknown")])
def test_stage_names_a_sink_only_against_a_wall(wall, expected):
    basin = SceneBox(20, np.array([3.0, 0.0, 0.6]), np.array([0.4, 0.4, 0.3]), "sink")
    side = SceneBox(3, np.array([3.0, 0.25, 1.5]), np.array([2.0, 0.1, 3.0]), "wall", True)
    scene = [*room(), side] if wall else room()
    frame = make_frame([*scene, basin], pose_looking_x(), 0.0, 0)
    world = World(background=background_instances(scene))
    r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
    assert [o.class_name for o in r.observations] == [expected]
    r = ForegroundStage(detector="log", pixel_step=2, fixture_classes="").process(frame, world)
    assert [o.class_name for o in r.observations] == ["sink"]


def _dets(*rows):
    return Detections(np.array([r[1] for r in rows], dtype=float), tuple(r[0] for r in rows),
                      np.array([r[2] for r in rows], dtype=float))


def test_a_bag_inside_a_persons_box_is_carried():
    def kept(*rows, min_score=0.0):
        return drop_carried(_dets(*rows), ("handbag",), ("person",), 0.8, min_score).class_names

    walker = ("person", [0, 30, 90, 450], 0.8)
    bag = ("handbag", [0, 100, 80, 220], 0.6)
    assert kept(walker, bag) == ("person",)
    alone = ("handbag", [300, 100, 380, 220], 0.6)  # on a chair, away from the person
    assert kept(walker, alone) == ("person", "handbag")
    chair = ("chair", [0, 300, 80, 440], 0.6)  # behind the person: not a carried class
    assert kept(walker, chair) == ("person", "chair")
    weak = ("person", [0, 30, 90, 450], 0.2)  # a person below the score threshold names nothing
    assert kept(weak, bag, min_score=0.3) == ("person", "handbag")


def test_stage_names_a_walker_with_a_bag_person():
    """The bag's box fits the walker's blob better than the person's (larger, jittered) box:
    without the rule the walker's blob is a ``handbag``."""
    frame = make_frame([*room(), person(10, 3.0, 0.0)], pose_looking_x(), 0.0, 0)
    assert frame.detections is not None
    x0, y0, x1, y1 = frame.detections.xyxy[0]
    grown = [x0 - 3, y0 - 5, x1 + 3, y1 + 5]
    dets = _dets(("person", grown, 0.8), ("handbag", [x0, y0, x1, y1], 0.6))
    frame = Frame(frame.stamp_s, frame.rgb, frame.depth_m, frame.camera, frame.T_map_cam, 0, detections=dets)
    world = World(background=background_instances(room()))
    r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
    assert [o.class_name for o in r.observations] == ["person"]
    r = ForegroundStage(detector="log", pixel_step=2, carried_classes="").process(frame, world)
    assert [o.class_name for o in r.observations] == ["unknown"]  # no 1.7 m handbag either
    no_sizes = ForegroundStage(detector="log", pixel_step=2, carried_classes="", class_sizes=False)
    r = no_sizes.process(frame, world)
    assert [o.class_name for o in r.observations] == ["handbag"]


@pytest.mark.parametrize(("doorway", "expected"), [(False, "unknown"), (True, "bed")])
def test_only_views_of_the_whole_object_show_it_too_short(doorway, expected):
    """A 1 m box named ``bed``, seen whole, is no bed; seen through a doorway (a wall hides half
    of it, the detection boxes the visible part) it may be a bed the camera sees only in part."""
    bed = SceneBox(20, np.array([3.0, 0.0, 0.3]), np.array([0.8, 1.0, 0.6]), "bed")
    jamb = SceneBox(4, np.array([2.0, 0.35, 1.0]), np.array([0.1, 0.7, 2.0]), "wall", True)
    scene = [*room(), jamb] if doorway else room()
    world = World(background=background_instances(scene))
    stage = ForegroundStage(detector="log", pixel_step=2)
    for k in range(6):
        stage.process(make_frame([*scene, bed], pose_looking_x(), k / RATE_HZ, k), world)
    assert [t.class_name for t in stage.tracker.tracks] == [expected]
