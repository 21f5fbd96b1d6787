"""A known background instance seen again moves its ``last_seen`` (``sighting.py``), whether
or not a plane segment forms: a table seen across a room answers "a table in the last 15 s"."""

import numpy as np
import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.background import BackgroundConfig
from hiper_cli.perceive.background.sighting import sighted
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame

TABLE = SceneBox(20, "table", (2.6, 2.0, 0.71), (3.8, 2.8, 0.75))


def _table_instance(last_seen_s):
    top = Box3D(np.array([3.2, 2.4, 0.75]), np.array([1.2, 0.8, 0.02]))
    return Instance("background", "table", top, 0.0, last_seen_s, data={"plane_map": [0, 0, 1, -0.75]})


def test_a_table_in_view_is_seen_and_one_behind_the_camera_is_not():
    cfg = BackgroundConfig()
    scene = [*box_room(), TABLE]
    toward = make_frame(scene, look_at((0.5, 0.5, 1.2), (3.2, 2.4, 0.75)), stamp_s=30.0, noise_m=0.002)
    away = make_frame(scene, look_at((0.5, 0.5, 1.2), (-2.0, -2.0, 1.2)), stamp_s=30.0, noise_m=0.002)
    seen = sighted(toward, [_table_instance(10.0)], cfg)
    assert [i.last_seen_s for i in seen] == [30.0]
    assert seen[0].first_seen_s == 0.0 and seen[0].box.extent_m[0] == 1.2  # nothing else moves
    assert sighted(away, [_table_instance(10.0)], cfg) == []


def test_sightings_are_at_most_every_refresh_and_can_be_off():
    scene = [*box_room(), TABLE]
    frame = make_frame(scene, look_at((0.5, 0.5, 1.2), (3.2, 2.4, 0.75)), stamp_s=30.0)
    assert sighted(frame, [_table_instance(29.5)], BackgroundConfig(sighting_refresh_s=1.0)) == []
    assert sighted(frame, [_table_instance(10.0)], BackgroundConfig(sighting_min_pixels=0)) == []


def test_a_few_pixels_are_no_sighting():
    """A sliver under the truth detector's 400 pixels (of 640x480) is not a sighting."""
    scene = [*box_room(), TABLE]
    frame = make_frame(scene, look_at((0.5, 0.5, 1.2), (3.2, 2.4, 0.75)), stamp_s=30.0)
    many = BackgroundConfig(sighting_min_pixels=640 * 480)  # all the image on the table: never
    assert sighted(frame, [_table_instance(10.0)], many) == []


def test_a_stride_below_one_is_a_config_error():
    with pytest.raises(ConfigError, match="sighting_stride_px must be >= 1"):
        BackgroundConfig(sighting_stride_px=0)
