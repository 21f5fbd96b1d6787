"""Table II on a small sim-format log written in code: a golden table with tolerances, and the CLI."""

import json

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.evaluate.background import evaluate_background
from hiper_cli.perceive.logs import TumWriter
from tests._bg_scenes import CAMERA, SceneBox, box_room, look_at, make_frame

TABLE = SceneBox(20, "table", (1.0, 3.2, 0.71), (2.2, 4.0, 0.75))
SHELF = SceneBox(21, "shelf", (4.2, 4.6, 0.0), (5.2, 5.0, 1.4))
DOOR = SceneBox(22, "door", (2.6, 5.02, 0.0), (3.5, 5.06, 2.0))
PERSON = SceneBox(23, "person", (4.6, 1.2, 0.0), (5.1, 1.5, 1.75))


def _scene():
    return [*box_room(door=(2.6, 3.5, 2.0)), TABLE, SHELF, DOOR, PERSON]


def _poses():
    center = (3.0, 2.5, 1.2)
    poses = []
    for k in range(12):
        a = 2 * np.pi * k / 12
        tilt = 0.4 if k % 2 == 0 else -0.4
        poses.append(look_at(center, (center[0] + np.cos(a), center[1] + np.sin(a), center[2] + tilt)))
    poses.append(look_at((2.8, 1.5, 1.3), (1.6, 3.6, 0.5)))  # the table
    return poses


def _truth_entry(box, state="static"):
    lo, hi = np.array(box.lo), np.array(box.hi)
    layer = "background" if box.class_name in ("wall", "floor", "ceiling", "table", "door") else "foreground"
    return {"id": box.id, "name": f"{box.class_name}_{box.id}", "class": box.class_name, "layer": layer,
            "state": state, "box": {"center_m": ((lo + hi) / 2).tolist(), "extent_m": (hi - lo).tolist(),
                                    "R": np.eye(3).tolist()}, "plane": None, "speed_mps": None}


@pytest.fixture(scope="module")
def sim_log(tmp_path_factory):
    root = tmp_path_factory.mktemp("bglog")
    scene = _scene()
    writer = TumWriter(root, CAMERA)
    (root / "gt" / "instance_ids").mkdir(parents=True)
    poses = _poses()
    for i, T in enumerate(poses):
        frame = make_frame(scene, T, pose_id=i, stamp_s=0.5 * i, noise_m=0.0015)
        stem = writer.write(frame)
        cv2.imwrite(str(root / "gt" / "instance_ids" / f"{stem}.png"), frame.extras["gt_ids"])
    writer.close()
    entries = {}
    for box in scene:  # the doorway wall is three boxes with one id: keep the first
        entries.setdefault(box.id, _truth_entry(box, "dynamic" if box.class_name == "person" else "static"))
    world = {"world": "boxroom", "seed": 0, "rate_hz": 2.0, "instances": list(entries.values()),
             "phases": [{"name": "mapping", "t_start_s": 0.0, "t_end_s": 0.5 * len(poses)}]}
    (root / "gt" / "world.json").write_text(json.dumps(world))
    return root


def test_golden_table(sim_log):
    r = evaluate_background(sim_log)
    assert r.keyframes == r.frames == 13
    # golden numbers of this scene, with tolerances: a regression fails loudly
    assert r.static_precision == 1.0
    assert r.semantic_precision >= 0.9
    assert r.walls_fp == 0 and r.tables_fp == 0 and r.door_fp == 0 and r.furniture_fp == 0
    assert r.truth_walls_found == 4 and r.truth_tables_found == 1
    assert 4 <= r.walls_tp <= 6
    assert r.floors_tp == 1 and r.ceilings_tp == 1
    assert r.distance_mean_m < 0.01 and r.distance_std_m < 0.01
    assert 20 <= r.observations <= 60
    assert 0 < r.time_mean_s < 0.5


def test_cli_prints_json_and_table(sim_log):
    runner = CliRunner()
    result = runner.invoke(app, ["eval", "background", str(sim_log), "--json", "--max-frames", "3"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["keyframes"] == 3 and data["method"] == "fast"
    assert data["paper"] is None and set(data["targets"]) == {
        "static_precision", "semantic_precision", "distance_mean_m", "time_mean_s"}
    result = runner.invoke(app, ["eval", "background", str(sim_log), "--max-frames", "2"])
    assert result.exit_code == 0 and "Precision semantics" in result.output


def test_cli_errors_name_the_file(tmp_path):
    result = CliRunner().invoke(app, ["eval", "background", str(tmp_path)])
    assert result.exit_code != 0
    assert "world.json" in result.output
    result = CliRunner().invoke(app, ["eval", "background", str(tmp_path), "--method", "magic"])
    assert result.exit_code != 0


def test_json_export_gives_each_plane_its_equation(sim_log, tmp_path):
    """A reader that ignores the box's axes still learns which way a wall faces: each
    background instance carries its plane, and the walls' planes are the room's inner faces."""
    kb = tmp_path / "kb"
    runner = CliRunner()
    result = runner.invoke(app, ["perceive", str(sim_log), "--kb", str(kb), "--stages", "background"])
    assert result.exit_code == 0, result.output
    out = tmp_path / "scene.json"
    assert runner.invoke(app, ["export", str(out), "--kb", str(kb)]).exit_code == 0
    instances = json.loads(out.read_text())["instances"]
    walls = [i for i in instances if i["class"] == "wall"]
    assert walls and all(i["plane"] is None for i in instances if i["layer"] == "foreground")
    inner_faces = {(0, 0.0), (0, 6.0), (1, 0.0), (1, 5.0)}  # (axis, coordinate) of box_room's walls
    for wall in walls:
        a, b, c, d = wall["plane"]
        n = np.array([a, b, c])
        assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-6) and abs(c) < 0.05
        axis = int(np.argmax(np.abs(n)))
        coordinate = -d / n[axis]
        assert min(abs(coordinate - x) for ax, x in inner_faces if ax == axis) < 0.03, wall
        assert abs(n @ np.array(wall["box"]["center_m"]) + d) < 0.03  # the box lies on its plane
    floor = next(i for i in instances if i["class"] == "floor")
    assert floor["plane"][2] == pytest.approx(1.0, abs=0.01) and abs(floor["plane"][3]) < 0.03
