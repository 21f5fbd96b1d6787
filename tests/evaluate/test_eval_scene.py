"""``hiper eval scene``: instances scored against a tiny generated realistic-world gt/ folder."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.evaluate.scene import score_scene
from hiper_cli.evaluate.surfaces import load_surfaces
from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.logs.truth import load_truth
from tests import WORLDS

WALK = [[1000.0 + 0.1 * k, 0.06 * k, 2.0, 0.85] for k in range(30)]  # 0.6 m/s along x


def _grid(lo, hi, step=0.1):
    axes = [np.arange(a, b + 1e-9, step) if b > a else np.array([a]) for a, b in zip(lo, hi, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def _write_gt(root: Path) -> None:
    gt = root / "gt"
    gt.mkdir(parents=True)
    # the stored wall plane is wrong on purpose: the scorer fits its own to the samples
    pieces = [(1, "B::floor_000", "floor", [-3, -3, 0], [3, 3, 0], [0, 0, 1, 0], 36.0),
              (2, "B::wall_001", "wall", [3, -3, 0], [3, 3, 3], [0.3, -0.4, -0.87, 2.6], 18.0),
              (3, "B::wall_misc", "wall", [-3, 3, 0], [-2.8, 3, 1], [0, 1, 0, -3], 0.2)]
    insts = [{"id": i, "name": n, "class": c, "layer": "background", "static": True, "aabb_min": lo,
              "aabb_max": hi, "plane": pl, "area_m2": a, "observed": True, "alt_classes": []}
             for i, n, c, lo, hi, pl, a in pieces]
    things = [(4, "chair_0", "chair", [1, -1, 0], [1.5, -0.5, 0.9]),
              (5, "shelf_0", "shelf", [2, 1, 0], [2.4, 2.5, 1.8])]
    insts += [{"id": i, "name": n, "class": c, "layer": "foreground", "static": True, "aabb_min": lo,
               "aabb_max": hi, "observed": True, "alt_classes": []} for i, n, c, lo, hi in things]
    insts.append({"id": 6, "name": "walker_0", "class": "person", "layer": "foreground", "static": False,
                  "aabb_min": [-0.3, 1.8, 0], "aabb_max": [2.0, 2.2, 1.7], "body_size": [0.5, 0.4, 1.7],
                  "speed_mps": 0.6, "active_from_t": 1000.0, "trajectory": WALK, "observed": True,
                  "alt_classes": []})
    doc = {"log": "tiny", "t0": 1000.0, "duration_s": 2.9, "seed": 1, "instances": insts}
    (gt / "instances.json").write_text(json.dumps(doc))
    parts = [(1, _grid([-3, -3, 0], [3, 3, 0]), [0, 0, 1]), (2, _grid([3, -3, 0], [3, 3, 3]), [-1, 0, 0]),
             (3, _grid([-3, 3, 0], [-2.8, 3, 1]), [0, -1, 0]),
             (4, _grid([1, -1, 0.45], [1.5, -0.5, 0.45]), [0, 0, 1]),
             (5, _grid([2, 1, 0], [2, 2.5, 1.8]), [-1, 0, 0])]
    xyz = np.concatenate([p for _, p, _ in parts])
    normal = np.concatenate([np.tile(np.array(n) * 127, (len(p), 1)) for _, p, n in parts]).astype(np.int8)
    ids = np.concatenate([np.full(len(p), i) for i, p, _ in parts]).astype(np.uint16)
    body = _grid([-0.2, 1.9, 0.3], [0.2, 2.1, 1.6])
    dyn = np.concatenate([body + np.array([x, 0.0, 0.0]) for x in (0.0, 1.0)])
    np.savez(gt / "surface_points.npz", static_xyz=xyz.astype(np.float32), static_normal=normal,
             static_id=ids, dynamic_xyz=dyn.astype(np.float32), dynamic_id=np.full(len(dyn), 6, np.uint16),
             dynamic_t=np.zeros(len(dyn), np.float32))


def _plane(cls, centre, extent, normal):
    n = np.asarray(normal, float)
    # box axes: in-plane u, v and the normal (a vertical plane: horizontal, up, normal)
    R = np.eye(3) if abs(n[2]) > 0.9 else np.column_stack([np.cross([0, 0, 1], n), [0, 0, 1], n])
    c = np.asarray(centre, float)
    return Instance("background", cls, Box3D(c, np.asarray(extent, float), R), 1000.0, 1001.0,
                    data={"plane_map": [*n, -float(n @ c)]})


def _thing(cls, centre, extent, state="static", trajectory=None):
    data = {"trajectory": trajectory} if trajectory is not None else {}
    return Instance("foreground", cls, Box3D(np.asarray(centre, float), np.asarray(extent, float)),
                    1000.0, 1002.0, state=state, data=data)


def _instances():
    track = [[t, x, y, z, 0.6, 0.0, 0.0] for t, x, y, z in WALK[::5]]
    return [
        _plane("floor", [0, 0, 0], [4, 4, 0.02], [0, 0, 1]),
        _plane("wall", [3, 0, 1.5], [4, 2, 0.02], [-1, 0, 0]),
        _plane("wall", [2, 1.75, 0.9], [1.4, 1.6, 0.02], [-1, 0, 0]),  # a shelf front
        _plane("wall", [0.0, 1.9, 0.9], [0.3, 1.2, 0.02], [0, -1, 0]),  # on the walker
        _thing("chair", [1.3, -0.7, 0.45], [0.5, 0.5, 0.9]),
        _thing("person", [1.0, 2.0, 0.85], [0.5, 0.4, 1.7], "dynamic", track),
        _thing("unknown", [-2, -2, 0.3], [0.3, 0.3, 0.3]),
        _thing("tv", [-2, 2, 1.0], [0.5, 0.1, 0.3]),
    ]


@pytest.fixture()
def tiny(tmp_path):
    _write_gt(tmp_path)
    return tmp_path


def test_background_scores(tiny):
    bg = score_scene(load_truth(tiny), load_surfaces(tiny), _instances())["background"]
    assert bg["instances"] == 4 and bg["on_unlabelled"] == 0
    assert bg["confusion"] == {"floor->floor": 1, "wall->person": 1, "wall->shelf": 1, "wall->wall": 1}
    assert bg["semantic_precision"] == pytest.approx(0.5)
    assert bg["static_precision"] == pytest.approx(0.75)
    assert bg["pieces"] == 2 and bg["coverage"] == pytest.approx(1.0)  # the misc piece is not counted
    assert bg["distance_centre_median_m"] == pytest.approx(0.0, abs=0.01)


def test_foreground_scores(tiny):
    fg = score_scene(load_truth(tiny), load_surfaces(tiny), _instances())["foreground"]
    assert (fg["tp"], fg["fp"], fg["fn_observed"]) == (2, 2, 1)
    assert fg["per_class"]["shelf"] == {"tp": 0, "fp": 0, "fn": 1}
    assert fg["classified_precision"] == pytest.approx(2 / 3) and fg["unknown"] == 1
    assert fg["centre_error_mean_m"] == pytest.approx(np.hypot(0.05, 0.05), abs=1e-6)
    assert fg["walkers_matched"] == 1 and fg["walker_speed_error_mps"] == pytest.approx(0.0, abs=0.01)
    assert fg["dynamic_instances"] == 1 and fg["state_accuracy"] == 1.0


def test_a_walker_left_static_is_a_wrong_state(tiny):
    insts = [i for i in _instances() if i.class_name != "person"]
    walker = next(i for i in _instances() if i.class_name == "person")
    walker.state = "static"  # what every walker was once its track closed
    fg = score_scene(load_truth(tiny), load_surfaces(tiny), [*insts, walker])["foreground"]
    assert fg["dynamic_instances"] == 0 and fg["state_accuracy"] == pytest.approx(0.5)


def test_a_table_the_foreground_found_is_right_and_one_it_left_to_the_background_no_miss(tiny):
    doc = json.loads((tiny / "gt" / "instances.json").read_text())
    doc["instances"].append({"id": 7, "name": "desk_0", "class": "table", "layer": "foreground",
                             "static": True, "aabb_min": [-2, -1, 0], "aabb_max": [-1, 0, 0.75],
                             "observed": True, "alt_classes": []})
    (tiny / "gt" / "instances.json").write_text(json.dumps(doc))
    truth, surfaces = load_truth(tiny), load_surfaces(tiny)
    without = score_scene(truth, surfaces, _instances())["foreground"]
    assert (without["tp"], without["fp"], without["fn_observed"]) == (2, 2, 1)  # no table missed
    found = _thing("table", [-1.5, -0.5, 0.38], [1.0, 1.0, 0.76])
    stray = _thing("table", [2.0, -2.5, 0.38], [1.0, 1.0, 0.76])
    fg = score_scene(truth, surfaces, [*_instances(), found, stray])["foreground"]
    assert fg["per_class"]["table"] == {"tp": 1, "fp": 1, "fn": 0}


def test_cli_names_a_missing_gt(tmp_path):
    result = CliRunner().invoke(app, ["eval", "scene", str(tmp_path), "--kb", str(tmp_path / "kb")])
    assert result.exit_code != 0
    assert "gt" in result.output


@pytest.mark.skipif(not (WORLDS / "bookstore" / "gt").is_dir(), reason="needs ../shared/worlds/bookstore")
def test_cli_scores_a_world(tmp_path):
    kb = tmp_path / "bs.hiper"
    hiper = [sys.executable, "-m", "hiper_cli"]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    subprocess.run([*hiper, "perceive", str(WORLDS / "bookstore"), "--kb", str(kb), "--stages", "background",
                    "--mapping-hz", "0.5"], check=True, capture_output=True, env=env)
    out = subprocess.run([*hiper, "eval", "scene", str(WORLDS / "bookstore"), "--kb", str(kb), "--json"],
                         check=True, capture_output=True, text=True, env=env).stdout
    data = json.loads(out)
    assert data["background"]["pieces"] == 6
    assert data["background"]["instances"] > 0 and data["background"]["coverage"] is not None


def test_eval_background_leaves_out_instances_seen_only_in_unlabelled_frames(tiny):
    from collections import Counter

    from hiper_cli.evaluate.background import BackgroundReport, score_background

    floor, wall = _instances()[:2]
    floor.observation_uuids[:] = ["labelled"]
    wall.observation_uuids[:] = ["unlabelled"]
    report = score_background([floor, wall], {"labelled": Counter({1: 40})}, load_truth(tiny),
                              BackgroundReport(log=str(tiny), world="tiny", method="fast"))
    assert report.unscored == 1 and report.unlabelled == 0
    assert report.semantic_precision == pytest.approx(1.0)
