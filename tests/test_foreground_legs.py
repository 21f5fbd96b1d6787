"""Table legs leave the foreground blobs: a chair beside a table keeps its own centre."""

import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundConfig
from hiper_cli.perceive.foreground.legs import drop_table_legs, leg_points
from hiper_cli.perceive.foreground.segment import segment
from tests.fg_scene import CAMERA, SceneBox, background_instances, make_frame, pose_looking_x, room

TOP = SceneBox(20, np.array([3.0, 0.6, 0.74]), np.array([0.8, 1.0, 0.04]), "table", True)
LEG = SceneBox(21, np.array([2.65, 0.15, 0.36]), np.array([0.06, 0.06, 0.72]), "leg")
CHAIR = SceneBox(22, np.array([2.65, -0.12, 0.3]), np.array([0.4, 0.4, 0.6]), "chair")  # 0.07 m from the leg


def blobs_of(boxes, cfg):
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = background_instances(boxes)
    return segment(frame.depth_m, CAMERA, frame.T_map_cam, [i.box for i in bg.values()], cfg)[0]


def test_a_leg_merged_with_a_chair_is_removed():
    cfg = ForegroundConfig(pixel_step=2)
    (merged,) = blobs_of([*room(), TOP, LEG, CHAIR], cfg)  # the clustering joins leg and chair
    assert merged.points_map[:, 2].max() > 0.65
    table = Box3D(TOP.center, TOP.extent)
    (chair,) = drop_table_legs([merged], [table], cfg, 2, CAMERA.width, CAMERA.height)
    assert chair.points_map[:, 2].max() == pytest.approx(0.6, abs=0.03)
    assert chair.points_map[:, 1].mean() == pytest.approx(-0.12, abs=0.03)
    assert len(chair.points_map) < len(merged.points_map)
    # Off, or no table known: the blob stays as it is.
    off = ForegroundConfig(pixel_step=2, table_leg_cell_m=0.0)
    assert drop_table_legs([merged], [table], off, 2, CAMERA.width, CAMERA.height) == [merged]
    assert drop_table_legs([merged], [], cfg, 2, CAMERA.width, CAMERA.height) == [merged]


def test_columns_that_go_higher_or_stop_lower_are_not_legs():
    cfg = ForegroundConfig()
    table = Box3D(np.array([0.0, 0.0, 0.74]), np.array([1.0, 1.0, 0.04]))
    zs = np.linspace(0.02, 1.0, 50)
    back_leg = np.stack([np.full(50, 0.45), np.zeros(50), zs], axis=1)  # a chair back: up to 1.0 m
    front_leg = back_leg[zs <= 0.45] + np.array([0.2, 0.0, 0.0])  # stops at the seat
    table_leg = back_leg[zs <= 0.72] + np.array([-0.2, 0.0, 0.0])  # up to the underside of the top
    pts = np.concatenate([back_leg, front_leg, table_leg])
    legs = leg_points(pts, [table], cfg)
    assert not legs[: len(back_leg) + len(front_leg)].any()
    assert legs[len(back_leg) + len(front_leg):].all()
    assert not leg_points(table_leg + np.array([3.0, 0.0, 0.0]), [table], cfg).any()  # far from the table
