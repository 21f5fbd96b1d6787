"""Detectors: the registry, YOLOX decoding and letterbox, YOLOv8 decoding, replayed detections."""

import json
from pathlib import Path

import numpy as np
import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect import make_detector
from hiper_cli.perceive.detect._onnx import COCO_NAMES, letterbox, nms
from hiper_cli.perceive.detect.yolo_onnx import decode_yolov8, parse_names
from hiper_cli.perceive.detect.yolox import decode_yolox, find_yolox_model
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAM = CameraIntrinsics(640, 480, 525.0, 525.0, 319.5, 239.5)


def frame(rgb=None, stamp=0.0, detections=None):
    rgb = np.zeros((480, 640, 3), np.uint8) if rgb is None else rgb
    return Frame(stamp, rgb, np.zeros((480, 640), np.float32), CAM, np.eye(4), 0, detections=detections)


def test_unknown_detector_lists_the_known_ones():
    expected = "unknown detector 'yolo9'; expected one of yolox, onnx:PATH, log, truth"
    with pytest.raises(ConfigError, match=expected):
        make_detector("yolo9")


def test_truth_detector_needs_a_log_and_onnx_needs_a_file(tmp_path):
    with pytest.raises(ConfigError, match="needs the log folder"):
        make_detector("truth")
    with pytest.raises(ConfigError, match=r"ONNX model not found"):
        make_detector(f"onnx:{tmp_path / 'missing.onnx'}")
    with pytest.raises(ConfigError, match=r"gt/world\.json: not found"):
        make_detector("truth", log_path=tmp_path)


def test_missing_yolox_model_says_where_to_download(tmp_path, monkeypatch):
    monkeypatch.setenv("HIPER_MODELS", str(tmp_path))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    with pytest.raises(ConfigError, match=r"Megvii-BaseDetection/YOLOX/releases/download/0\.1\.1rc0"):
        find_yolox_model(tmp_path / "nope.onnx", search_roots=[])


def test_letterbox_top_left_and_centred():
    img = np.full((480, 640, 3), 7, np.uint8)
    canvas, r, pad = letterbox(img, (416, 416), centre=False)
    assert r == pytest.approx(0.65) and pad == (0.0, 0.0)
    assert canvas[0, 0, 0] == 7 and canvas[-1, 0, 0] == 114
    assert canvas[311, 0, 0] == 7 and canvas[312, 0, 0] == 114
    canvas, r, pad = letterbox(img, (640, 640), centre=True)
    assert r == 1.0 and pad == (0.0, 80.0)
    assert canvas[79, 0, 0] == 114 and canvas[80, 0, 0] == 7


def test_yolox_decoding_maps_a_cell_back_to_image_pixels():
    out = np.zeros((1, 3549, 85), np.float32)
    # stride-16 grid starts after 52*52 rows; cell (gx=10, gy=5) of the 26x26 grid
    row = 52 * 52 + 5 * 26 + 10
    out[0, row, :5] = [0.5, 0.5, np.log(4.0), np.log(8.0), 0.9]
    out[0, row, 5 + 41] = 0.8  # cup
    out[0, row + 1, :5] = [0.5, 0.5, np.log(4.0), np.log(8.0), 0.9]  # a duplicate next door
    out[0, row + 1, 5 + 41] = 0.7
    xyxy, cls, scores = decode_yolox(out, (416, 416), 0.65, score_threshold=0.3, nms_iou=0.45)
    assert list(cls) == [41] and COCO_NAMES[41] == "cup"
    cx, cy, w, h = (10.5 * 16) / 0.65, (5.5 * 16) / 0.65, 64 / 0.65, 128 / 0.65
    assert xyxy[0] == pytest.approx([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2])
    assert scores[0] == pytest.approx(0.72)


def test_yolov8_decoding_and_names():
    out = np.zeros((1, 4 + 3, 5), np.float32)
    out[0, :4, 2] = [320, 320, 100, 50]
    out[0, 4 + 1, 2] = 0.9
    xyxy, cls, _ = decode_yolov8(out, 1.0, (0.0, 80.0), score_threshold=0.25, nms_iou=0.45)
    assert xyxy.tolist() == [[270.0, 215.0, 370.0, 265.0]] and cls.tolist() == [1]
    assert parse_names({"names": "{0: 'cat', 1: 'robot', 2: 'cup'}"}, 3) == ("cat", "robot", "cup")
    assert parse_names({}, 80) == COCO_NAMES and parse_names({}, 2) == ("class_0", "class_1")
    with pytest.raises(ConfigError, match=r"expected \[1, 4 \+ classes, N\]"):
        decode_yolov8(np.zeros((1, 4, 10)), 1.0, (0, 0), score_threshold=0.3, nms_iou=0.4)


def test_nms_is_class_wise():
    xyxy = np.array([[0, 0, 10, 10], [1, 1, 10, 10], [0, 0, 10, 10]], float)
    keep = nms(xyxy, np.array([0.9, 0.8, 0.7]), np.array([0, 0, 1]), 0.45)
    assert keep.tolist() == [0, 2]


def test_log_detector_replays_frame_detections():
    d = Detections.from_records([{"xyxy": [1, 2, 3, 4], "class": "cup", "score": 0.2}])
    det = make_detector("log", min_score=0.1)
    assert det.detect(frame(detections=d)).to_records() == d.to_records()
    assert len(det.detect(frame())) == 0


def test_truth_detector_matches_by_stamp_and_drops_instance_ids(tmp_path):
    gt = tmp_path / "gt"
    gt.mkdir()
    (gt / "world.json").write_text(json.dumps({"world": "t", "seed": 1, "instances": [], "phases": []}))
    lines = [
        {"stamp_s": 1.0, "detections": [{"xyxy": [0, 0, 5, 5], "class": "person", "score": 0.9,
                                         "instance_id": 3}]},
        {"stamp_s": 1.1, "detections": []},
    ]
    (gt / "detections.jsonl").write_text("\n".join(json.dumps(x) for x in lines) + "\n")
    det = make_detector("truth", log_path=tmp_path)
    expected = [{"xyxy": [0, 0, 5, 5], "class": "person", "score": 0.9}]
    assert det.detect(frame(stamp=1.0001)).to_records() == expected
    assert len(det.detect(frame(stamp=1.1))) == 0
    assert len(det.detect(frame(stamp=5.0))) == 0


def _sample_photo():
    try:
        import matplotlib.cbook as cbook

        path = Path(cbook.get_sample_data("grace_hopper.jpg", asfileobj=False))
    except Exception:
        return None
    return path if path.is_file() else None


def test_yolox_finds_the_person_in_a_photo():
    try:
        find_yolox_model()
    except ConfigError:
        pytest.skip("YOLOX-Nano model absent (set HIPER_MODELS; see docs/foreground.md)")
    photo = _sample_photo()
    if photo is None:
        pytest.skip("matplotlib's sample photo grace_hopper.jpg is not installed")
    import cv2

    rgb = np.ascontiguousarray(cv2.resize(cv2.imread(str(photo))[:, :, ::-1], (640, 480)))
    dets = make_detector("yolox").detect(frame(rgb))
    people = [i for i, n in enumerate(dets.class_names) if n == "person"]
    assert people, dets.to_records()
    x0, y0, x1, y1 = dets.xyxy[people[0]]
    assert (x1 - x0) * (y1 - y0) > 0.5 * 640 * 480 and dets.scores[people[0]] > 0.7
