"""Algorithm 4: IoU of blob image boxes with detection boxes, threshold, ties, empty inputs."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground.match import assign_classes, iou_matrix
from hiper_cli.types import Detections


def dets(*records):
    return Detections.from_records([{"xyxy": b, "class": c, "score": s} for b, c, s in records])


def test_iou_matrix_values():
    iou = iou_matrix(np.array([[0, 0, 10, 10]]), np.array([[0, 0, 10, 10], [5, 0, 15, 10], [20, 20, 30, 30]]))
    assert iou == pytest.approx(np.array([[1.0, 50 / 150, 0.0]]))


def test_iou_of_touching_and_degenerate_boxes_is_zero():
    iou = iou_matrix(np.array([[0, 0, 10, 10], [3, 3, 3, 3]]), np.array([[10, 0, 20, 10], [3, 3, 3, 3]]))
    assert np.all(iou == 0.0)


def test_no_overlap_gives_unknown():
    d = dets(([50, 50, 60, 60], "person", 0.9))
    out = assign_classes(np.array([[0, 0, 10, 10]]), d, iou_threshold=0.3)
    assert out[0].class_name == "unknown" and out[0].detection_index is None


def test_threshold_is_strict():
    box = np.array([[0, 0, 10, 10]])
    half = dets(([5, 0, 15, 10], "cup", 0.9))  # IoU exactly 1/3
    assert assign_classes(box, half, iou_threshold=1 / 3)[0].class_name == "unknown"
    assert assign_classes(box, half, iou_threshold=1 / 3 - 1e-9)[0].class_name == "cup"


def test_best_iou_wins_and_ties_go_to_higher_score():
    box = np.array([[0, 0, 10, 10]])
    d = dets(([0, 0, 10, 10], "chair", 0.4), ([0, 0, 10, 12], "couch", 0.99), ([0, 0, 10, 10], "person", 0.8))
    m = assign_classes(box, d, iou_threshold=0.5)[0]
    assert (m.class_name, m.detection_index, m.iou) == ("person", 2, 1.0)


def test_low_score_detections_are_ignored():
    box = np.array([[0, 0, 10, 10]])
    m = assign_classes(box, dets(([0, 0, 10, 10], "tv", 0.1)), iou_threshold=0.5, min_score=0.3)[0]
    assert m.class_name == "unknown"


def test_empty_inputs():
    assert assign_classes(np.zeros((0, 4)), dets(([0, 0, 1, 1], "cup", 1.0)), iou_threshold=0.5) == []
    out = assign_classes(np.array([[0, 0, 5, 5], [1, 1, 2, 2]]), Detections.empty(), iou_threshold=0.5)
    assert [m.class_name for m in out] == ["unknown", "unknown"]
    assert iou_matrix(np.zeros((0, 4)), np.zeros((3, 4))).shape == (0, 3)


def test_one_detection_may_name_two_blobs():
    boxes = np.array([[0, 0, 10, 20], [0, 0, 10, 18]])
    out = assign_classes(boxes, dets(([0, 0, 10, 19], "person", 0.9)), iou_threshold=0.5)
    assert [m.class_name for m in out] == ["person", "person"]
