"""Motion needs evidence: a static object's stored speed is exactly 0 and its path a point,
whatever its partial views did to the filter; an object that moved keeps its speed. A tiny
ray-cast scene for the principle, and the demo's knowledge base (fixtures/house_small perceived
as scripts/demo.sh does) for a whole log."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.graph.ontology import speed_mps
from hiper_cli.perceive.detect.yolox import find_yolox_model
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import World
from tests import REPO_ROOT
from tests.fg_scene import background_instances, chair, make_frame, pose_looking_x, room

RATE_HZ = 30.0
FIXTURE = REPO_ROOT / "fixtures" / "house_small"


def _instances_after(frames):
    stage = ForegroundStage(detector="log", pixel_step=2)
    world, _ = run_stages(frames, [stage], World(background=background_instances(room())))
    return list(world.foreground.values())


def _doc(inst):
    return {"state": inst.state, "data": inst.data}


def test_a_chair_seen_in_parts_as_the_camera_drives_past_is_static_with_speed_zero():
    # The camera drives sideways 1.6 m past a chair 3 m ahead: it enters the image at one edge
    # and leaves at the other, so each view shows a different part and the blob's centroid slides.
    frames = [make_frame([*room(), chair(11, 3.0, 0.0)], pose_looking_x(0.0, 1.6 - 3.2 * k / 60),
                         k / RATE_HZ, k) for k in range(60)]
    (inst,) = _instances_after(frames)
    assert inst.class_name == "chair" and inst.state == "static"
    rows = np.asarray(inst.data["trajectory"])
    assert len(rows) >= 2
    assert np.all(rows[:, 4:7] == 0.0)  # no velocity ...
    assert np.all(rows[:, 1:4] == rows[0, 1:4])  # ... and one place, the fused centre
    assert rows[0, 1:4] == pytest.approx(inst.box.center_m)
    assert speed_mps(_doc(inst)) == 0.0


def test_a_chair_pushed_across_the_view_is_dynamic_with_its_speed():
    pushed = [make_frame([*room(), chair(11, 4.0, 1.5 - 1.5 * k / 60)], pose_looking_x(), k / RATE_HZ, k)
              for k in range(60)]
    (inst,) = _instances_after(pushed)
    assert inst.state == "dynamic"
    assert speed_mps(_doc(inst)) == pytest.approx(0.75, abs=0.2)  # 1.5 m in 2 s


def test_the_demo_knowledge_base_has_no_static_object_with_a_speed(tmp_path):
    """scripts/demo.sh perceives fixtures/house_small with the default detector when its model
    is found, else with the log's own (noisy ground-truth) detections: both are checked when the
    model is found. The export is what a user reads: state and speed must agree."""
    detectors = ["truth"]
    try:
        find_yolox_model()
        detectors.append("yolox")
    except ConfigError:
        pass  # the truth detector alone, as the demo runs without the model
    runner = CliRunner()
    for detector in detectors:
        kb, out = tmp_path / f"{detector}.hiper", tmp_path / f"{detector}.json"
        result = runner.invoke(app, ["perceive", str(FIXTURE), "--kb", str(kb), "--detector", detector])
        assert result.exit_code == 0, result.output
        assert runner.invoke(app, ["export", str(out), "--kb", str(kb)]).exit_code == 0
        fg = [i for i in json.loads(out.read_text())["instances"] if i["layer"] == "foreground"]
        static = [i for i in fg if i["motion"] == "static"]  # export v2: "state" is present | removed
        assert static, f"{detector}: no static object at all"
        moving = [(i["class"], i["speed_mps"]) for i in static if i["speed_mps"] not in (None, 0.0)]
        assert moving == [], f"{detector}: static objects with a speed {moving}"
