"""A detector's class must fit the 3D object it names (``plausible.py``): common-sense sizes,
plumbing fixtures against a wall or in a counter, what people carry is part of them
(``carried.py``), and a class no view of the whole object gave is refused (``class_vote``)."""

import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.carried import drop_carried
from hiper_cli.perceive.foreground.class_vote import shown_class
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.match import named_within
from hiper_cli.perceive.foreground.plausible import attached, longest_m, max_longest_m, min_longest_m
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker, object_box
from hiper_cli.perceive.foreground.whole import in_full_view
from hiper_cli.perceive.stage import World
from hiper_cli.types import CameraIntrinsics, Detections, Frame
from tests.fg_constants import constants
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
    with constants(**options) as fields:
        tracker = Tracker(TrackerConfig(**fields))
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
    with constants(fixture_classes=()):
        r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
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
    with constants(carried_classes=()):
        r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
        assert [o.class_name for o in r.observations] == ["unknown"]  # no 1.7 m handbag either
        no_sizes = ForegroundStage(detector="log", pixel_step=2, class_sizes=False)
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


def _refused_track(full_named: int, full_views: int = 10, within: frozenset[str] = frozenset(),
                   detected: bool = True, whole: bool = True, **options):
    """A track named ``chair`` in 12 views cut by the border (by a detection, or by its shape
    when not ``detected``), then seen in ``full_views`` full views of which the first
    ``full_named`` were named ``chair`` too, and the others held detections of the classes
    ``within`` inside the blob's box."""
    with constants(**options) as fields:
        tracker = Tracker(TrackerConfig(**fields))
        centre, extent = np.array([3.0, 0.0, 0.6]), np.array([0.8, 0.35, 1.2])
        for k in range(12 + full_views):
            full = k >= 12
            named = not full or k - 12 < full_named
            m = Measurement(centre, extent, "chair" if named else "unknown", 0.6 if named else 0.0, f"o{k}",
                            full_view=full, named_within=frozenset() if named else within, whole=whole,
                            detection_index=0 if named and detected else None)
            tracker.step(k / RATE_HZ, [m])
    return tracker.tracks[0]


def test_a_class_named_only_on_cut_views_and_declined_in_full_view_is_refused():
    """A shelf YOLOX calls ``chair`` while the border cuts it, and names nothing whenever all of
    it shows: no chair. One full view named is enough to keep the class; so is too few full
    views to judge."""
    assert _refused_track(0).class_name == "unknown"
    assert _refused_track(0).search_class == "chair"  # it still says what it was taken for
    assert _refused_track(1).class_name == "chair"  # one full view named is enough
    assert _refused_track(0, full_views=7).class_name == "chair"  # too few silent ones to tell
    # ... but one that named another class contradicts it (a walker called refrigerator while
    # cut, person in one of its three full views); none, or one that named the class, does not
    assert _refused_track(0, full_views=1, within=frozenset({"person"})).class_name == "unknown"
    assert _refused_track(0, full_views=3, within=frozenset({"person"})).class_name == "unknown"
    assert _refused_track(0, full_views=1).class_name == "chair"
    assert _refused_track(1, full_views=2, within=frozenset({"person"})).class_name == "chair"
    with constants(contradicted_views=2):
        assert _refused_track(0, full_views=1, within=frozenset({"person"})).class_name == "chair"
    assert _refused_track(0, refused_min_views=0).class_name == "chair"
    # a chair's box inside a blob that took no class (joined with the table beside it) is a
    # view that named the chair; a book's box on the shelf is not
    assert _refused_track(0, within=frozenset({"chair"})).class_name == "chair"
    assert _refused_track(0, within=frozenset({"book"})).class_name == "unknown"
    # a class its shape gave it (a table top found without a detector) is not the detector's to refuse
    assert _refused_track(0, detected=False).class_name == "chair"


def test_a_refused_class_leaves_an_unknown_object_not_nothing():
    """The full views tell what the object is not, not that nothing stands there: the track
    the detections named stays an instance, ``unknown`` (located, not named wrongly)."""
    track = _refused_track(0, whole=False)  # no whole view: only the detections tell it is there
    assert track.class_name == "unknown" and track.confirmed


def _named_in(named: int, views: int, score: float) -> object:
    """A track seen in ``views`` cut views (never whole), ``named`` of them ``refrigerator``
    with ``score``, the others named nothing."""
    tracker = Tracker(TrackerConfig())
    centre, extent = np.array([3.0, 0.0, 1.0]), np.array([0.3, 0.5, 0.7])
    for k in range(views):
        named_now = k % (views // named) == 0 and k // (views // named) < named
        name = "refrigerator" if named_now else "unknown"
        m = Measurement(centre, extent, name, score if named_now else 0.0, f"o{k}", whole=False,
                        detection_index=0 if named_now else None)
        tracker.step(k / RATE_HZ, [m])
    return tracker.tracks[0]


def test_a_class_the_silent_views_outweigh_names_nothing():
    """Office 74: a person's shoulders, cut by the image's border, called ``refrigerator`` in 7
    of 24 views (score 0.51) and nothing in the others: too weak a support to name the
    instance, which stays where the tracker (still taking it for a refrigerator) found it. A
    chair behind a desk named in 6 of 16 views (score 0.41) keeps its name."""
    track = _named_in(7, 24, 0.51)
    assert track.class_counts["refrigerator"] == 7
    assert track.class_name == "refrigerator" and track.confirmed  # the tracker's hypothesis
    assert shown_class(track) == "unknown"
    with constants(support_margin=1.0):
        assert shown_class(_named_in(7, 24, 0.51)) == "refrigerator"  # a bare majority named it
    assert shown_class(_named_in(6, 16, 0.41)) == "refrigerator"


def _named_while(cut: bool, named: int = 6, silent: int = 14, score: float = 0.6) -> object:
    """A track named ``oven`` in ``named`` views (``score``) whose blob the border cut when
    ``cut``, and seen inside the image in ``silent`` views that named nothing."""
    tracker = Tracker(TrackerConfig())
    centre, extent = np.array([3.0, 0.0, 0.5]), np.array([0.8, 0.6, 0.9])
    for k in range(named + silent):
        is_named = k < named
        m = Measurement(centre, extent, "oven" if is_named else "unknown", score if is_named else 0.0,
                        f"o{k}", whole=False, detection_index=0 if is_named else None,
                        cut_by_border=cut and is_named)
        tracker.step(k / RATE_HZ, [m])
    return tracker.tracks[0]


def test_a_view_cut_by_the_border_counts_less():
    """Degraded bookstore: a holder called ``oven`` in 6 of 20 views (score 0.6), every one cut
    by the image's border, and nothing in the views that show it inside the image. A name given
    to a part counts ``CUT_VIEW_WEIGHT``: too weak a support to name the object. The same names
    on views inside the image name it; so do the cut ones when they count in full."""
    cut = _named_while(cut=True)
    assert cut.class_votes["oven"] == pytest.approx(6 * 0.6 * 0.8)
    assert shown_class(cut) == "unknown"
    assert shown_class(_named_while(cut=False)) == "oven"
    with constants(cut_view_weight=1.0):
        assert shown_class(_named_while(cut=True)) == "oven"


def test_a_silent_view_cut_by_the_border_counts_less_too():
    """A view cut by the border shows a part whichever way the detector answers: its silence
    counts ``CUT_VIEW_WEIGHT`` of a silence inside the image."""
    tracker = Tracker(TrackerConfig())
    centre, extent = np.array([3.0, 0.0, 0.5]), np.array([0.4, 0.4, 0.9])
    for k in range(4):
        tracker.step(k / RATE_HZ, [Measurement(centre, extent, "unknown", 0.0, f"o{k}", cut_by_border=k < 2)])
    weight = TrackerConfig().unknown_vote_weight
    assert tracker.tracks[0].class_votes["unknown"] == pytest.approx(2 * weight * 0.8 + 2 * weight)


def test_the_stage_shows_the_supported_class():
    """The instance of a track shows ``shown_class``, not the tracker's working class."""
    stage = ForegroundStage(detector="log")
    track = _named_in(7, 24, 0.51)
    assert stage._instance(track).class_name == "unknown"
    assert stage._instance(_named_in(12, 24, 0.51)).class_name == "refrigerator"


def test_the_classes_of_detections_inside_a_blobs_box():
    dets = _dets(("bottle", [100, 100, 120, 160], 0.7), ("cup", [118, 140, 150, 160], 0.6),
                 ("chair", [90, 50, 300, 400], 0.9), ("book", [105, 105, 110, 110], 0.1))
    within = named_within(np.array([95.0, 95.0, 140.0, 165.0]), dets, min_score=0.3, min_cover=0.5)
    assert within == {"bottle", "cup"}  # the cup's box is 69 % inside; the chair's 5 %; the book too weak
    assert named_within(np.array([95.0, 95.0, 140.0, 165.0]), _dets(), min_score=0.3, min_cover=0.5) == set()


@pytest.mark.parametrize(("options", "expected"), [({}, "unknown"), ({"refused_min_views": 0}, "chair")])
def test_stage_counts_only_views_of_the_whole_blob_against_a_class(options, expected):
    """Named ``chair`` while the camera, 1.6 m to the side, sees the box cut by the image's
    left edge; then, straight in front, the whole box shows and the detector names nothing."""
    shelf = SceneBox(20, np.array([2.0, 0.0, 0.6]), np.array([0.35, 0.8, 1.2]), "chair")
    world = World(background=background_instances(room()))
    stage = ForegroundStage(detector="log", pixel_step=2, **options)
    for k in range(20):
        cut = k < 10
        frame = make_frame([*room(), shelf], pose_looking_x(y=-1.6 if cut else 0.0), k / RATE_HZ, k)
        if not cut:
            frame = Frame(frame.stamp_s, frame.rgb, frame.depth_m, frame.camera, frame.T_map_cam, k,
                          detections=_dets())
        stage.process(frame, world)
    track = stage.tracker.tracks[0]
    assert track.class_counts["chair"] == 10 and track.full_named.get("chair", 0) == 0
    assert track.full_views == (10 if options == {} else 0)  # not looked for when off
    assert track.class_name == expected


def test_a_full_view_shows_all_of_the_object_large_enough_to_name():
    """Inside the image, at least 32 x 32 px, nothing nearer around, above or below it: the back
    of a chair over a counter's top in front is a part, and so is a blob cut by the border."""
    camera = CameraIntrinsics(width=640, height=480, fx=525.0, fy=525.0, cx=319.5, cy=239.5)

    def blob_at(v0, v1, u0, u1):
        v, u = np.mgrid[v0:v1:2, u0:u1:2]
        uv = np.stack([u.ravel(), v.ravel()], axis=1).astype(np.int32)
        points = np.column_stack([np.zeros(len(uv)), np.zeros(len(uv)), np.full(len(uv), 3.5)])
        return Blob(points, points.copy(), uv, np.array([u0 - 1.0, v0 - 1.0, u1 + 1.0, v1 + 1.0]))

    def full(blob, depth):
        return in_full_view(blob, depth, camera, np.eye(4), 2, 1024.0)

    depth = np.zeros((480, 640), np.float32)
    depth[100:200, 300:340] = 3.5
    depth[200:, :] = 3.45  # the floor it stands on
    assert full(blob_at(100, 200, 300, 340), depth)
    assert not full(blob_at(100, 120, 300, 320), depth)  # 22 x 22 px: too small to name
    depth[200:, :] = 2.0  # a counter's front 1.5 m before it hides its lower part
    assert not full(blob_at(100, 200, 300, 340), depth)
    assert not full(blob_at(100, 200, 0, 40), np.zeros((480, 640), np.float32))  # cut by the border
