"""hiper sim writes a TUM log plus gt/ that the readers and load_truth understand, deterministically."""

import filecmp
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError, LogError
from hiper_cli.perceive.logs import open_log
from hiper_cli.sim import DepthNoise, NoiseModel, RenderConfig, SimConfig, load_truth, simulate

TINY = SimConfig(rate_hz=5.0, mapping_s=1.0, render=RenderConfig(width=96, height=72))


@pytest.fixture(scope="module")
def hospital_log(tmp_path_factory):
    """Hospital, 4 s at 5 Hz, 160×120, exact depth: mapping 1.6 s, then five people in corridor A."""
    out = tmp_path_factory.mktemp("sim") / "hospital"
    cfg = SimConfig(rate_hz=5.0, mapping_s=1.6, render=RenderConfig(width=160, height=120,
                                                                    noise=DepthNoise.off()))
    result = simulate("hospital", 4.0, 3, out, cfg)
    return out, result


def _tree_equal(a, b):
    cmp = filecmp.dircmp(a, b)
    assert not cmp.left_only and not cmp.right_only and not cmp.diff_files, (
        cmp.left_only, cmp.right_only, cmp.diff_files)
    _, mismatch, errors = filecmp.cmpfiles(a, b, cmp.common_files, shallow=False)
    assert not mismatch and not errors, (mismatch, errors)
    for sub in cmp.common_dirs:
        _tree_equal(a / sub, b / sub)


def test_same_seed_gives_identical_files(tmp_path):
    simulate("house", 2.4, 5, tmp_path / "a", TINY)
    simulate("house", 2.4, 5, tmp_path / "b", TINY)
    _tree_equal(tmp_path / "a", tmp_path / "b")
    simulate("house", 2.4, 6, tmp_path / "c", TINY)
    world_a, world_c = (tmp_path / d / "gt" / "world.json" for d in "ac")
    assert world_a.read_text() != world_c.read_text()


def test_open_log_reads_the_output(hospital_log):
    out, result = hospital_log
    reader = open_log(out)
    info = reader.info()
    assert len(reader) == info.frames == result.frames == 20
    assert (info.camera.width, info.camera.height) == (160, 120)
    frames = list(reader)
    assert frames[0].stamp_s == 0.0 and frames[-1].stamp_s == pytest.approx(3.8)
    assert frames[3].depth_m.max() <= 5.0 and (frames[3].depth_m > 0).mean() > 0.5
    assert not reader.skipped


def test_truth_loads_with_phases_and_classes(hospital_log):
    out, _ = hospital_log
    truth = load_truth(out)
    assert truth.world == "hospital" and truth.seed == 3
    assert [p.name for p in truth.phases] == ["mapping", "operation"]
    assert truth.phases[0].t_end_s < 1.6 <= truth.phases[1].t_start_s
    classes = [i.class_name for i in truth.instances.values()]
    assert classes.count("person") == 5 and "cart" in classes
    assert {"wall", "floor", "ceiling", "table", "door", "bed", "chair", "picture"} <= set(classes)
    people = [i for i in truth.instances.values() if i.class_name == "person"]
    assert all(p.state == "dynamic" and p.speed_mps == 0.6 for p in people)
    assert all(1.6 <= p.box.extent_m[2] <= 1.9 for p in people)
    assert all(i.plane is not None for i in truth.instances.values() if i.layer == "background")
    noise = json.loads((out / "gt" / "noise.json").read_text())
    assert NoiseModel.from_dict(noise) == NoiseModel()
    dets = truth.load_detections()
    assert len(dets) == 20 and any(d["class"] == "person" for ds in dets.values() for d in ds)


def test_mapping_phase_has_no_people(hospital_log):
    out, _ = hospital_log
    truth = load_truth(out)
    person_ids = {i for i, inst in truth.instances.items() if inst.class_name == "person"}
    mapping = truth.phases[0]
    for pid in person_ids:
        assert truth.tracks[pid][0, 0] >= truth.phases[1].t_start_s
    seen_in_operation = set()
    for frame in open_log(out):
        ids = set(np.unique(truth.load_instance_ids(f"rgb/{frame.stamp_s:.6f}.png")).tolist())
        if frame.stamp_s <= mapping.t_end_s:
            assert not ids & person_ids, f"person visible at {frame.stamp_s} during mapping"
        else:
            seen_in_operation |= ids & person_ids
    assert seen_in_operation, "the robot should see corridor people during operation"


def _boxes_contain_pixels(out, tol_m):
    """Check every labelled pixel; ``tol_m(z)`` is the allowed distance outside the box at depth z."""
    truth = load_truth(out)
    checked = 0
    for frame in open_log(out):
        ids = truth.load_instance_ids(f"rgb/{frame.stamp_s:.6f}.png")
        K = frame.camera
        v, u = np.nonzero(ids)
        z = frame.depth_m[v, u].astype(np.float64)
        assert np.all(z > 0), "every labelled pixel has a depth return"
        pts_cam = np.stack([(u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z], axis=1)
        pts = pts_cam @ frame.T_map_cam[:3, :3].T + frame.T_map_cam[:3, 3]
        for inst_id in np.unique(ids[v, u]):
            inst = truth.instances[int(inst_id)]
            mask = ids[v, u] == inst_id
            sel = pts[mask]
            center = inst.box.center_m
            if inst.state == "dynamic":
                center = truth.position_at(int(inst_id), frame.stamp_s)
                assert center is not None
            local = (sel - center) @ inst.box.R
            outside = (np.abs(local) - inst.box.extent_m / 2).max(axis=1) - tol_m(z[mask])
            where = f"{inst.name} at {frame.stamp_s}"
            assert outside.max() <= 0, f"{where}: {outside.max():.3f} m further outside its box than allowed"
            checked += 1
    return checked


def test_every_truth_box_contains_its_back_projected_pixels(hospital_log):
    out, _ = hospital_log
    # exact depth (noise off), quantised to 0.2 mm: 2 mm tolerance
    assert _boxes_contain_pixels(out, lambda z: np.full_like(z, 0.002)) > 100


def test_boxes_contain_noisy_pixels_within_three_sigma(tmp_path):
    cfg = SimConfig(rate_hz=5.0, mapping_s=1.0, render=RenderConfig(width=96, height=72))
    simulate("office", 3.0, 2, tmp_path / "o", cfg)
    noise = DepthNoise()

    def tol(z):  # 4.5 sigma of noise plus half a disparity step, stretched along the ray (≤ 1.25)
        step = z**2 / noise.focal_baseline_px_m * noise.disparity_step_px
        return 1.25 * (4.5 * noise.sigma_m(z) + step / 2 + 0.001)

    assert _boxes_contain_pixels(tmp_path / "o", tol) > 30


def test_perfect_noise_model_gives_tight_boxes():
    from hiper_cli.sim.noise import detect

    ids = np.zeros((48, 64), dtype=np.uint16)
    ids[10:20, 5:15] = 3
    ids[30:40, 40:60] = 4
    ids[0, 0:3] = 5  # 3 pixels: below min_pixels (4 at this size)
    rng = np.random.default_rng(0)
    dets = detect(ids, {3: "chair", 4: "wall", 5: "cup"}, NoiseModel.perfect(), rng)
    assert dets == [{"xyxy": [5.0, 10.0, 15.0, 20.0], "class": "chair", "score": 1.0, "instance_id": 3}]
    assert detect(ids, {3: "chair"}, NoiseModel(miss_rate=1.0, false_positives_per_image=0.0), rng) == []
    with pytest.raises(ConfigError, match=r"miss_rate=1\.5"):
        NoiseModel(miss_rate=1.5)


def test_bad_options_are_one_line_errors(tmp_path):
    with pytest.raises(ConfigError, match="unknown world 'moon'; expected one of house, hospital, office"):
        simulate("moon", 1.0, 0, tmp_path / "x", TINY)
    with pytest.raises(ConfigError, match=r"expected 0 < speed <= 0\.9"):
        from hiper_cli.sim import RouteConfig

        RouteConfig(speed_mps=1.5)
    simulate("house", 1.2, 0, tmp_path / "y", TINY)
    with pytest.raises(LogError, match="not empty"):
        simulate("house", 1.2, 0, tmp_path / "y", TINY)


def test_cli_sim_json_and_info(tmp_path):
    runner = CliRunner()
    out = tmp_path / "cli"
    result = runner.invoke(app, ["sim", "--world", "office", "--seconds", "1", "--seed", "1", "-o", str(out),
                                 "--rate-hz", "4", "--width", "64", "--height", "48", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.output)
    assert doc["frames"] == 4 and doc["world"] == "office" and doc["out"] == str(out)
    bad = runner.invoke(app, ["sim", "--world", "moon", "-o", str(tmp_path / "m")])
    assert bad.exit_code != 0 and "unknown world" in bad.output
    info = runner.invoke(app, ["info", str(out), "--json"])
    assert info.exit_code == 0, info.output
    assert json.loads(info.output)["frames"] == 4
