"""``hiper eval detector``: the detector's ceiling over the frames with per-pixel truth."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.evaluate.detector import _Object, _score_frame, detector_ceiling, recall_beside_ceiling
from hiper_cli.perceive.detect import make_detector
from hiper_cli.perceive.logs import open_log
from hiper_cli.types import Detections
from tests import REPO_ROOT, WORLDS

FIXTURE = REPO_ROOT / "fixtures" / "house_small"


def _ids_with_chair() -> np.ndarray:
    ids = np.zeros((100, 100), dtype=np.uint16)
    ids[20:60, 30:70] = 7  # a 40 × 40 chair
    return ids


@pytest.mark.parametrize(("box", "cls", "found"), [
    ([30, 20, 70, 60], "chair", True),    # exact box
    ([30, 20, 70, 50], "chair", True),    # IoU 0.75
    ([30, 20, 50, 50], "chair", False),   # IoU 0.375
    ([30, 20, 70, 60], "couch", False),   # right box, wrong class
    ([30, 20, 70, 60], "bench", True),    # an alt class
])
def test_found_needs_its_class_and_iou_of_a_half(box, cls, found):
    objects = {7: _Object(7, "chair", frozenset({"chair", "bench"}))}
    dets = Detections(np.array([box], dtype=np.float64), (cls,), np.array([0.9]))
    _score_frame(_ids_with_chair(), dets, objects)
    assert objects[7].frames_shown == 1 and objects[7].frames_found == int(found)


def test_dining_table_names_a_table_and_tiny_views_do_not_count():
    ids = np.zeros((100, 100), dtype=np.uint16)
    ids[0:10, 0:10] = 3  # 100 px: below the 200 px a frame needs to show it
    ids[50:90, 10:90] = 4
    objects = {3: _Object(3, "chair", frozenset({"chair"})), 4: _Object(4, "table", frozenset({"table"}))}
    boxes = np.array([[0, 0, 10, 10], [10, 50, 90, 90]], dtype=np.float64)
    dets = Detections(boxes, ("chair", "dining table"), np.array([0.9, 0.8]))
    _score_frame(ids, dets, objects)
    assert objects[3].frames_shown == 0 and objects[4].frames_found == 1


def test_truth_detector_on_the_fixture():
    result = detector_ceiling(FIXTURE, open_log(FIXTURE), make_detector("truth", log_path=FIXTURE))
    data = result.to_dict()
    assert data["frames"] == 60
    assert data["total"]["seen_clearly"] == 4 and data["total"]["found"] == 3
    assert data["per_class"]["chair"] == {"seen_clearly": 2, "found": 2, "frames_shown": 43,
                                          "frames_found": 39, "frame_share": 0.907}
    beside = recall_beside_ceiling(result, [o["id"] for o in data["objects"] if o["class"] == "chair"])
    assert (beside["seen_clearly"], beside["detector_found"], beside["hiper_found"]) == (4, 3, 2)
    assert beside["hiper_found_of_detector_found"] == 2


def test_cli_json_and_table(tmp_path):
    runner = CliRunner()
    result = runner.invoke(app, ["eval", "detector", str(FIXTURE), "--detector", "log", "--max-frames", "5",
                                 "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["frames"] == 5 and data["total"] == {"found": 0, "seen_clearly": 4, "frame_share": 0.0}
    table = runner.invoke(app, ["eval", "detector", str(FIXTURE), "--detector", "truth"])
    assert table.exit_code == 0 and "total" in table.output and "chair" in table.output


def test_cli_errors_are_one_line(tmp_path):
    runner = CliRunner()
    result = runner.invoke(app, ["eval", "detector", str(tmp_path), "--detector", "log"])
    assert result.exit_code != 0 and "Traceback" not in result.output
    unknown = runner.invoke(app, ["eval", "detector", str(FIXTURE), "--detector", "detr"])
    assert unknown.exit_code != 0 and "unknown detector 'detr'" in unknown.output


@pytest.mark.skipif(not (WORLDS / "bookstore" / "gt").is_dir(),
                    reason=f"needs the shared bookstore at {WORLDS} (set HIPER_WORLDS)")
def test_yolox_finds_about_7_of_the_27_nameable_objects_of_the_bookstore():
    from hiper_cli.perceive.detect.yolox import find_yolox_model

    try:
        find_yolox_model()
    except ConfigError:
        pytest.skip("YOLOX-Nano model absent (set HIPER_MODELS)")
    log = WORLDS / "bookstore"
    result = detector_ceiling(log, open_log(log), make_detector("yolox"))
    total = result.to_dict()["total"]
    assert total["seen_clearly"] == 27  # the reference scorer's nameable objects seen clearly
    assert abs(total["found"] - 7) <= 2  # counted independently: 7


def test_eval_scene_prints_the_ceiling_beside_hipers_recall(tmp_path):
    runner = CliRunner()
    kb = tmp_path / "fx.hiper"
    perceived = runner.invoke(app, ["perceive", str(FIXTURE), "--kb", str(kb), "--detector", "truth"])
    assert perceived.exit_code == 0, perceived.output
    scene = ["eval", "scene", str(FIXTURE), "--kb", str(kb), "--ceiling", "truth"]
    result = runner.invoke(app, [*scene, "--json"])
    assert result.exit_code == 0, result.output
    ceiling = json.loads(result.output)["detector_ceiling"]
    assert (ceiling["seen_clearly"], ceiling["detector_found"]) == (4, 3)
    assert ceiling["hiper_found_of_detector_found"] <= ceiling["detector_found"]
    assert ceiling["per_class"]["table"]["detector_found"] == 0  # tables: hiper finds them as planes
    text = runner.invoke(app, scene)
    assert "the detector (truth) alone 3" in " ".join(text.output.split())
