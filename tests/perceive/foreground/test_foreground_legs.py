"""Table legs leave the foreground blobs: a chair beside a table keeps its own centre."""

import numpy as np
import pytest

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground import ForegroundConfig
from hiper_cli.perceive.foreground.legs import drop_table_legs, leg_points
from hiper_cli.perceive.foreground.segment import segment
from tests.fg_constants import patched
from tests.fg_scene import CAMERA, SceneBox, background_instances, make_frame, pose_looking_x, room

TOP = SceneBox(20, np.array([3.0, 0.6, 0.74]), np.array([0.8, 1.0, 0.04]), "table", True)
LEG = SceneBox(21, np.array([2.65, 0.15, 0.36]), np.array([0.06, 0.06, 0.72]), "leg")
CHAIR = SceneBox(22, np.array([2.65, -0.12, 0.3]), np.array([0.4, 0.4, 0.6]), "chair")  # 0.07 m from the leg


def blobs_of(boxes, cfg):
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = background_instances(boxes)
    return segment(frame.depth_m, CAMERA, frame.T_map_cam, [i.box for i in bg.values()], cfg)[0]


def test_a_leg_merged_with_a_chair_is_removed(monkeypatch):
    cfg = ForegroundConfig(pixel_step=2)
    (merged,) = blobs_of([*room(), TOP, LEG, CHAIR], cfg)  # the clustering joins leg and chair
    assert merged.points_map[:, 2].max() > 0.65
    table = Box3D(TOP.center, TOP.extent)
    (chair,) = drop_table_legs([merged], [table], cfg, 2, CAMERA.width, CAMERA.height)
    assert chair.points_map[:, 2].max() == pytest.approx(0.6, abs=0.03)
    assert chair.points_map[:, 1].mean() == pytest.approx(-0.12, abs=0.03)
    assert len(chair.points_map) < len(merged.points_map)
    # Off, or no table known: the blob stays as it is.
    off = patched(monkeypatch, pixel_step=2, table_leg_cell_m=0.0)
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


def test_the_rim_of_a_table_top_no_longer_joins_a_chair_to_a_vase_on_the_table(monkeypatch):
    # The background layer knows the top as a thin plane; the top's edge under it survives the
    # filter and links the chair in front of the table to the vase standing at the edge.
    # (Block means off: the rim is a single row of samples here, a block would mix in the top.)
    cfg = patched(monkeypatch, pixel_step=2, table_rim_depth_m=0.08, background_block_mean=False)
    top_plane = Box3D(np.array([3.0, 0.6, 0.75]), np.array([0.8, 1.0, 0.01]))
    slab = SceneBox(30, np.array([3.0, 0.6, 0.715]), np.array([0.8, 1.0, 0.07]), "table")
    chair = SceneBox(31, np.array([2.36, 0.6, 0.3]), np.array([0.4, 0.4, 0.6]), "chair")
    vase = SceneBox(32, np.array([2.68, 0.6, 0.86]), np.array([0.16, 0.16, 0.22]), "vase")
    frame = make_frame([*room(), slab, chair, vase], pose_looking_x(x=0.3, z=1.2), 0.0, 0)
    filters = [i.box for i in background_instances(room()).values()] + [top_plane]
    (merged,) = segment(frame.depth_m, CAMERA, frame.T_map_cam, filters, cfg)[0]
    assert merged.points_map[:, 2].max() > 0.9  # chair, rim and vase in one blob
    # Without the rim rule the blob stays one (the rim is no leg).
    (same,) = drop_table_legs([merged], [top_plane], cfg, 2, CAMERA.width, CAMERA.height)
    assert len(same.points_map) == len(merged.points_map)
    parts = drop_table_legs([merged], [top_plane], cfg, 2, CAMERA.width, CAMERA.height, rims=True)
    assert len(parts) == 2
    low, high = sorted(parts, key=lambda b: b.points_map[:, 2].max())
    assert low.points_map[:, 2].max() == pytest.approx(0.6, abs=0.02)  # the chair, alone
    assert low.points_map[:, 0].mean() == pytest.approx(2.2, abs=0.05)
    assert high.points_map[:, 0].mean() == pytest.approx(2.62, abs=0.03)  # the vase
    assert np.mean(high.points_map[:, 2] > 0.75) > 0.8  # with the bit of rim right below it
    assert len(low.points_map) + len(high.points_map) < len(merged.points_map)  # the rim left
