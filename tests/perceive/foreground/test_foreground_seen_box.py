"""A static object's box is the union of the blobs it was seen as (``seen_box.py``), robust to a
few stray blobs; a moved object is told from one seen from different sides; a chair's back above
a table and its seat below stay one chair, two cups side by side stay two."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.moving import is_dynamic
from hiper_cli.perceive.foreground.seen_box import SeenBox
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker, object_box

RATE_HZ = 15.0


def _add(box, lower, upper, times=1):
    for _ in range(times):
        box.add(np.asarray(lower, float), np.asarray(upper, float))


def test_the_union_of_partial_views_is_the_whole_bed():
    box = SeenBox()
    _add(box, [0.0, 0.0, 0.0], [1.0, 1.4, 0.5], times=20)  # the near half, from one side
    _add(box, [0.9, 0.0, 0.0], [2.0, 1.4, 0.5], times=20)  # the far half, from the other
    centre, extent = box.box()
    assert np.allclose(centre, [1.0, 0.7, 0.25], atol=0.06)
    assert np.allclose(extent, [2.0, 1.4, 0.5], atol=0.12)


def test_a_few_stray_blobs_do_not_stretch_the_box():
    box = SeenBox()
    _add(box, [0.0, 0.0, 0.0], [0.5, 0.5, 0.9], times=45)
    _add(box, [-1.0, 0.0, 0.0], [0.5, 0.5, 2.0], times=5)  # a wrong association, an edge's noise
    lower, upper = box.corners()
    assert np.allclose(lower, [0.0, 0.0, 0.0]) and np.allclose(upper, [0.5, 0.5, 0.9])


def test_a_cart_that_drove_moved_a_chair_seen_from_two_sides_did_not():
    chair = SeenBox()
    _add(chair, [0.0, 0.0, 0.0], [0.3, 0.5, 0.9], times=20)
    _add(chair, [0.2, 0.0, 0.0], [0.5, 0.5, 0.9], times=20)
    assert not chair.moved()
    cart = SeenBox()
    for k in range(40):
        x = 0.05 * k
        _add(cart, [x, 0.0, 0.0], [x + 0.6, 0.4, 0.8])
    assert cart.moved()
    assert not SeenBox().moved() and SeenBox().box() is None


def _static_run(frames):
    """Feed ``frames`` (lists of (lower, upper, class)) at RATE_HZ; return the tracker."""
    tracker = Tracker(TrackerConfig())
    t_s, k = 0.0, 0
    for blobs in frames:
        measurements = []
        for lower, upper, cls in blobs:
            lower, upper = np.asarray(lower, float), np.asarray(upper, float)
            k += 1
            measurements.append(Measurement((lower + upper) / 2, upper - lower, cls, 0.9, f"o{k}",
                                            bounds_map_m=(lower, upper)))
        tracker.step(t_s, measurements)
        t_s += 1.0 / RATE_HZ
    return tracker


def test_a_chairs_back_over_a_table_and_its_seat_under_it_are_one_chair():
    back = ([1.0, 1.0, 0.76], [1.45, 1.12, 1.0], "chair")   # above the table top at 0.75 m
    seat = ([1.0, 0.95, 0.0], [1.45, 1.45, 0.5], "chair")   # seen under it, once the robot is close
    tracker = _static_run([[back]] * 30 + [[]] * 75 + [[seat]] * 30)
    alive = tracker.tracks + tracker.dormant
    assert len({t.uuid for t in alive}) == 1
    centre, extent = object_box(alive[0], tracker.config)
    assert extent[2] > 0.8 and abs(centre[2] - 0.5) < 0.1


def test_two_cups_side_by_side_stay_two():
    left = ([0.0, 0.0, 0.75], [0.08, 0.08, 0.85], "cup")
    right = ([0.19, 0.0, 0.75], [0.27, 0.08, 0.85], "cup")
    tracker = _static_run([[left]] * 30 + [[]] * 75 + [[right]] * 30)
    assert len({t.uuid for t in tracker.tracks + tracker.dormant}) == 2


def test_a_blob_that_grew_went_nowhere_a_walker_went_its_way():
    grew, walked = SeenBox(), SeenBox()
    for k in range(40):
        _add(grew, [0.0, 0.0, 1.0], [0.1 + 0.025 * k, 0.3, 1.3])  # more of a shelf came into view
        _add(walked, [0.03 * k, 0.0, 0.0], [0.03 * k + 0.4, 0.3, 1.7])
    assert grew.shift_m() == 0.0
    assert walked.shift_m() == pytest.approx(0.9, abs=0.01)  # the quarters' medians, 30 blobs apart


def test_an_unknown_that_walked_is_dynamic_one_that_moved_in_spells_is_not():
    def state(xs):
        tracker = _static_run([[([x, 0.0, 0.0], [x + 0.4, 0.3, 1.7], "unknown")] for x in xs])
        (track,) = tracker.tracks
        return is_dynamic(track, tracker.config)

    assert state([0.05 * k for k in range(60)])  # 0.75 m/s for 4 s
    # a blob that shifts for 0.67 s at a time, three times, as the camera passes what it is
    spells = [0.0] * 20
    for _ in range(3):
        spells += [spells[-1] + 0.06 * (i + 1) for i in range(10)] + [spells[-1] + 0.6] * 20
    assert not state(spells)


def test_a_cup_whose_blob_slid_a_hand_width_is_static():
    xs = [0.0] * 12 + [0.021 * (i + 1) for i in range(10)] + [0.21] * 12
    tracker = _static_run([[([x, 0.0, 0.8], [x + 0.08, 0.08, 0.9], "cup")] for x in xs])
    (track,) = tracker.tracks
    assert track.seen.moved()  # its boxes left where they were ...
    assert not is_dynamic(track, tracker.config)  # ... by 0.21 m: not a cup that went somewhere


def test_the_top_of_a_class_is_that_of_the_blobs_views_named_it():
    box = SeenBox()
    for _ in range(20):
        box.add(np.array([0.8, 0.1, 0.0]), np.array([2.0, 0.8, 0.76]), True, class_name="table")
    for _ in range(10):  # the bottles on it, named before the top was found
        box.add(np.array([1.1, 0.4, 0.0]), np.array([1.5, 0.7, 1.01]), True, class_name="bottle")
    assert box.corners()[1][2] > 1.0  # the union reaches the bottles' tops
    assert abs(box.top_of("table") - 0.76) < 1e-9
    assert box.top_of("chair") is None


def test_a_table_with_bottles_named_on_it_is_the_table_the_background_mapped():
    """Office 62: a desk's blob was named ``bottle`` in 12 views, then found a table by its top;
    its box reached the bottles' tops (1.01 m) and it stayed beside the mapped top at 0.76 m."""
    from hiper_cli.model import Box3D
    from hiper_cli.perceive.foreground.unmapped_tables import withdraw_mapped

    with_bottles = ([0.8, 0.1, 0.0], [2.0, 0.8, 1.01], "bottle")
    table = ([0.8, 0.1, 0.0], [1.95, 0.8, 0.77], "table")
    tracker = _static_run([[with_bottles]] * 12 + [[table]] * 20)
    (track,) = tracker.tracks
    assert track.class_name == "table" and track.seen.corners()[1][2] > 1.0
    mapped = Box3D(np.array([1.86, 0.41, 0.76]), np.array([1.09, 0.8, 0.02]))
    assert withdraw_mapped(tracker, [mapped], 0.1) == [track.uuid]
    assert tracker.tracks == []


def test_a_walker_named_in_a_few_frames_only_went_its_way():
    """Degraded bookstore: a person named in 11 of the 25 frames of a walk (blur, JPEG), then
    followed as unnamed blobs of a person's size. The named blobs alone straddle the turn at
    the walk's end and went nowhere; all of its blobs went 1.4 m: a walker who walked, whose
    stored speed is its pace, not a static person at speed 0."""
    xs = [0.04 * k for k in range(6)] + [0.2 - 0.04 * k for k in range(1, 45)]  # 0.6 m/s, one turn
    names = ["person"] * 11 + ["unknown"] * (len(xs) - 11)
    frames = [[([x, 0.0, 0.0], [x + 0.4, 0.3, 1.7], name)] for x, name in zip(xs, names, strict=True)]
    tracker = _static_run(frames)
    (track,) = tracker.tracks
    assert track.class_name == "person"
    assert track.seen.shift_m() < 0.5 < track.seen.shift_m(every_blob=True)
    assert is_dynamic(track, tracker.config)


def _readings(box):
    """Everything a track reads from its seen box, as plain values."""
    found = box.corners()
    view = box.viewpoint()
    return (None if found is None else (found[0].tolist(), found[1].tolist()),
            None if view is None else view.tolist(), box.top_seen(), box.bottom_seen(), box.moved(),
            box.shift_m(), box.shift_m(every_blob=True))


def test_the_kept_arrays_read_as_the_lists_do_while_blobs_come_and_go():
    """``SeenBox`` keeps its per-blob lists as arrays between reads (grown, reset on a trim):
    after every blob, past two trims, a reused box reads exactly as one built afresh from its lists."""
    from hiper_cli.perceive.foreground import seen_box

    rng = np.random.default_rng(3)
    box = SeenBox()
    for k in range(2 * seen_box.MAX_SEEN_BOXES + 300):
        lower = rng.normal(0.0, 0.05, 3) + (0.5 if k > 900 else 0.0)
        view = None if k % 7 == 0 else rng.normal(0.0, 1.0, 3)
        box.add(lower, lower + 1.0, named=k % 3 == 0, viewpoint_m=view, top_hidden=k % 4 == 0,
                bottom_hidden=k % 5 == 0, class_name="chair")
        if k % 37 and k not in (1, 2, 1200, 1201):
            continue
        fresh = SeenBox(box.lower_m, box.upper_m, box.named, box.viewpoints_m, box.tops_hidden,
                        box.bottoms_hidden, box.classes)
        assert _readings(box) == _readings(fresh)
    assert len(box.lower_m) < 2 * seen_box.MAX_SEEN_BOXES  # trimmed on the way
    with pytest.raises(ValueError):
        box._array("lower_m")[0, 0] = 1.0  # shared between reads: read only
