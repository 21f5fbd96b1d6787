"""hiper bench: configurations, the C5 box projection, navigation, and the --quick run end to end."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.bench import CONFIGS, parse_configs
from hiper_cli.bench.baseline import project_box, project_detections
from hiper_cli.bench.nav import NavConfig, NavMap
from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.sim import make_world
from hiper_cli.types import CameraIntrinsics, Detections, Frame


def _frame(depth: float) -> Frame:
    cam = CameraIntrinsics(width=64, height=48, fx=50.0, fy=50.0, cx=32.0, cy=24.0)
    depth_m = np.full((48, 64), depth, np.float32)
    return Frame(0.0, np.zeros((48, 64, 3), np.uint8), depth_m, cam, np.eye(4), 0)


def test_configs_follow_the_paper_table():
    assert [c.name for c in parse_configs(None)] == ["C1", "C2", "C3", "C4", "C5"]
    assert CONFIGS["C1"].features and not CONFIGS["C2"].features and CONFIGS["C2"].heatmaps
    assert not CONFIGS["C3"].heatmaps and CONFIGS["C3"].background and not CONFIGS["C4"].background
    assert not CONFIGS["C5"].foreground
    with pytest.raises(ConfigError, match="expected names from C1"):
        parse_configs("C1,C9")


def test_box_projection_uses_depth_then_the_class_height():
    box = np.array([22.0, 14.0, 42.0, 34.0])  # centred on the principal point
    p = project_box(_frame(3.0), box, "bottle")
    assert p is not None and np.allclose(p, [0.0, 0.0, 3.0], atol=0.2)
    far = project_box(_frame(0.0), np.array([30.0, 10.0, 34.0, 38.0]), "person")  # no depth: 1.75 m tall
    assert far is not None and far[2] == pytest.approx(50.0 * 1.75 / 28.0)
    frames = [(_frame(3.0), Detections(box[None], ("bottle",), np.ones(1)))] * 3
    run = project_detections(frames)
    assert len(run.instances) == 1 and run.observations == 3


def test_nav_plans_around_walls_and_sees_through_doorways():
    nav = NavMap(make_world("house", 0))
    a, b = nav.world.waypoints[0], nav.world.waypoints[5]
    path, length = nav.astar(a, b)
    assert length >= math.dist(path[0], path[-1]) - 1e-6
    assert nav.detect_range_m(1.75, needs_depth=True) == NavConfig().sensor_range_m
    assert nav.detect_range_m(1.75, needs_depth=False) > 20.0
    x, y = a
    assert nav.sees((x, y), 0.0, (x + 1.0, y), 5.0) or not nav.line_of_sight((x, y), (x + 1.0, y))
    assert not nav.sees((x, y), 0.0, (x - 1.0, y), 5.0)  # behind the camera


def test_quick_bench_writes_a_report(tmp_path):
    runner = CliRunner()
    out = tmp_path / "bench"
    quick = ["bench", "--quick", "--log-s", "60", "--mapping-s", "20"]  # shorter still: < 60 s
    result = runner.invoke(app, [*quick, "-o", str(out), "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert set(summary["tasks"]["house"]) == {"C1", "C2", "C3", "C4", "C5"}
    cell = summary["tasks"]["house"]["C1"]["T1"]
    assert cell["runs"] == 2 and len(cell["times_s"]) == 2
    assert summary["perception"]["house"]["table2"] is not None
    assert summary["settings"]["run_seeds"]["house"]
    text = (out / "report.md").read_text()
    assert "hiper bench --quick" in text or "hiper bench" in text
    for png in ("times_house.png", "success_house.png"):
        assert (out / png).stat().st_size > 1000 and png in text


def test_bench_options_are_checked():
    runner = CliRunner()
    bad = runner.invoke(app, ["bench", "-o", "/tmp/never", "--runs", "0"])
    assert bad.exit_code != 0 and "--runs" in bad.output
    bad = runner.invoke(app, ["bench", "-o", "/tmp/never", "--worlds", "moon", "--runs", "1"])
    assert bad.exit_code != 0 and "expected some of house" in bad.output


def test_grasp_aims_at_the_bottle_instance_nearest_the_bottle_found():
    from hiper_cli.bench.perception import Knowledge
    from hiper_cli.bench.tasks import grasp_error

    truth = np.array([[1.39, 2.09, 0.87], [1.16, 1.85, 0.89]])
    # Instance 0 joined both bottles (its votes: mostly bottle 1, 0.27 m off it); instance 1
    # stands on bottle 0. Grasping bottle 0 aims at instance 1, whatever the votes said.
    bottles = np.array([[1.30, 2.09, 0.86], [1.40, 2.10, 0.87]])
    knowledge = Knowledge("C1", np.zeros((0, 7)), np.zeros(0, np.int64), None, bottles, None, [], [],
                          0.0, 0.0, True, [(1.30, 2.09, 0.272), (1.40, 2.10, 0.018)])
    error, source = grasp_error(knowledge, truth, (1.39, 2.09), None)
    assert error == pytest.approx(0.014, abs=0.002) and source == "this bottle's instance"
    error, _ = grasp_error(knowledge, truth, (1.16, 1.85), None)
    assert error == pytest.approx(0.27, abs=0.01)  # the merged instance is the nearest one
    far = Knowledge("C1", np.zeros((0, 7)), np.zeros(0, np.int64), None, bottles + 5.0, None, [], [],
                    0.0, 0.0, True, [(6.3, 7.1, 0.02), (6.4, 7.1, 0.04)])
    error, source = grasp_error(far, truth, (1.39, 2.09), 0.5)
    assert (error, source) == (pytest.approx(0.03), "median over the bottle instances")
