"""A wall on evidence judged against the sensor's noise at its range (``wall_range.py``, the
probe tolerance of ``bounds.py``): depth noise grows with the square of the range, so a far
view tells a front or a door from a wall less well than a near one. A wall no nearer view saw
stays in the map while the log runs (its surface is no object) and is withdrawn at its end."""

import numpy as np

from hiper_cli.model import FrameResult, World
from hiper_cli.perceive.background import BackgroundConfig, BackgroundStage
from hiper_cli.perceive.background.wall_range import beyond_wall_range
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame

ROOM = box_room(size=(6.0, 8.0, 3.0))  # the wall facing the camera at y = 8
OFF = {"wall_view_max_noise_m": 0.0}  # every view counts


def _pitched(y, tx=3.0):
    """A camera 1.2 m high at (3, y) looking at the wall at y = 8, 15 degrees down."""
    dist = 8.0 - y
    return look_at((3.0, y, 1.2), (tx, 8.0, 1.2 - dist * np.tan(np.radians(15.0))))


def _walls_at_y(world, y, tol=0.1):
    return [i for i in world.background.values() if i.class_name == "wall"
            and i.data["plane_map"][1] < -0.9 and abs(abs(i.data["plane_map"][3]) - y) < tol]


def _run(boxes, poses, noise_m=0.001, **options):
    frames = [make_frame(boxes, T, pose_id=i, noise_m=noise_m) for i, T in enumerate(poses)]
    world, _ = run_stages(frames, [BackgroundStage(**options)])
    return world


def test_a_wall_seen_only_from_4_6_m_is_withdrawn_when_the_log_ends():
    # at 4.6 m the noise (0.053 m) hides a shelf front's rows and a door flush with its wall
    assert _walls_at_y(_run(ROOM, [_pitched(3.4)]), 8.0) == []
    assert len(_walls_at_y(_run(ROOM, [_pitched(3.4)], **OFF), 8.0)) == 1


def test_while_the_log_runs_the_far_wall_is_in_the_map():
    """The plane is a surface whatever it is: the stages after the background (the object map)
    see it while the log runs, and its finish withdraws it."""
    stage, world = BackgroundStage(), World()
    world.apply(stage.process(make_frame(ROOM, _pitched(3.4), noise_m=0.001), world))
    assert len(_walls_at_y(world, 8.0)) == 1
    world.apply(stage.finish(world))
    assert _walls_at_y(world, 8.0) == []


class _Recorder:
    """A stage after the background (as the object map is) that records the walls its
    ``finish`` sees."""

    name = "recorder"

    def __init__(self):
        self.walls_at_finish = None

    def process(self, frame, world):
        return FrameResult()

    def finish(self, world):
        self.walls_at_finish = _walls_at_y(world, 8.0)
        return FrameResult()


def test_the_stages_after_the_background_finish_before_it_withdraws_the_far_wall():
    recorder = _Recorder()
    world, _ = run_stages([make_frame(ROOM, _pitched(3.4), noise_m=0.001)], [BackgroundStage(), recorder])
    assert len(recorder.walls_at_finish) == 1  # fails with the stages finishing in order
    assert _walls_at_y(world, 8.0) == []


def test_a_far_view_extends_the_wall_a_near_view_mapped():
    for poses in ([_pitched(5.5), _pitched(3.4, tx=1.5)], [_pitched(3.4, tx=1.5), _pitched(5.5)]):
        walls = _walls_at_y(_run(ROOM, poses), 8.0)
        assert len(walls) == 1
        assert len(walls[0].observation_uuids) == 2  # the far view's observation joined it


def test_a_wall_of_an_earlier_session_is_kept():
    """An instance the run did not make (a place's map, loaded) has observations this run
    never judged: the far view that joins it withdraws nothing."""
    earlier = _walls_at_y(_run(ROOM, [_pitched(3.4)], **OFF), 8.0)  # mapped from 4.6 m
    world, _ = run_stages([make_frame(ROOM, _pitched(3.4, tx=1.5), noise_m=0.001)], [BackgroundStage()],
                          World(background={w.uuid: w for w in earlier}))
    assert len(_walls_at_y(world, 8.0)) == 1
    assert len(_walls_at_y(world, 8.0)[0].observation_uuids) == 2


def test_the_range_follows_the_noise_model():
    cfg = BackgroundConfig()  # sigma(z) = cell_noise_m z^2, at most wall_view_max_noise_m (0.045 m)
    assert not beyond_wall_range(4.0, cfg)  # 0.040 m
    assert beyond_wall_range(4.5, cfg)  # 0.051 m
    assert not beyond_wall_range(9.0, BackgroundConfig(cell_noise_m=0.0005))  # a better sensor
    assert not beyond_wall_range(9.0, BackgroundConfig(**OFF))


def test_a_shelf_front_with_its_books_recessed_seen_from_4_1_m_is_no_wall():
    """A free-standing shelf 4 m wide: its frame 1.6 m tall, above it the book rows 0.25 m back
    (up to 2.14 m, above the view). Seen from 4.1 m, above the front's top edge the camera sees
    the rows 0.24 m deeper than its plane: the front ends in the room. A probe tolerance of 5 %
    of the depth (0.255 m there) took them for the plane going on and the front for a wall;
    one no deeper than a front's least depth less the noise there (0.25 - 0.042 m) does not.
    A wall at the same range stays a wall."""
    room = box_room(size=(6.0, 10.0, 3.0))
    shelf = [SceneBox(41, "shelf", (1.0, 6.0, 0.0), (5.0, 6.6, 1.6)),
             SceneBox(41, "shelf", (1.0, 6.25, 1.6), (5.0, 6.6, 2.14))]
    tilt = 4.1 * np.tan(np.radians(15.0))
    facing_shelf = look_at((3.0, 1.9, 1.2), (3.0, 6.0, 1.2 - tilt))
    assert _walls_at_y(_run([*room, *shelf], [facing_shelf], noise_m=0.0), 6.0) == []
    facing_wall = look_at((3.0, 5.9, 1.2), (3.0, 10.0, 1.2 - tilt))
    assert len(_walls_at_y(_run(room, [facing_wall], noise_m=0.0), 10.0)) == 1
