"""A bottle cut from its table's blob starts a track of its own; the table keeps the blob's track."""

import numpy as np

from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.split_parts import held_tables
from hiper_cli.perceive.foreground.tables import split_unseen_tables
from hiper_cli.perceive.foreground.tracking import Measurement, Tracker

TABLE_LO, TABLE_HI = np.array([-0.3, -0.3, 0.0]), np.array([0.3, 0.3, 0.8])


def _box(lo, hi, class_name, uuid, cut=None):
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    return Measurement((lo + hi) / 2, hi - lo, class_name, 0.9 if class_name != "unknown" else 0.0, uuid,
                       bounds_map_m=(lo, hi), cut_from_table_m=cut)


def _run(cut, composite_class="unknown"):
    """Hospital 46: 40 frames of a bedside table and its bottle as one blob no detection names,
    with a chair's blob beside them; then the table's top is found and the blob falls apart
    into the table and the bottle, while the chair is hidden. Returns (the composite's track,
    the chair's, the track the bottle joined, the track the table joined)."""
    tracker = Tracker(ForegroundConfig())
    first: list = []
    for k in range(40):
        ms = [_box([-0.3, -0.3, 0.0], [0.3, 0.3, 1.04], composite_class, f"c{k}"),
              _box([-0.22, 0.28, 0.0], [0.22, 0.68, 0.7], "unknown", f"h{k}")]
        _, joined = tracker.step(k / 30.0, ms)
        if k == 1:
            first = joined
    table_box = (TABLE_LO, TABLE_HI) if cut else None
    bottle = _box([0.01, -0.04, 0.8], [0.08, 0.03, 1.04], "bottle", "b", cut=table_box)
    table = _box(TABLE_LO, TABLE_HI, "table", "t")
    _, joined = tracker.step(40 / 30.0, [bottle, table])
    return first[0], first[1], joined[0], joined[1]


def test_a_bottle_cut_from_its_tables_blob_does_not_take_that_blobs_track():
    composite, chair, bottle, table = _run(cut=False)
    assert (bottle, table) == (composite, chair)  # nearest centres: both go wrong
    composite, chair, bottle, table = _run(cut=True)
    assert bottle is None and table == composite


def test_a_named_track_keeps_its_object_cut_from_a_table():
    composite, _, bottle, _ = _run(cut=True, composite_class="bottle")
    assert bottle == composite


def test_held_tables_is_the_share_of_the_table_inside_the_last_box():
    tables = [None, (TABLE_LO, TABLE_HI)]
    last = [(TABLE_LO, np.array([0.3, 0.3, 1.1])), (TABLE_LO, np.array([0.3, 0.0, 0.8])),
            (TABLE_LO, np.array([0.3, -0.1, 0.8])), None]
    np.testing.assert_array_equal(held_tables(last, tables), [[False, True], [False, True],
                                                              [False, False], [False, False]])


def test_parts_of_a_split_blob_carry_the_table_they_were_cut_from():
    from tests.fg_scene import CAMERA
    from tests.test_foreground_tables import _scene

    cfg, blobs, _, person_box = _scene()
    out, tables, _ = split_unseen_tables(blobs, person_box, ["person"], cfg, CAMERA.width, CAMERA.height)
    (table,) = tables
    cut = [b for b in out if b.cut_from_table_m is not None]
    assert cut
    for part in cut:
        np.testing.assert_allclose(part.cut_from_table_m[0], table.bounds_map[0])
        np.testing.assert_allclose(part.cut_from_table_m[1], table.bounds_map[1])

