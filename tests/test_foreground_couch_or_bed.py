"""A couch and a bed are told apart by where their tall part stands (``couch_or_bed.py``): a
back along a long side, a headboard across a short end; a view that cannot show it leaves the
detector's name."""

import numpy as np

from hiper_cli.perceive.foreground.couch_or_bed import BED, COUCH, couch_or_bed

RNG = np.random.default_rng(7)


def _box(lo, hi, n):
    """Points on the top and the sides of a box (what a camera above seat height sees)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    pts = RNG.uniform(lo, hi, size=(n, 3))
    pts[: n // 2, 2] = hi[2]  # half on its top
    return pts


def _turn(points, yaw_rad, offset=(3.0, -1.0)):
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    out = points.copy()
    out[:, :2] = points[:, :2] @ np.array([[c, s], [-s, c]]) + offset
    return out


# a couch 0.9 m deep, 1.8 m long (along y), its back along x = -0.45; a bed 2 m long (along x)
COUCH_POINTS = np.vstack([_box([-0.45, -0.9, 0.0], [0.45, 0.9, 0.45], 600),
                          _box([-0.45, -0.9, 0.42], [-0.25, 0.9, 0.85], 250),
                          _box([-0.45, -0.9, 0.42], [0.45, -0.72, 0.62], 60),
                          _box([-0.45, 0.72, 0.42], [0.45, 0.9, 0.62], 60)])
BED_POINTS = np.vstack([_box([-1.0, -0.5, 0.0], [1.0, 0.5, 0.55], 900),
                        _box([-1.05, -0.5, 0.0], [-1.0, 0.5, 0.95], 120)])


def test_a_back_along_a_long_side_is_a_couch_a_headboard_across_an_end_a_bed():
    for yaw in (0.0, 0.6, np.pi / 2):  # however it is turned in the map
        assert couch_or_bed(_turn(COUCH_POINTS, yaw), 0.0) == COUCH
        assert couch_or_bed(_turn(BED_POINTS, yaw), 0.0) == BED
    assert couch_or_bed(BED_POINTS + np.array([0.0, 0.0, 0.3]), 0.3) == BED  # heights from the floor


def test_what_cannot_show_its_tall_part_keeps_the_detectors_name():
    no_headboard = _box([-1.0, -0.5, 0.0], [1.0, 0.5, 0.55], 900)
    both_ends = np.vstack([BED_POINTS, _box([1.0, -0.5, 0.0], [1.05, 0.5, 0.95], 120)])
    back_only = COUCH_POINTS[COUCH_POINTS[:, 0] < -0.25]  # a couch seen from behind
    strip = BED_POINTS[np.abs(BED_POINTS[:, 0]) < 0.5]  # a 1 m piece of a bed's side
    for points in (no_headboard, both_ends, back_only, strip, BED_POINTS[:10]):
        assert couch_or_bed(points, 0.0) is None
