"""A walker is a solid body and a detection names the nearest thing in its box (``solid.py``):
a picture of a person is no person, a lost person's track does not take a wall piece, and a
wall behind a person does not take the person's name."""

import numpy as np

from hiper_cli.perceive.foreground import ForegroundConfig, ForegroundStage
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.match import Match
from hiper_cli.perceive.foreground.solid import detected_blobs, is_flat
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker
from hiper_cli.perceive.stage import World
from tests.fg_constants import constants
from tests.fg_scene import SceneBox, background_instances, make_frame, person, pose_looking_x, room

RATE_HZ = 15.0


def _poster(id_, y):
    """A poster of a person 1 cm thick on a stand (its class: what a detector names it), 3.4 m
    away: within the range where the depth noise cannot hide a body's relief."""
    return SceneBox(id_, np.array([3.4, y, 1.2]), np.array([0.01, 0.6, 1.2]), "person")


def test_a_poster_of_a_person_is_no_person_and_a_person_is():
    boxes = [*room(), _poster(20, 0.8), person(10, 3.0, -0.8)]
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    for solid, picture_class in ((True, "unknown"), (False, "person")):
        with constants(walker_solid=solid):
            stage = ForegroundStage(detector="log", pixel_step=2)
            result = stage.process(frame, World(background=background_instances(room())))
        by_side = sorted(result.observations, key=lambda o: o.data["center_map"][1])
        assert [o.class_name for o in by_side] == ["person", picture_class], solid


def test_flat_means_within_the_depth_noise_of_one_plane():
    cfg = ForegroundConfig()
    rng = np.random.default_rng(1)
    n = 400
    uv = rng.uniform(-0.3, 0.3, (n, 2))
    wall = np.column_stack([uv, 3.0 + rng.normal(0.0, 0.01, n)])  # 1 cm of noise at 3 m
    body = np.column_stack([uv, 3.0 - 0.15 * (1.0 - (uv[:, 0] / 0.3) ** 2) + rng.normal(0.0, 0.01, n)])
    assert is_flat(wall, cfg) and not is_flat(body, cfg)
    chest = np.column_stack([uv[:, 0] * 0.15, uv[:, 1] * 0.5, 0.4 + rng.normal(0.0, 0.001, n)])
    assert not is_flat(chest, cfg)  # a person 0.4 m away: a flat patch 9 x 30 cm, no panel
    close = np.column_stack([uv[:, 0] * 0.9, uv[:, 1], 0.45 + rng.normal(0.0, 0.001, n)])
    assert not is_flat(close, cfg)  # 0.45 m away the chest fills the view, 0.54 m across


def test_flatness_is_no_evidence_where_the_noise_reaches_a_bodys_relief():
    """At 5 m the noise margin (0.0475 m) exceeds a torso's relief: a walker's upper body read
    as flat as a wall (bookstore), and its track lost it."""
    cfg = ForegroundConfig()
    rng = np.random.default_rng(2)
    uv = rng.uniform(-0.3, 0.3, (400, 2))
    torso = np.column_stack([uv, 5.0 - 0.05 * (1.0 - (uv[:, 0] / 0.3) ** 2) + rng.normal(0.0, 0.01, 400)])
    assert not is_flat(torso, cfg)


def test_a_lost_persons_track_does_not_take_a_wall_piece():
    def run(wall_solid):
        tracker = Tracker(TrackerConfig())
        t = 0.0
        size = np.array([0.5, 0.4, 1.7])
        for k in range(30):  # a person walks along x at 0.9 m/s ...
            centre = np.array([0.06 * k, 0.0, 0.85])
            tracker.step(t, [Measurement(centre, size, "person", 0.9, f"p{k}")])
            t += 1.0 / RATE_HZ
        for k in range(5):  # ... leaves the view; a wall piece as large shows where it went
            wall = np.array([2.0 + 0.06 * k, 0.2, 1.0])
            tracker.step(t, [Measurement(wall, np.array([0.6, 0.03, 2.0]), "unknown", 0.0, f"w{k}",
                                         solid=wall_solid)])
            t += 1.0 / RATE_HZ
        walker = next(tr for tr in tracker.tracks if tr.class_name == "person")
        return walker.hits

    assert run(wall_solid=False) == 30
    assert run(wall_solid=True) > 30  # a solid blob as large: the person cut by the border


def test_a_detection_names_the_nearest_of_its_blobs():
    cfg = ForegroundConfig()
    named = Match("person", 0.8, 0, 0.9)
    other = Match("chair", 0.7, 1, 0.8)
    person_depths = np.linspace(2.0, 2.3, 50)
    wall_depths = np.linspace(4.8, 4.9, 50)  # the wall behind the person, in the same box
    legs_depths = np.linspace(2.05, 2.35, 50)  # the person's legs under a table: same depth
    chair_depths = np.linspace(4.8, 5.0, 50)  # another detection's blob, far away
    depths = [person_depths, wall_depths, legs_depths, chair_depths]
    out = detected_blobs([named, named, named, other], depths, cfg)
    assert [m.class_name for m in out] == ["person", "unknown", "person", "chair"]
    assert out[1].detection_index is None


def test_a_detection_of_furniture_names_the_blob_that_fits_its_box():
    """A desk's end 1.2 m in front of a chair fills part of the chair's box (office 72): the
    chair's blob fits the box best and keeps the name, the desk is not a chair. A walker's
    detection still names the nearest: the person in front of a wall trimmed to its box."""
    cfg = ForegroundConfig()
    desk_end, chair = Match("chair", 0.8, 0, 0.69), Match("chair", 0.8, 0, 0.86)
    chair_seat = Match("chair", 0.8, 0, 0.3)  # a piece of the same chair at its depth
    depths = [np.linspace(1.8, 2.3, 50), np.linspace(3.2, 3.6, 50), np.linspace(3.3, 3.5, 50)]
    out = detected_blobs([desk_end, chair, chair_seat], depths, cfg)
    assert [m.class_name for m in out] == ["unknown", "chair", "chair"]
    person, wall = Match("person", 0.8, 0, 0.8), Match("person", 0.8, 0, 0.95)
    out = detected_blobs([person, wall], [np.linspace(2.0, 2.3, 50), np.linspace(4.8, 4.9, 50)], cfg)
    assert [m.class_name for m in out] == ["person", "unknown"]
