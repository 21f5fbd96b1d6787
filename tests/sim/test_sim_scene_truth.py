"""hiper sim writes its truth in the realistic worlds' format too (``sim/scene_truth.py``), so
``hiper eval scene`` and the worlds' reference scorer score a simulated log like a world's."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.evaluate.scene import score_scene
from hiper_cli.evaluate.surfaces import load_surfaces
from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.logs.world_truth import load_world_truth
from hiper_cli.sim import DepthNoise, RenderConfig, SimConfig, simulate


@pytest.fixture(scope="module")
def office_log(tmp_path_factory):
    """Office, 4 s at 5 Hz, 160×120: mapping 1.6 s, then people walking."""
    out = tmp_path_factory.mktemp("sim") / "office"
    cfg = SimConfig(rate_hz=5.0, mapping_s=1.6, render=RenderConfig(width=160, height=120,
                                                                    noise=DepthNoise.off()))
    simulate("office", 4.0, 3, out, cfg)
    return out


def test_instances_json_has_the_worlds_fields(office_log):
    doc = json.loads((office_log / "gt" / "instances.json").read_text())
    assert doc["n_frames"] == 20 and doc["rate_hz"] == 5.0 and doc["t0"] == 0.0
    records = doc["instances"]
    walls = [r for r in records if r["class"] == "wall" and r["observed"]]
    assert walls and all(r["layer"] == "background" and r["area_m2"] > 1.0 for r in walls)
    assert all(r["layer"] == "foreground" for r in records if r["class"] in ("table", "chair"))
    walkers = [r for r in records if not r["static"]]
    assert walkers, "the office log shows people"
    for r in walkers:
        assert r["trajectory"][0][0] >= 1.6 and r["speed_mps"] > 0 and len(r["body_size"]) == 3
    truth = load_world_truth(office_log)
    assert {t.id for t in truth.instances.values() if t.state == "dynamic"} == {r["id"] for r in walkers}


def test_surface_samples_lie_on_their_instances(office_log):
    doc = json.loads((office_log / "gt" / "instances.json").read_text())
    records = {r["id"]: r for r in doc["instances"]}
    with np.load(office_log / "gt" / "surface_points.npz") as npz:
        xyz, ids = npz["static_xyz"], npz["static_id"]
        normals = npz["static_normal"].astype(float) / 127.0
        dyn_xyz, dyn_id, dyn_t = npz["dynamic_xyz"], npz["dynamic_id"], npz["dynamic_t"]
    assert len(xyz) > 1000 and len(dyn_xyz) > 0
    lo = np.array([records[i]["aabb_min"] for i in ids])
    hi = np.array([records[i]["aabb_max"] for i in ids])
    assert np.all((xyz >= lo - 0.01) & (xyz <= hi + 0.01))
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=0.02)
    # one sample per 2 cm cell and instance
    cells = np.floor(xyz / 0.02).astype(np.int64)
    assert len(np.unique(np.column_stack([ids, cells]), axis=0)) == len(xyz)
    for i in np.unique(dyn_id):  # a walker's samples lie on its body at their time
        rows = np.array(records[int(i)]["trajectory"])
        at = dyn_t[dyn_id == i]
        centre = np.stack([np.interp(at, rows[:, 0], rows[:, k]) for k in (1, 2, 3)], axis=1)
        assert np.all(np.linalg.norm((dyn_xyz[dyn_id == i] - centre)[:, :2], axis=1) < 0.6)


def test_eval_scene_scores_a_sim_log(office_log, tmp_path):
    truth = load_world_truth(office_log)
    surfaces = load_surfaces(office_log)
    wall = next(t for t in truth.instances.values() if t.class_name == "wall" and t.observed)
    plane = surfaces.piece_planes[wall.id]
    lo, hi = wall.box.aabb()
    extent = np.maximum(hi - lo, 0.02)
    on_wall = Instance(layer="background", class_name="wall", box=Box3D((lo + hi) / 2, extent),
                       first_seen_s=0.0, last_seen_s=1.0, data={"plane_map": [float(v) for v in plane]})
    thing = next(t for t in truth.instances.values() if t.layer == "foreground" and t.state == "static"
                 and t.observed)
    named = Instance(layer="foreground", class_name=thing.class_name, box=thing.box, first_seen_s=0.0,
                     last_seen_s=1.0)
    stray = Instance(layer="foreground", class_name="unknown", box=Box3D(np.array([50.0, 50, 1]), np.ones(3)),
                     first_seen_s=0.0, last_seen_s=1.0)
    scores = score_scene(truth, surfaces, [on_wall, named, stray])
    assert scores["background"]["semantic_precision"] == 1.0
    assert scores["background"]["pieces_covered"] >= 1
    fg = scores["foreground"]
    assert fg["classified_precision"] == 1.0 and fg["unknown_on_nothing"] == 1.0
    assert fg["unmatched"] == {"unknown->nothing": 1}


def test_hiper_eval_scene_on_a_perceived_sim_log(office_log, tmp_path):
    kb = str(tmp_path / "office.hiper")
    runner = CliRunner()
    perceived = runner.invoke(app, ["perceive", str(office_log), "--kb", kb, "--detector", "truth"])
    assert perceived.exit_code == 0, perceived.output
    result = runner.invoke(app, ["eval", "scene", str(office_log), "--kb", kb, "--json"])
    assert result.exit_code == 0, result.output
    scores = json.loads(result.output)
    assert scores["world"] == "office"
    assert scores["background"]["instances"] > 0 and scores["background"]["semantic_precision"] >= 0.9
    assert scores["background"]["pieces"] > 0


def test_an_old_sim_log_without_scene_truth_is_one_line_error(office_log, tmp_path):
    old = tmp_path / "old"
    (old / "gt").mkdir(parents=True)
    (old / "gt" / "world.json").write_text((office_log / "gt" / "world.json").read_text())
    result = CliRunner().invoke(app, ["eval", "scene", str(old), "--kb", str(tmp_path / "kb")])
    assert result.exit_code != 0
    assert "instances.json: not found" in result.output and "hiper sim" in result.output
