"""Table III's truth votes (``hiper eval foreground``, ``hiper bench``): which truth instance an
observation shows."""

from __future__ import annotations

import numpy as np

from hiper_cli.evaluate.foreground import _both_ways_ids, _frame_truth
from hiper_cli.model import Box3D, Observation
from hiper_cli.perceive.logs.truth import Truth, TruthInstance
from hiper_cli.types import CameraIntrinsics, Frame

CAMERA = CameraIntrinsics(width=40, height=30, fx=30.0, fy=30.0, cx=20.0, cy=15.0)


class _Truth(Truth):
    def load_instance_ids(self, rgb_relpath: str) -> np.ndarray:
        ids = np.zeros((CAMERA.height, CAMERA.width), np.uint16)
        ids[15:, :20] = 1  # the table (background layer in a hiper sim world)
        ids[15:, 20:] = 2  # the chair
        return ids


def _observation(class_name: str, columns: slice) -> Observation:
    uv = [[u, v] for v in range(16, 30, 2) for u in range(columns.start, columns.stop, 2)]
    box = Box3D(np.zeros(3), np.ones(3))
    data = {"pixels_uv": uv, "center_map": [0.0, 0.0, 2.0]}
    return Observation("foreground", class_name, 0.9, 0.0, 0, box, data=data)


def test_a_table_the_foreground_found_votes_for_the_true_table():
    box = Box3D(np.array([2.0, 0.0, 0.4]), np.array([1.0, 1.0, 0.8]))
    instances = {
        1: TruthInstance(1, "table_0", "table", "background", "static", box),
        2: TruthInstance(2, "chair_0", "chair", "foreground", "static", box),
    }
    truth = _Truth("house", 0, instances, [])
    depth = np.full((CAMERA.height, CAMERA.width), 2.0, np.float32)
    frame = Frame(0.0, np.zeros((30, 40, 3), np.uint8), depth, CAMERA, np.eye(4), 0, source="rgb/0.png")
    table, named_wrong = _observation("table", slice(0, 20)), _observation("bottle", slice(0, 20))
    chair = _observation("chair", slice(20, 40))
    ids, errors, _ = _frame_truth(frame, truth, [table, named_wrong, chair], {2}, _both_ways_ids(truth), 2)
    # Only a table observation may take a background table's id: a bottle there shows no object.
    assert ids == {table.uuid: 1, named_wrong.uuid: None, chair.uuid: 2}
    assert set(errors) == {chair.uuid}  # a table's centre is its top's: no localisation
