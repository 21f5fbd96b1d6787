"""Tables the background layer has not mapped yet leave the blobs of what stands at them."""

import numpy as np

from hiper_cli.perceive.foreground import ForegroundConfig
from hiper_cli.perceive.foreground.segment import segment
from hiper_cli.perceive.foreground.tables import drop_unseen_tables, unseen_table_top
from tests.fg_scene import CAMERA, SceneBox, background_instances, make_frame, person, pose_looking_x, room

TABLE_ID, PERSON_ID = 20, 10


def _table(x0=2.0, x1=2.8, y=0.0, half_width=0.4, height=0.75):
    parts = [SceneBox(TABLE_ID, np.array([(x0 + x1) / 2, y, height - 0.02]),
                      np.array([x1 - x0, 2 * half_width, 0.04]), "table")]
    for lx in (x0 + 0.05, x1 - 0.05):
        for ly in (y - half_width + 0.05, y + half_width - 0.05):
            parts.append(SceneBox(TABLE_ID, np.array([lx, ly, (height - 0.04) / 2]),
                                  np.array([0.05, 0.05, height - 0.04]), "table"))
    return parts


def _scene():
    boxes = [*room(), *_table(), person(PERSON_ID, 2.05, 0.65)]  # beside the table, touching it
    cfg = ForegroundConfig(pixel_step=2)
    frame = make_frame(boxes, pose_looking_x(z=1.6), 0.0, 0)  # looking down at the top
    bg = [i.box for i in background_instances(boxes).values()]  # floor and wall: no table
    blobs, _ = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, cfg)
    ids = frame.extras["ids"]
    ys, xs = np.nonzero(ids == PERSON_ID)
    person_box = np.array([[xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]], dtype=np.float64)
    return cfg, blobs, ids, person_box


def _ids(blob, ids):
    return set(np.unique(ids[blob.pixels_uv[:, 1], blob.pixels_uv[:, 0]]).tolist())


def _table_share(blobs, ids):
    """Share of table samples in the blob holding most of the person."""
    counts = [np.bincount(ids[b.pixels_uv[:, 1], b.pixels_uv[:, 0]], minlength=TABLE_ID + 1) for b in blobs]
    best = max(counts, key=lambda c: c[PERSON_ID])
    return best[TABLE_ID] / best.sum(), best[PERSON_ID]


def test_a_person_at_an_unmapped_table_comes_apart_from_it():
    cfg, blobs, ids, person_box = _scene()
    share, person_before = _table_share(blobs, ids)
    assert share > 0.2  # one cluster: the person and the table
    (merged,) = [b for b in blobs if PERSON_ID in _ids(b, ids)]
    top = unseen_table_top(merged.points_map, cfg)
    assert top is not None and abs(top.aabb()[1][2] - 0.75) < 0.03
    out = drop_unseen_tables(blobs, person_box, ["person"], cfg, CAMERA.width, CAMERA.height)
    share, person_after = _table_share(out, ids)
    assert share < 0.05 and person_after >= 0.9 * person_before


def test_furniture_with_tops_of_its_own_and_blobs_without_detection_stay_whole():
    cfg, blobs, _, person_box = _scene()
    as_couch = drop_unseen_tables(blobs, person_box, ["couch"], cfg, CAMERA.width, CAMERA.height)
    assert [len(b.points_cam) for b in as_couch] == [len(b.points_cam) for b in blobs]
    no_dets = drop_unseen_tables(blobs, np.zeros((0, 4)), [], cfg, CAMERA.width, CAMERA.height)
    assert [len(b.points_cam) for b in no_dets] == [len(b.points_cam) for b in blobs]
    off = ForegroundConfig(pixel_step=2, unseen_table_min_side_m=0.0)
    kept = drop_unseen_tables(blobs, person_box, ["person"], off, CAMERA.width, CAMERA.height)
    assert len(kept) == len(blobs)


def test_a_narrow_slab_is_not_a_table():
    cfg = ForegroundConfig(pixel_step=2)
    rng = np.random.default_rng(0)
    n = 300
    back = np.column_stack([rng.uniform(0, 0.45, n), rng.uniform(0, 0.04, n), rng.uniform(0.88, 0.92, n)])
    c, s = np.cos(0.8), np.sin(0.8)
    turned = back @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T
    assert unseen_table_top(turned, cfg) is None  # a chair's back, turned 45 degrees
    top = np.column_stack([rng.uniform(0, 0.8, n), rng.uniform(0, 0.6, n), rng.uniform(0.73, 0.75, n)])
    assert unseen_table_top(top, cfg) is not None
