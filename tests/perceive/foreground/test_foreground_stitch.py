"""Stitching (``stitch.py``): one object stays one instance when the frame-to-frame association
lets it go: a walker picked up again (by position after a short gap, by the colours of the
clothes after a long one), a second blob of a walker, a static object seen again."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground.appearance import HISTOGRAM_BINS, histogram, similarity
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.stitch import RESUME, find_target
from hiper_cli.perceive.foreground.tracking import Measurement, Track, Tracker, object_box
from tests.fg_constants import set_constants

RATE_HZ = 15.0
PERSON = np.array([0.5, 0.4, 1.7])
CHAIR = np.array([0.45, 0.45, 0.9])


def _colours(hot_bin):
    h = np.full(HISTOGRAM_BINS, 0.01)
    h[hot_bin] = 1.0
    return h / h.sum()


class _Run:
    """A tracker fed frame by frame; collects the uuids of the instances it reports."""

    def __init__(self, **config):
        self.tracker = Tracker(TrackerConfig(**config))
        self.seen: set[str] = set()  # uuids of the instances the tracker reported
        self.t_s = 0.0
        self.k = 0

    def frame(self, blobs):
        measurements = []
        for centre, extent, cls, colours in blobs:
            self.k += 1
            measurements.append(Measurement(np.asarray(centre, float), extent, cls, 0.9, f"o{self.k}",
                                            appearance=colours))
        changed, _ = self.tracker.step(self.t_s, measurements)
        self.seen.update(t.uuid for t in changed)
        self.seen -= set(self.tracker.absorbed)
        self.t_s += 1.0 / RATE_HZ

    def idle(self, seconds):
        for _ in range(int(seconds * RATE_HZ)):
            self.frame([])

    def walk(self, start, velocity, seconds, colours=None, cls="person"):
        start, velocity = np.asarray(start, float), np.asarray(velocity, float)
        t0 = self.t_s
        for _ in range(int(seconds * RATE_HZ)):
            self.frame([(start + velocity * (self.t_s - t0), PERSON, cls, colours)])
        return start + velocity * (self.t_s - t0)

    def uuids(self):
        return self.seen


def test_a_walker_picked_up_again_after_a_short_gap_is_one_instance():
    run = _Run()
    end = run.walk([0, 0, 0.85], [0.6, 0, 0], 3.0)
    run.idle(2.0)  # behind a shelf for 2 s: the track closes after max_age_s
    run.walk(end + np.array([1.2, 0, 0.0]), [0.6, 0, 0], 3.0)
    assert len(run.uuids()) == 1
    track = run.tracker.tracks[0]
    assert track.hits == 90
    rows = np.array(track.trajectory)
    assert np.all(np.diff(rows[:, 0]) > 0)


def test_the_switch_and_a_walker_too_far_away_keep_two():
    run = _Run(stitch=False)
    end = run.walk([0, 0, 0.85], [0.6, 0, 0], 3.0)
    run.idle(2.0)
    run.walk(end + np.array([1.2, 0, 0.0]), [0.6, 0, 0], 3.0)
    assert len(run.uuids()) == 2
    run = _Run()
    end = run.walk([0, 0, 0.85], [0.6, 0, 0], 3.0)
    run.idle(2.0)
    run.walk(end + np.array([0, 6.0, 0.0]), [0.6, 0, 0], 3.0)  # 6 m in 2 s (or 3 s from before): no walk
    assert len(run.uuids()) == 2


@pytest.mark.parametrize(("pace_factor", "instances"), [(1.5, 2), (0.0, 1)])
def test_the_next_person_in_a_corridor_is_not_the_slow_walker_lost_there(pace_factor, instances, monkeypatch):
    """A walker at 0.6 m/s lost, and 2 s later a person in other clothes 4.6 m back the way it
    came: a walk of 2.3 m/s (1.5 m/s from its rows 3 s before), not at its pace."""
    set_constants(monkeypatch, stitch_pace_factor=pace_factor)
    run = _Run()
    end = run.walk([0, 0, 0.85], [-0.6, 0, 0], 4.0, colours=_colours(0))
    run.idle(2.0)
    run.walk(end + np.array([4.6, 0.2, 0.0]), [-0.6, 0, 0], 3.0, colours=_colours(20))
    assert len(run.uuids()) == instances


def test_a_walker_keeps_its_pace_and_turns_back_unseen():
    """Lost for 2 s, it turned and came back past where it was: within its pace, one person."""
    run = _Run()
    end = run.walk([0, 0, 0.85], [0.6, 0, 0], 4.0, colours=_colours(0))
    run.idle(2.0)
    run.walk(end + np.array([-0.8, 0.1, 0.0]), [-0.6, 0, 0], 3.0, colours=_colours(20))
    assert len(run.uuids()) == 1


@pytest.mark.parametrize(("colours_after", "instances"), [(0, 1), (20, 2)])
def test_after_a_long_gap_the_clothes_tell(colours_after, instances):
    run = _Run()
    end = run.walk([0, 0, 0.85], [0.6, 0, 0], 3.0, colours=_colours(0))
    run.idle(10.0)  # out of view while the robot toured
    run.walk(end + np.array([-2.0, 1.0, 0.0]), [-0.6, 0, 0], 3.0, colours=_colours(colours_after))
    assert len(run.uuids()) == instances


def test_two_blobs_of_one_walker_are_one_instance():
    run = _Run()
    for k in range(45):
        x = 0.6 * k / RATE_HZ
        legs = ([x, 0.0, 0.4], np.array([0.4, 0.3, 0.8]), "person", None)
        head = ([x + 0.1, 0.05, 1.5], np.array([0.3, 0.3, 0.4]), "person", None)
        run.frame([legs, head] if k >= 5 else [legs])
    assert len(run.uuids()) == 1
    track = run.tracker.tracks[0]
    # every observation links to it but the head's last few, of a track not yet confirmed
    assert 45 + 40 - 3 <= len(track.observation_uuids) < 45 + 40


def test_a_chair_seen_again_keeps_its_instance_and_its_neighbour_its_own():
    run = _Run()
    chair = ([2.0, 1.0, 0.45], CHAIR, "chair", None)
    for _ in range(30):
        run.frame([chair])
    run.idle(5.0)  # the robot looks elsewhere; the chair's track closes
    assert not run.tracker.tracks and len(run.tracker.dormant) == 1
    back = ([2.05, 1.02, 0.4], np.array([0.45, 0.3, 0.5]), "chair", None)  # partly hidden now
    neighbour = ([2.8, 1.0, 0.45], CHAIR, "chair", None)
    for _ in range(30):
        run.frame([back, neighbour])
    assert len(run.uuids()) == 2
    revisited = min(run.tracker.tracks, key=lambda t: t.first_seen_s)
    assert revisited.hits == 60
    assert np.allclose(revisited.position[:2], [2.03, 1.01], atol=0.03)


def test_histograms_tell_colours_not_brightness():
    rng = np.random.default_rng(0)
    uv = np.stack(np.meshgrid(np.arange(20), np.arange(20)), axis=-1).reshape(-1, 2).astype(np.int32)
    red = np.zeros((20, 20, 3), np.uint8)
    red[..., 0] = rng.integers(150, 255, (20, 20))
    dark_red = (red * 0.6).astype(np.uint8)
    blue = red[..., ::-1].copy()
    h_red, h_dark, h_blue = (histogram(img, uv) for img in (red, dark_red, blue))
    assert similarity(h_red, h_dark) > 0.9
    assert similarity(h_red, h_blue) < 0.2
    assert histogram(red, uv[:5]) is None


def test_a_resume_drops_the_junk_a_lost_walker_took_while_it_searched():
    from hiper_cli.perceive.foreground.stitch import stale_rows

    config = TrackerConfig()
    tracker = Tracker(config)
    old = tracker._birth(Measurement(np.array([0.0, 0.0, 0.85]), PERSON, "person", 0.9, "a"), 0.0)
    old.trajectory = [[k / RATE_HZ, 0.6 * k / RATE_HZ, 0.0, 0.85, 0.6, 0.0, 0.0] for k in range(30)]
    walked = old.trajectory[-1][1]
    # lost, it took five junk blobs 2.5 m to the side; the walker is picked up where it went on
    old.trajectory += [[2.0 + k / RATE_HZ, walked, 2.5, 0.85, 0.0, 0.0, 0.0] for k in range(5)]
    new = tracker._birth(Measurement(np.array([walked + 0.3, 0.0, 0.85]), PERSON, "person", 0.9, "b"), 2.4)
    assert stale_rows(new, old, config) == 5
    new_far = tracker._birth(Measurement(np.array([9.0, 9.0, 0.85]), PERSON, "person", 0.9, "c"), 2.4)
    assert stale_rows(new_far, old, config) == 0  # within a walk of no row: nothing to cut


def test_a_walker_stands_on_the_floor_whatever_part_of_it_a_blob_shows():
    run = _Run()
    tracker = run.tracker
    for k in range(60):
        x = 0.6 * k / RATE_HZ
        legs = k % 3 == 2  # legs under a table: a blob 0.8 m tall
        box = (
            (np.array([x, 0.0, 0.4]), np.array([0.4, 0.3, 0.8])) if legs
            else (np.array([x, 0.0, 0.85]), PERSON)
        )
        m = Measurement(box[0], box[1], "person", 0.9, f"o{k}", standing=box)
        tracker.step(run.t_s, [m])
        run.t_s += 1.0 / RATE_HZ
    (track,) = tracker.tracks
    assert track.position[2] == pytest.approx(0.85, abs=1e-6)
    assert track.extent_m[2] == pytest.approx(1.7, abs=1e-6)
    assert track.velocity[2] == 0.0
    (closed,) = tracker.close_all()
    assert [row[3] for row in closed.trajectory] == pytest.approx([0.85] * 60, abs=1e-6)


def test_a_walker_last_seen_in_part_keeps_the_height_it_stood():
    """House 44: a person walked out of the image's side; the last views showed slivers of the
    upper body, and the instance box became 7 cm wide and 1.19 m tall, its bottom 0.3 m above
    the floor, so the learned altitude of people then refused people whose feet were seen."""
    run = _Run()
    tracker = run.tracker
    for k in range(45):
        x = 0.6 * k / RATE_HZ
        if k < 30:
            box = (np.array([x, 0.0, 0.85]), PERSON)
            m = Measurement(box[0], box[1], "person", 0.9, f"o{k}", standing=box)
        else:  # a sliver of the upper body at the image's border, no floor under it
            m = Measurement(np.array([x, 0.0, 1.25]), np.array([0.05, 0.04, 0.9]), "person", 0.9, f"o{k}",
                            whole=False)
        tracker.step(run.t_s, [m])
        run.t_s += 1.0 / RATE_HZ
    (track,) = tracker.tracks
    centre, extent = object_box(track, tracker.config)
    assert extent == pytest.approx(PERSON, abs=1e-6)
    assert centre[2] - extent[2] / 2.0 == pytest.approx(0.0, abs=1e-6)


def _walker_track(name, stamps, x_of_t, first_seen):
    """A confirmed person track with one row per stamp, walking along x."""
    rows = [[t, x_of_t(t), 0.0, 0.85, 0.6, 0.0, 0.0] for t in stamps]
    return Track(uuid=name, motion=None, first_seen_s=first_seen, last_update_s=stamps[-1],
                 last_time_s=stamps[-1], extent_m=PERSON, confirmed=True, hits=len(stamps),
                 class_votes={"person": float(len(stamps))}, class_counts={"person": len(stamps)},
                 trajectory=rows)


@pytest.mark.parametrize(("old_last_s", "apart_m", "joined"), [(3.7, 0.05, True), (3.7, 1.0, False),
                                                               (4.4, 0.05, False)])
def test_a_handover_between_two_tracks_of_one_walker_is_a_resume(old_last_s, apart_m, joined):
    """The old track lost the walker at 3.0 s, a new one took it from 3.03 s, and the old one
    took it once more at ``old_last_s``: one stamp in common, too few for a duplicate."""
    walk = lambda t: 0.6 * t  # noqa: E731
    old_stamps = [k / RATE_HZ for k in range(46)] + [old_last_s]
    old = _walker_track("old", old_stamps, lambda t: walk(t) + (apart_m if t > 3.5 else 0.0), 0.0)
    new_stamps = [3.03 + k / RATE_HZ for k in range(30)]
    new_stamps = sorted({round(t, 4) for t in new_stamps} | {old_last_s})
    new = _walker_track("new", new_stamps, walk, 3.03)
    found = find_target(new, [old], TrackerConfig(), moving=lambda t: True)
    assert (found == (old, RESUME)) is joined


def test_the_rows_after_a_resume_are_smoothed_too():
    """A walker lost and picked up again: the track closed (its rows smoothed) before the
    resume; at the end the rows after it are smoothed as well, so their speeds start at the
    walker's pace, not at the filter's (office 62 read 0.5 m/s for 1.0 where it came back)."""
    rng = np.random.default_rng(3)
    run = _Run()
    pos = np.array([0.0, 0.0, 0.85])
    for _ in range(int(3.0 * RATE_HZ)):
        run.frame([(pos + rng.normal(0.0, 0.03, 3), PERSON, "person", None)])
        pos = pos + np.array([1.0 / RATE_HZ, 0.0, 0.0])
    run.idle(2.0)
    pos = pos + np.array([2.0 + 1.0 / RATE_HZ, 0.0, 0.0])
    back_s = run.t_s
    for _ in range(int(1.5 * RATE_HZ)):
        run.frame([(pos + rng.normal(0.0, 0.03, 3), PERSON, "person", None)])
        pos = pos + np.array([1.0 / RATE_HZ, 0.0, 0.0])
    assert len(run.uuids()) == 1
    track = run.tracker.close_all()[0]
    rows = np.array([r for r in track.trajectory if r[0] >= back_s - 1e-9])
    assert len(rows) == int(1.5 * RATE_HZ)
    speeds = np.hypot(rows[:, 4], rows[:, 5])
    assert np.all(np.abs(speeds[:5] - 1.0) < 0.15)
