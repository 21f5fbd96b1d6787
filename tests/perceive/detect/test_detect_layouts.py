"""Detectors users have: tiny ONNX graphs of each output layout, built with the ``onnx`` package,
run through the whole detector (preprocessing, onnxruntime, layout, decoding, class names).

Each graph returns a fixed tensor (plus 0 x the sum of its input, so that the input is used);
the boxes, classes and scores it must decode to are worked out by hand in each test.
"""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect import make_detector
from hiper_cli.perceive.detect.layouts import coco91_names, grid_cells, identify_layout
from hiper_cli.perceive.detect.onnx_model import OnnxDetector
from hiper_cli.types import CameraIntrinsics, Frame

onnx = pytest.importorskip("onnx", reason="the onnx package builds the test graphs (pip install -e '.[dev]')")
from onnx import TensorProto, helper, numpy_helper  # noqa: E402

SIDE = 64  # input side: grid cells 8x8 + 4x4 + 2x2 = 84
CELLS = grid_cells((SIDE, SIDE))
NAMES = "{0: 'cat', 1: 'robot', 2: 'cup'}"


def _graph(path, outputs: dict[str, np.ndarray], names: str | None = None, side: int = SIDE):
    """An ONNX model with input ``images`` [1, 3, side, side] whose outputs are ``outputs``."""
    nodes = [helper.make_node("ReduceSum", ["images"], ["total"], keepdims=0),
             helper.make_node("Constant", [], ["zero"], value=numpy_helper.from_array(np.float32(0), "zero")),
             helper.make_node("Mul", ["total", "zero"], ["nothing"])]
    outs = []
    for name, value in outputs.items():
        const = numpy_helper.from_array(value.astype(np.float32), f"{name}_value")
        nodes.append(helper.make_node("Constant", [], [f"{name}_const"], value=const))
        nodes.append(helper.make_node("Add", [f"{name}_const", "nothing"], [name]))
        outs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, list(value.shape)))
    images = helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, side, side])
    model = helper.make_model(helper.make_graph(nodes, "tiny", [images], outs),
                              opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    if names is not None:
        helper.set_model_props(model, {"names": names})
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path


def _frame(width=128, height=96):
    cam = CameraIntrinsics(width, height, 100.0, 100.0, width / 2, height / 2)
    return Frame(0.0, np.zeros((height, width, 3), np.uint8), np.zeros((height, width), np.float32), cam,
                 np.eye(4), 0)


def _records(det):
    return [(r["class"], [round(v, 3) for v in r["xyxy"]], round(r["score"], 4))
            for r in det.detect(_frame()).to_records()]


# A 128x96 frame letterboxed into 64x64: scale 0.5; centred (YOLOv5/v8) it is pasted 8 px down.


def test_yolox_layout_any_size_with_a_labels_file(tmp_path):
    out = np.zeros((1, CELLS, 5 + 3), np.float32)
    row = 8 * 8 + 1 * 4 + 2  # stride-16 grid (4x4), cell gx=2, gy=1
    out[0, row, :5] = [0.5, 0.5, np.log(2.0), np.log(1.0), 0.9]
    out[0, row, 5 + 2] = 0.8
    model = _graph(tmp_path / "x.onnx", {"output": out})
    (tmp_path / "labels.txt").write_text("cat\nrobot\nmug\n")
    det = OnnxDetector(model)
    assert det.layout == "yolox" and det.class_names == ("cat", "robot", "mug")
    # centre (2.5*16, 1.5*16) = (40, 24), size 32x16 input px; top-left letterbox, / 0.5
    assert _records(det) == [("mug", [48.0, 32.0, 112.0, 64.0], 0.72)]


def test_yolov5_layout_with_names_metadata(tmp_path):
    out = np.zeros((1, 3 * CELLS, 5 + 3), np.float32)
    out[0, 7, :5] = [32, 32, 16, 8, 0.9]
    out[0, 7, 5 + 1] = 0.8
    out[0, 8, :5] = [33, 32, 16, 8, 0.9]  # the same object again: suppressed
    out[0, 8, 5 + 1] = 0.5
    det = OnnxDetector(_graph(tmp_path / "v5.onnx", {"output0": out}, NAMES))
    assert det.layout == "yolov5" and det.class_names == ("cat", "robot", "cup")
    # input box [24, 28, 40, 36]; minus the 8 px pad, / 0.5
    assert _records(det) == [("robot", [48.0, 40.0, 80.0, 56.0], 0.72)]


def test_yolov8_layout(tmp_path):
    out = np.zeros((1, 4 + 3, CELLS), np.float32)
    out[0, :4, 5] = [16, 40, 8, 16]
    out[0, 4 + 2, 5] = 0.6
    det = OnnxDetector(_graph(tmp_path / "v8.onnx", {"output0": out}, NAMES))
    assert det.layout == "yolov8"
    assert _records(det) == [("cup", [24.0, 48.0, 40.0, 80.0], 0.6)]


def test_rtdetr_layout_one_output_normalised(tmp_path):
    out = np.zeros((1, 10, 4 + 3), np.float32)
    out[0, 3, :4] = [0.5, 0.25, 0.25, 0.5]
    out[0, 3, 4 + 0] = 0.7
    out[0, 4, :4] = [0.1, 0.1, 0.1, 0.1]
    out[0, 4, 4 + 1] = 0.2  # below the threshold
    det = OnnxDetector(_graph(tmp_path / "rtdetr.onnx", {"output0": out}, NAMES))
    assert det.layout == "detr"
    # resized, not letterboxed: x by the frame width 128, y by its height 96
    assert _records(det) == [("cat", [48.0, 0.0, 80.0, 48.0], 0.7)]


def test_rfdetr_layout_boxes_and_logits_in_coco_ids(tmp_path):
    boxes = np.zeros((1, 5, 4), np.float32)
    logits = np.full((1, 5, 91), -10.0, np.float32)
    boxes[0, 1] = [0.25, 0.5, 0.5, 0.5]
    logits[0, 1, 47] = 2.0  # COCO category id 47: cup
    det = OnnxDetector(_graph(tmp_path / "rfdetr.onnx", {"dets": boxes, "labels": logits}))
    assert det.layout == "detr" and det.class_names[47] == "cup" and coco91_names()[1] == "person"
    score = round(1.0 / (1.0 + np.exp(-2.0)), 4)
    assert _records(det) == [("cup", [0.0, 24.0, 64.0, 72.0], score)]


def test_another_layout_is_one_error_naming_the_layouts_read(tmp_path):
    model = _graph(tmp_path / "cls.onnx", {"logits": np.zeros((1, 1000), np.float32)})
    expected = r"cls\.onnx: outputs \[1, 1000\] at input 64x64 are not a detector layout hiper reads \(yolox"
    with pytest.raises(ConfigError, match=expected):
        make_detector(f"onnx:{model}")
    result = CliRunner().invoke(app, ["models", "add", str(model), "--dir", str(tmp_path / "m")])
    assert result.exit_code == 2 and "yolov8/YOLO11 [1, 4+C, cells]" in result.output
    assert len(result.output.strip().splitlines()) == 1 and not (tmp_path / "m").exists()
    with pytest.raises(ConfigError, match="are not a detector layout"):
        identify_layout([(1, 84, 8400, 2)], (640, 640))


def test_catalog_names_and_added_models_are_detectors(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setenv("HIPER_MODELS", str(tmp_path / "models"))
    out = np.zeros((1, 4 + 3, CELLS), np.float32)
    out[0, :4, 0] = [32, 32, 8, 8]
    out[0, 4 + 1, 0] = 0.9
    (tmp_path / "models" / "yolo11n").mkdir(parents=True)
    _graph(tmp_path / "models" / "yolo11n" / "yolo11n.onnx", {"output0": out}, NAMES)
    det = make_detector("yolo11n")
    assert det.name == "yolo11n" and _records(det) == [("robot", [56.0, 40.0, 72.0, 56.0], 0.9)]
    fetch = r"model 'yolox_s' not found .*'hiper models fetch yolox_s --trust-unverified'"
    with pytest.raises(ConfigError, match=fetch):
        make_detector("yolox_s")
    mine = _graph(tmp_path / "shelf_bot.onnx", {"output0": out}, NAMES)
    result = CliRunner().invoke(app, ["models", "add", str(mine), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["layout"] == "yolov8"
    assert make_detector("shelf_bot").detect(_frame()).class_names == ("robot",)


def test_the_real_yolox_nano_is_read_by_its_layout_alone():
    """``onnx:PATH`` on the YOLOX-Nano file tells its layout and finds what ``yolox`` finds."""
    from hiper_cli.perceive.detect.catalog import locate

    path = locate("yolox_nano")
    if path is None:
        pytest.skip("YOLOX-Nano model absent (run 'hiper models fetch yolox' or set HIPER_MODELS)")
    try:
        import matplotlib.cbook as cbook

        photo = cbook.get_sample_data("grace_hopper.jpg", asfileobj=False)
    except Exception:
        pytest.skip("matplotlib's sample photo grace_hopper.jpg is not installed")
    import cv2

    rgb = np.ascontiguousarray(cv2.resize(cv2.imread(str(photo))[:, :, ::-1], (128, 96)))
    frame = _frame()
    frame = Frame(0.0, rgb, frame.depth_m, frame.camera, np.eye(4), 0)
    generic = make_detector(f"onnx:{path}", score_threshold=0.05)
    assert generic.layout == "yolox" and generic.size_hw == (416, 416) and len(generic.class_names) == 80
    a = generic.detect(frame)
    b = make_detector("yolox", model_path=path, score_threshold=0.05).detect(frame)
    assert "person" in a.class_names
    assert a.class_names == b.class_names and np.allclose(a.xyxy, b.xyxy) and np.allclose(a.scores, b.scores)


def test_a_post_processed_output_is_not_misread_as_detr(tmp_path):
    """YOLOv10-style [1, 300, 6] (box, score, class) with 80 names is refused, not decoded as 2 classes."""
    names = repr(dict(enumerate(["person"] * 80)))
    model = _graph(tmp_path / "v10.onnx", {"output0": np.zeros((1, 300, 6), np.float32)}, names, side=640)
    with pytest.raises(ConfigError, match=r"read as layout detr give 2 classes but the model names 80"):
        OnnxDetector(model)
