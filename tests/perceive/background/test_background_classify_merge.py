"""Plane classification thresholds and the three cases of Algorithm 2, on planes built by hand."""

import numpy as np
import pytest

from hiper_cli.model import Box3D, Observation
from hiper_cli.perceive.background import BackgroundConfig
from hiper_cli.perceive.background.classify import classify_plane
from hiper_cli.perceive.background.merge import MapObservation
from hiper_cli.perceive.background.stage import merge_observations

CFG = BackgroundConfig()


def _vertical(x0, x1, z0, z1, y=3.0):
    """A vertical rectangle in the plane y = const, facing -y (a camera at smaller y)."""
    ring = np.array([[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]])
    return np.array([0.0, -1.0, 0.0, y]), ring


def _horizontal(x0, x1, y0, y1, z, up=True):
    ring = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])
    return (np.array([0.0, 0.0, 1.0, -z]) if up else np.array([0.0, 0.0, -1.0, z])), ring


@pytest.mark.parametrize(
    "shape,expected",
    [
        (_vertical(0.0, 4.0, 0.0, 2.5), "wall"),
        (_vertical(0.0, 1.5, 0.3, 2.2), "wall"),  # a wall piece seen partly
        (_vertical(0.0, 0.5, 0.0, 1.8), None),  # a person standing still: too narrow
        (_vertical(0.0, 1.2, 0.0, 1.4), None),  # a shelf front: not tall enough
        (_horizontal(0.0, 5.0, 0.0, 4.0, 0.0), "floor"),
        (_horizontal(0.0, 0.8, 0.0, 0.5, 0.15), None),  # a cart's low shelf
        (_horizontal(0.0, 1.6, 0.0, 0.9, 0.75), "table"),
        (_horizontal(0.0, 0.44, 0.0, 0.44, 0.45), None),  # a chair seat
        (_horizontal(0.0, 2.0, 0.0, 1.0, 0.53), None),  # a bed
        (_horizontal(0.0, 0.6, 0.0, 0.6, 0.8), "table"),  # a bedside table
        (_horizontal(0.0, 6.0, 0.0, 4.0, 2.6, up=False), "ceiling"),
        (_horizontal(0.0, 1.0, 0.0, 1.0, 0.9, up=False), None),  # the underside of a table
    ],
)
def test_classification(shape, expected):
    plane, ring = shape
    assert classify_plane(plane, ring, CFG) == expected


def _obs(plane, ring, stamp_s, class_name="wall"):
    obs = Observation("background", class_name, 1.0, stamp_s, int(stamp_s * 2), Box3D.from_points(ring))
    return MapObservation(obs, plane, ring, ring.mean(axis=0), 1.0)


def test_algorithm_2_new_merge_and_delete_duplicates():
    live = {}
    left = _obs(*_vertical(0.0, 2.0, 0.0, 2.5), 0.0)
    right = _obs(*_vertical(3.0, 5.0, 0.0, 2.5), 0.5)
    touched, deleted = merge_observations([left, right], live, CFG)
    assert len(live) == 2 and not deleted  # 0 matches: two new instances (1 m apart)
    same = _obs(*_vertical(0.5, 1.5, 0.5, 2.0), 1.0)
    touched, deleted = merge_observations([same], live, CFG)
    assert len(live) == 2 and not deleted and len(touched) == 1  # 1 match: merged
    (inst,) = touched.values()
    assert inst.observation_uuids == [left.obs.uuid, same.obs.uuid]
    bridge = _obs(*_vertical(1.5, 3.5, 0.0, 2.5), 1.5)
    touched, deleted = merge_observations([bridge], live, CFG)
    assert len(live) == 1 and len(deleted) == 1  # >1 matches: merged, the duplicate deleted
    (inst,) = live.values()
    assert inst.uuid == next(iter(touched))
    assert sorted(inst.observation_uuids) == sorted(o.obs.uuid for o in (left, right, same, bridge))
    assert inst.box.extent_m[:2] == pytest.approx([5.0, 2.5], abs=0.05)
    assert bridge.obs.instance_uuid == inst.uuid


def test_other_classes_and_parallel_planes_do_not_merge():
    live = {}
    wall = _obs(*_vertical(0.0, 2.0, 0.0, 2.5), 0.0)
    other_side = _obs(np.array([0.0, 1.0, 0.0, -3.1]), _vertical(0.0, 2.0, 0.0, 2.5, y=3.1)[1], 0.5)
    table = _obs(*_horizontal(0.0, 1.0, 2.0, 2.9, 0.75), 1.0, class_name="table")
    merge_observations([wall, other_side, table], live, CFG)
    assert len(live) == 3
