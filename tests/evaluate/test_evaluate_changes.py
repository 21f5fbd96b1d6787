"""``hiper eval changes`` scoring (``evaluate/changes.py``): re-identification against the true
objects of either layer, ghosts, counts of the foreground, and change matching by kind."""

from __future__ import annotations

import numpy as np

from hiper_cli.evaluate.changes import ChangeReport, _score_changes, _score_memory
from hiper_cli.model import Box3D, Instance


def _obj(oid, cls, x, y, layer="foreground"):
    return {"id": oid, "class": cls, "layer": layer, "state": "static", "box": {"center_m": [x, y, 0.4]}}


def _inst(cls, x, y, **data):
    box = Box3D(np.array([x, y, 0.4]), np.array([0.5, 0.5, 0.8]))
    return Instance(layer="foreground", class_name=cls, box=box, first_seen_s=0.0, last_seen_s=1.0,
                    data=dict(data))


def test_a_table_kept_as_an_object_is_one_true_table_but_not_counted_as_a_foreground_one():
    table, chair = _obj(1, "table", 8.4, 1.6, layer="background"), _obj(2, "chair", 1.0, 1.0)
    swapped = _obj(3, "chair", 3.0, 1.0)  # another chair where session 1's instance stood
    worlds = {1: [table, chair, _obj(4, "chair", 1.0, 3.0)], 2: [table, swapped, _obj(4, "chair", 1.0, 3.0)]}
    kept, wrong, gone = _inst("table", 8.4, 1.6), _inst("chair", 3.0, 1.0), _inst("chair", 1.0, 3.0)
    report = ChangeReport()
    seen_in = {kept.uuid: [1, 2], wrong.uuid: [1, 2], gone.uuid: [1]}
    _score_memory(report, [kept, wrong, gone], seen_in, worlds, last=2)
    assert (report.reid_merged, report.reid_precision) == (2, 0.5)  # the table right, the chair not
    assert report.counts["table"] == {"stored": 1, "true": 0, "error": 1}
    assert report.counts["chair"] == {"stored": 2, "true": 2, "error": 0}
    assert (report.ghosts, report.present_real) == (0, 3)


def test_changes_match_by_kind_class_session_and_place():
    truth = [{"kind": "moved", "class": "chair", "session": 2, "from_m": [0, 0, 0], "to_m": [2, 0, 0]},
             {"kind": "removed", "class": "potted plant", "session": 2, "from_m": [5, 5, 0], "to_m": None}]
    stored = [{"kind": "moved", "class": "chair", "from_m": [0.1, 0, 0], "to_m": [2.2, 0, 0]},
              {"kind": "removed", "class": "potted plant", "from_m": [5, 5, 0], "to_m": None},
              {"kind": "added", "class": "chair", "from_m": None, "to_m": [4, 4, 0]}]
    for change, session in zip(stored, (2, 3, 2), strict=True):
        change["truth_session"] = session
    got = _score_changes(stored, truth)
    assert got["moved"]["f1"] == 1.0
    assert (got["removed"]["precision"], got["removed"]["recall"]) == (0.0, 0.0)  # the wrong session
    assert (got["added"]["stored"], got["added"]["true"], got["added"]["precision"]) == (1, 0, 0.0)


def test_the_alignment_error_is_also_measured_where_the_robot_was(tmp_path):
    from hiper_cli.evaluate.changes import _alignment_errors

    log = tmp_path / "session_2"
    (log / "gt").mkdir(parents=True)
    # the true path in the log's frame: from 6 m to 8 m along x
    (log / "gt" / "groundtruth.txt").write_text("0.0 6 0 1.2 0 0 0 1\n1.0 8 0 1.2 0 0 0 1\n")
    a = np.radians(0.5)  # the stored transform is turned 0.5 deg about the log's origin
    T = np.eye(4)
    T[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    aligned = {"T_map_log": T.tolist(), "method": "registration", "fitness": 0.8}
    sessions = [{"id": 2, "log_path": str(log), "alignment": aligned}]
    (row,) = _alignment_errors(sessions, {"session_2": {"log": "session_2", "T_log_map": np.eye(4).tolist()}})
    assert row["error_m"] == 0.0  # at the origin, nothing
    assert abs(row["error_start_m"] - 6 * a) < 1e-3  # 5 cm at the start, 6 m from the origin
    assert abs(row["error_path_max_m"] - 8 * a) < 1e-3
    assert abs(row["error_deg"] - 0.5) < 1e-3
