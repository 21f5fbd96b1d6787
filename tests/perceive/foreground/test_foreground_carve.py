"""A small thing on furniture the background did not map is cut out of the furniture's blob
by its detection (house 41: a bottle on a side table was part of a 1 m ``unknown``)."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground.carve import carve_small
from hiper_cli.perceive.foreground.config import RefineConfig
from hiper_cli.perceive.foreground.segment import Blob, image_box
from tests.fg_constants import constants

FX, CX, CY, W, H, STEP = 525.0, 319.5, 239.5, 640, 480, 4
CAMERA_Z_M = 1.2  # looking along map +y, level; image x along map +x
TABLE_TOP_M, TABLE_NEAR_M, TABLE_FAR_M, TABLE_HALF_M = 0.75, 1.5, 2.1, 0.3
BOTTLE_Y_M, BOTTLE_HALF_M, BOTTLE_TOP_M = 1.75, 0.035, 1.0
HUTCH_Y_M, HUTCH_TOP_M = 2.05, 1.4  # a panel standing on the table's back


def _scene(with_table=True):
    """Ray-cast a bottle standing on a side table with a panel at its back: the blob the
    clustering would make of them, and the bottle's detection box."""
    us, vs = np.meshgrid(np.arange(0, W, STEP), np.arange(0, H, STEP))
    u, v = us.ravel().astype(float), vs.ravel().astype(float)
    rx, rz = (u - CX) / FX, -(v - CY) / FX  # ray per unit of depth (map y)
    depth = np.full(u.shape, np.inf)
    hit_bottle = np.zeros(u.shape, dtype=bool)
    # bottle front (y = BOTTLE_Y_M)
    x, z = rx * BOTTLE_Y_M, CAMERA_Z_M + rz * BOTTLE_Y_M
    on = (np.abs(x) <= BOTTLE_HALF_M) & (z >= TABLE_TOP_M) & (z <= BOTTLE_TOP_M)
    depth[on], hit_bottle[on] = BOTTLE_Y_M, True
    if with_table:
        with np.errstate(divide="ignore"):
            y_top = (TABLE_TOP_M - CAMERA_Z_M) / rz  # the top, seen from above
        on = (y_top >= TABLE_NEAR_M) & (y_top <= TABLE_FAR_M) & (np.abs(rx * y_top) <= TABLE_HALF_M)
        on &= y_top < depth
        depth[on] = y_top[on]
        hit_bottle[on] = False
        z = CAMERA_Z_M + rz * HUTCH_Y_M  # the panel
        on = (np.abs(rx * HUTCH_Y_M) <= TABLE_HALF_M) & (z >= TABLE_TOP_M) & (z <= HUTCH_TOP_M)
        on &= depth > HUTCH_Y_M
        depth[on] = HUTCH_Y_M
        hit_bottle[on] = False
        z = CAMERA_Z_M + rz * TABLE_NEAR_M  # the front
        on = (np.abs(rx * TABLE_NEAR_M) <= TABLE_HALF_M) & (z >= 0.0) & (z <= TABLE_TOP_M)
        on &= depth > TABLE_NEAR_M
        depth[on] = TABLE_NEAR_M
        hit_bottle[on] = False
    seen = np.isfinite(depth)
    d = depth[seen]
    cam = np.c_[rx[seen] * d, -rz[seen] * d, d]
    pts = np.c_[cam[:, 0], cam[:, 2], CAMERA_Z_M - cam[:, 1]]
    uv = np.c_[u[seen], v[seen]].astype(np.int32)
    blob = Blob(cam, pts, uv, image_box(uv, STEP, W, H))
    b = uv[hit_bottle[seen]]
    box = np.array([b[:, 0].min(), b[:, 1].min(), b[:, 0].max() + STEP, b[:, 1].max() + STEP], dtype=float)
    return blob, box


def _carve(blob, box, name="bottle", config=None):
    return carve_small([blob], [False], box.reshape(1, 4), [name], config or RefineConfig(), 0.15, W, H)


def test_a_bottle_on_a_side_table_is_cut_out():
    blob, box = _scene()
    blobs, changed = _carve(blob, box)
    assert len(blobs) == 2 and all(changed)
    table, bottle = blobs
    centre = bottle.points_map.mean(axis=0)
    assert centre[0] == pytest.approx(0.0, abs=0.02)
    assert centre[1] == pytest.approx(BOTTLE_Y_M, abs=0.03)
    assert centre[2] == pytest.approx((TABLE_TOP_M + BOTTLE_TOP_M) / 2, abs=0.03)
    assert bottle.points_map[:, 2].min() > TABLE_TOP_M - 0.02  # none of the table's front
    assert bottle.points_map[:, 1].max() < HUTCH_Y_M - 0.05  # none of the panel behind it
    assert not np.any(np.abs(table.points_map[:, 1] - BOTTLE_Y_M) < 1e-6)  # none of the bottle


def test_only_small_classes_in_a_blob_too_big_for_them_are_cut():
    blob, box = _scene()
    assert len(_carve(blob, box, "chair")[0]) == 1  # a chair's box: no small thing
    alone, alone_box = _scene(with_table=False)
    assert len(_carve(alone, alone_box)[0]) == 1  # the bottle on its own fits its class
    with constants(carve_classes=()):
        assert len(_carve(blob, box)[0]) == 1
