"""The foreground stage end to end on ray-cast scenes, and ``hiper eval foreground``."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.learned import AltitudeFeature, SizeFeature
from hiper_cli.perceive.foreground import ForegroundConfig, ForegroundStage
from hiper_cli.perceive.foreground.segment import segment
from hiper_cli.perceive.runner import run_stages
from hiper_cli.perceive.stage import FrameResult, World, make_stage
from tests import REPO_ROOT
from tests.fg_scene import (
    CAMERA,
    SceneBox,
    background_instances,
    chair,
    make_frame,
    person,
    pose_looking_x,
    room,
    write_sim_log,
)

RATE_HZ = 30.0


def walker_frames(n=60, speed=0.6):
    return [
        make_frame([*room(), person(10, 3.0, -1.0 + speed * k / RATE_HZ)], pose_looking_x(), k / RATE_HZ, k)
        for k in range(n)
    ]


def test_unknown_option_is_a_config_error():
    with pytest.raises(ConfigError, match="unknown foreground option"):
        ForegroundStage(detector="log", iou=0.3)
    with pytest.raises(ConfigError, match="iou_threshold must be in"):
        ForegroundConfig(iou_threshold=1.5)


def test_registry_builds_the_stage():
    stage = make_stage("foreground", detector="log", pixel_step=2)
    assert stage.name == "foreground"


def test_background_filter_leaves_only_the_person():
    boxes = [*room(), person(10, 3.0, 0.0), chair(11, 4.0, 1.0)]
    frame = make_frame(boxes, pose_looking_x(), 0.0, 0)
    bg = [i.box for i in background_instances(boxes).values()]
    cfg = ForegroundConfig(pixel_step=2)
    blobs, stats = segment(frame.depth_m, CAMERA, frame.T_map_cam, bg, cfg)
    assert stats.after_background < stats.points / 3
    centres = sorted(b.center_map_m[1] for b in blobs)
    assert len(blobs) == 2 and centres == pytest.approx([0.0, 1.0], abs=0.05)
    # Without the filter (C4) the person merges with the floor into one rejected cluster and
    # strips of far floor become blobs.
    off = ForegroundConfig(pixel_step=2, background_filter=False)
    blobs_off, stats_off = segment(frame.depth_m, CAMERA, frame.T_map_cam, [], off)
    assert stats_off.after_background == stats.points
    assert not any(np.linalg.norm(b.center_map_m[:2] - [2.85, 0.0]) < 0.2 for b in blobs_off)
    assert any(b.extent_map_m[2] < 0.05 for b in blobs_off)


def test_walker_becomes_one_dynamic_person_with_its_speed():
    stage = ForegroundStage(detector="log", pixel_step=2)
    world, _ = run_stages(walker_frames(), [stage], World(background=background_instances(room())))
    (inst,) = world.foreground.values()
    assert inst.class_name == "person" and inst.layer == "foreground"
    rows = np.array(inst.data["trajectory"])
    assert rows.shape == (60, 7)
    assert np.hypot(rows[:, 4], rows[:, 5]).mean() == pytest.approx(0.6, abs=0.05)
    assert inst.box.center_m[0] == pytest.approx(2.85, abs=0.05)  # the visible front at x = 2.85
    assert len(inst.observation_uuids) == 60
    assert inst.state == "dynamic"  # after the log ended and its track closed


def _instances_after(frames):
    stage = ForegroundStage(detector="log", pixel_step=2)
    world, _ = run_stages(frames, [stage], World(background=background_instances(room())))
    return list(world.foreground.values())


def test_a_walker_that_stopped_is_dynamic_and_a_person_standing_still_static():
    def frames(walk_frames):  # walks 0.6 m/s for walk_frames, then stands until frame 90
        return [make_frame([*room(), person(10, 3.0, -1.0 + 0.6 * min(k, walk_frames) / RATE_HZ)],
                           pose_looking_x(), k / RATE_HZ, k) for k in range(90)]

    (walked,) = _instances_after(frames(45))
    assert walked.class_name == "person" and walked.state == "dynamic"
    (stood,) = _instances_after(frames(0))
    assert stood.class_name == "person" and stood.state == "static"


def test_a_static_object_is_static_and_a_moving_one_dynamic():
    still = [make_frame([*room(), chair(11, 4.0, 1.0)], pose_looking_x(), k / RATE_HZ, k) for k in range(60)]
    (chair_inst,) = _instances_after(still)
    assert chair_inst.class_name == "chair" and chair_inst.state == "static"
    pushed = [make_frame([*room(), chair(11, 4.0, 1.5 - 1.5 * k / 60)], pose_looking_x(), k / RATE_HZ, k)
              for k in range(60)]
    states = {i.class_name: i.state for i in _instances_after(pushed)}
    assert states == {"chair": "dynamic"}


def test_observations_carry_the_low_level_data():
    stage = ForegroundStage(detector="log", pixel_step=2, confirm_hits=2)
    world = World(background=background_instances(room()))
    frames = walker_frames(5)  # named 4 times: a person (a class never named is withdrawn)
    results = []
    for f in frames:
        r = stage.process(f, world)
        world.apply(r)
        results.append(r)
    obs = results[2].observations[0]
    assert obs.class_name == "person" and obs.frame_id == "camera" and obs.pose_id == 2
    assert set(obs.data) >= {"image_box_xyxy", "points_cam", "pixels_uv", "detection", "center_map"}
    assert obs.data["detection"]["class"] == "person"
    assert obs.instance_uuid in world.foreground
    assert results[0].observations[0].instance_uuid is None  # tentative track: not yet an instance
    assert {"foreground_s", "foreground_detect_s", "foreground_cluster_s"} <= set(results[-1].timings_s)
    assert stage.finish(world).instances[0].data["closed"] is True


def test_learned_size_prior_rules_out_only_blobs_too_large():
    """Priors are learned from instances, the extent of all views; one view shows at most that."""
    world = World(background=background_instances(room()))
    frame = make_frame([*room(), chair(11, 3.0, 0.0)], pose_looking_x(), 0.0, 0)
    bottle_sized = SizeFeature(0.004, 0.003, 0.005, 0.002, 0.01, 10)
    world.analyses.append(bottle_sized.to_analysis("chair", 0, 1, created_s=1.0))
    r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
    assert [o.class_name for o in r.observations] == ["unknown"]
    switched_off = ForegroundStage(detector="log", pixel_step=2, learned_size=False)
    assert [o.class_name for o in switched_off.process(frame, world).observations] == ["chair"]
    # A blob smaller than every instance of its class is a partial or sparse view, no evidence.
    world.analyses = [SizeFeature(7.0, 6.0, 8.0, 5.0, 9.0, 10).to_analysis("chair", 0, 1, created_s=1.0)]
    r = ForegroundStage(detector="log", pixel_step=2).process(frame, world)
    assert [o.class_name for o in r.observations] == ["chair"]
    # A walker's instance box is the running mean of its views: no bound on one view.
    world.analyses = [bottle_sized.to_analysis("person", 0, 1, created_s=1.0)]
    r = ForegroundStage(detector="log", pixel_step=2).process(walker_frames(1)[0], world)
    assert [o.class_name for o in r.observations] == ["person"]


def test_learned_altitude_prior_rejects_a_floating_person():
    world = World(background=background_instances(room()))
    floating = AltitudeFeature(1.5, 1.4, 1.6, 1.2, 1.8, 10).to_analysis("person", 0, 1, created_s=1.0)
    world.analyses.append(floating)
    r = ForegroundStage(detector="log", pixel_step=2).process(walker_frames(1)[0], world)
    assert [o.class_name for o in r.observations] == ["unknown"]
    r = ForegroundStage(detector="log", pixel_step=2, use_learned_priors=False).process(
        walker_frames(1)[0], world
    )
    assert [o.class_name for o in r.observations] == ["person"]


def test_a_range_learned_from_fewer_instances_than_prior_min_instances_is_no_prior():
    """House 44: one TV's learned altitude, a point, refused 9 of the next session's 46 TV views."""
    world = World(background=background_instances(room()))
    for instances, expected in ((1, "person"), (2, "person"), (3, "unknown")):
        floating = AltitudeFeature(1.5, 1.4, 1.6, 1.2, 1.8, instances)
        world.analyses = [floating.to_analysis("person", 0, 1, created_s=1.0)]
        r = ForegroundStage(detector="log", pixel_step=2).process(walker_frames(1)[0], world)
        assert [o.class_name for o in r.observations] == [expected], instances


def test_learned_altitude_prior_keeps_a_person_cut_by_the_image_edge():
    """A bottom above the learned range rules a class out only where the blob is seen whole."""
    world = World(background=background_instances(room()))
    on_the_floor = AltitudeFeature(0.01, 0.0, 0.02, 0.0, 0.02, 10)
    world.analyses.append(on_the_floor.to_analysis("person", 0, 1, created_s=1.0))
    stage = ForegroundStage(detector="log", pixel_step=2)
    # On a 0.6 m platform (background, so no blob of its own) the whole person is in view.
    platform = SceneBox(20, np.array([3.0, 0.0, 0.3]), np.array([0.8, 1.0, 0.6]), "other", background=True)
    raised = SceneBox(10, np.array([3.0, 0.0, 1.45]), np.array([0.3, 0.5, 1.7]), "person", relief_m=0.1)
    world.background = background_instances([*room(), platform])
    frame = make_frame([*room(), platform, raised], pose_looking_x(), 0.0, 0)
    assert [o.class_name for o in stage.process(frame, world).observations] == ["unknown"]
    # 1.2 m before the camera the legs are below the image's lower edge: the blob's bottom
    # (0.3 m up) is not the person's.
    world.background = background_instances(room())
    frame = make_frame([*room(), person(10, 1.2, 0.0)], pose_looking_x(), 0.0, 0)
    assert [o.class_name for o in stage.process(frame, world).observations] == ["person"]


def test_eval_foreground_command_on_a_small_sim_log(tmp_path):
    log = tmp_path / "log"
    write_sim_log(log, seconds=2.0, fp_every=10)
    args = ["eval", "foreground", str(log), "--json", "--no-ablation", "--background", "truth",
            "--set", "pixel_step=2"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    ours = report["ours"]
    assert ours["classification"] == {"chair": {"tp": 1, "fp": 0}, "person": {"tp": 1, "fp": 0}}
    assert ours["identity_switches"] == 0
    assert ours["moving_people_speed_error_mps"] == pytest.approx(0.0, abs=0.05)
    assert ours["localisation_visible_m"][0] < 0.06  # a 160x120 camera: 4 cm pixels at 4 m
    assert ours["frames"] == 60 and "ablation" not in report


def test_moving_people_are_found_after_the_log_is_perceived(tmp_path):
    log, kb = tmp_path / "log", tmp_path / "kb.hiper"
    write_sim_log(log, seconds=2.0)
    runner = CliRunner()
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(kb), "--detector", "truth",
                                 "-o", "foreground.pixel_step=2"])
    assert result.exit_code == 0, result.output

    def count(words):
        answer = runner.invoke(app, ["query", words, "--kb", str(kb), "--json"])
        assert answer.exit_code == 0, answer.output
        return json.loads(answer.output)["count"]

    assert count("moving people") == 1 and count("static people") == 0
    assert count("static chairs") == 1 and count("moving objects") == 1


def test_eval_foreground_needs_ground_truth(tmp_path):
    result = CliRunner().invoke(app, ["eval", "foreground", str(tmp_path)])
    assert result.exit_code != 0
    assert "gt/world.json: not found" in result.output


def test_every_option_is_documented():
    from dataclasses import fields

    doc = (REPO_ROOT / "docs" / "foreground.md").read_text()
    missing = [f.name for f in fields(ForegroundConfig) if f"`{f.name}`" not in doc]
    assert not missing, f"docs/foreground.md does not mention {missing}"


def test_objects_rest_on_the_fitted_floor_plane_not_on_the_top_of_its_box():
    from hiper_cli.model import Box3D, Instance
    from hiper_cli.perceive.foreground.supports import support_boxes

    # The background stage's floor box is 2 cm thick around its plane (the points' noise).
    floor_box = Box3D(np.array([2.0, 0.0, 0.0]), np.array([4.0, 4.0, 0.02]))
    floor = Instance("background", "floor", floor_box, 0.0, 0.0)
    floor.data["plane_map"] = [0.0, 0.0, 1.0, 0.004]  # z = -0.004 m
    wall_box = Box3D(np.array([4.0, 0.0, 1.0]), np.array([0.02, 4.0, 2.0]))
    wall = Instance("background", "wall", wall_box, 0.0, 0.0)
    (box,) = support_boxes([floor, wall])
    lo, hi = box.aabb()
    assert hi[2] == pytest.approx(-0.004) and lo[2] == pytest.approx(-0.01)
    floor.data.pop("plane_map")  # no plane: the box as it is
    (box,) = support_boxes([floor])
    assert box.aabb()[1][2] == pytest.approx(0.01)


class _RecordingDetector:
    """The ``log`` detector, recording which frames it saw whole and on which thread (and apart,
    the tiles of a keyframe's closer look, ``keyframes.py``)."""

    name = "recording"

    def __init__(self):
        from hiper_cli.perceive.detect.recorded import LogDetector

        self.inner = LogDetector()
        self.seen = []
        self.tiles = []

    def detect(self, frame):
        import threading

        looks = self.seen if frame.width == CAMERA.width else self.tiles
        looks.append((frame.pose_id, threading.current_thread().name))
        return self.inner.detect(frame)


def test_the_detector_runs_one_frame_ahead_once_per_frame_in_its_worker(monkeypatch):
    detector = _RecordingDetector()
    stage = ForegroundStage(detector_instance=detector, pixel_step=2)
    calls = []
    prepare, process = stage.prepare, stage.process
    stage.prepare = lambda frame: (calls.append(("prepare", frame.pose_id)), prepare(frame))[1]
    stage.process = lambda frame, world: (calls.append(("process", frame.pose_id)), process(frame, world))[1]
    frames = walker_frames(n=4)
    world, _ = run_stages(frames, [stage], World(background=background_instances(room())))
    # the next frame goes to the detector before the current one is processed
    assert calls == [
        ("prepare", 1), ("process", 0), ("prepare", 2), ("process", 1),
        ("prepare", 3), ("process", 2), ("process", 3),
    ]  # fmt: skip
    assert sorted(pose for pose, _ in detector.seen) == [0, 1, 2, 3]
    assert all(name.startswith("hiper-detect") for _, name in detector.seen + detector.tiles)
    assert sorted(pose for pose, _ in detector.tiles) == [0, 1, 2, 3]  # a keyframe: one tile a frame
    # same result as detecting each frame when it is processed
    plain = ForegroundStage(detector="log", pixel_step=2, detector_threads=0)
    world_plain, _ = run_stages(walker_frames(n=4), [plain], World(background=background_instances(room())))
    ((a,), (b,)) = world.foreground.values(), world_plain.foreground.values()
    assert a.class_name == b.class_name == "person"
    assert len(a.data["trajectory"]) == 4
    assert np.allclose(a.data["trajectory"], b.data["trajectory"])
    assert len(a.observation_uuids) == len(b.observation_uuids) == 4


def test_live_the_detector_starts_on_each_frame_before_the_stages_before_it(monkeypatch):
    """``look_ahead=False`` (a live stream): no next frame to hand over, so each frame goes to
    the detector before the first stage (the background) processes it; same result."""
    detector = _RecordingDetector()
    stage = ForegroundStage(detector_instance=detector, pixel_step=2)
    calls = []
    prepare, process = stage.prepare, stage.process
    stage.prepare = lambda frame: (calls.append(("prepare", frame.pose_id)), prepare(frame))[1]
    stage.process = lambda frame, world: (calls.append(("process", frame.pose_id)), process(frame, world))[1]

    class Before:  # stands for the background: runs first, records its turn
        name = "before"

        def process(self, frame, world):
            calls.append(("before", frame.pose_id))
            return FrameResult()

        def finish(self, world):
            return FrameResult()

    world, _ = run_stages(walker_frames(n=4), [Before(), stage],
                          World(background=background_instances(room())), look_ahead=False)
    assert calls == [
        ("prepare", 0), ("before", 0), ("process", 0), ("prepare", 1), ("before", 1), ("process", 1),
        ("prepare", 2), ("before", 2), ("process", 2), ("prepare", 3), ("before", 3), ("process", 3),
    ]  # fmt: skip
    assert sorted(pose for pose, _ in detector.seen) == [0, 1, 2, 3]  # once per frame, in the worker
    assert all(name.startswith("hiper-detect") for _, name in detector.seen)
    plain = ForegroundStage(detector="log", pixel_step=2, detector_threads=0)
    world_plain, _ = run_stages(walker_frames(n=4), [plain], World(background=background_instances(room())))
    ((a,), (b,)) = world.foreground.values(), world_plain.foreground.values()
    assert len(a.data["trajectory"]) == 4
    assert np.allclose(a.data["trajectory"], b.data["trajectory"])


def test_each_learned_dynamics_prior_switches_alone():
    from hiper_cli.learned import ObjectDynamics

    world = World(background=background_instances(room()))
    ods = ObjectDynamics(0.6, 0.58, 0.62, 0.4, 0.8, 0.9, 0.03, 0.06, 100, 90, 5)
    world.analyses.append(ods.to_analysis("person", 0, 1, created_s=1.0))
    priors = {}
    settings = {"all": {}, "no gates": {"learned_gates": False}, "no noise": {"learned_motion_noise": False},
                "C2": {"use_learned_priors": False}}
    for name, opts in settings.items():
        stage = ForegroundStage(detector="log", pixel_step=2, **opts)
        stage.process(walker_frames(1)[0], world)
        priors[name] = stage._priors.class_prior("person")
    assert (priors["all"].cu_mps, priors["all"].sigma_mps) == (0.8, 0.03)
    assert (priors["no gates"].cu_mps, priors["no gates"].sigma_mps) == (None, 0.03)
    assert (priors["no noise"].cu_mps, priors["no noise"].sigma_mps) == (0.8, None)
    assert (priors["C2"].cu_mps, priors["C2"].sigma_mps) == (None, None)


def test_a_class_seen_only_standing_sets_no_motion_noise():
    """House 44 -> 47: the drift σ of standing chairs and bottles, taken for their motion noise,
    stiffened their filters and added identity switches in the next log."""
    from hiper_cli.learned import ObjectDynamics

    world = World(background=background_instances(room()))
    standing = ObjectDynamics(None, None, None, None, None, 0.0, 0.03, 0.06, 300, 0, 5)
    world.analyses.append(standing.to_analysis("chair", 0, 1, created_s=1.0))
    stage = ForegroundStage(detector="log", pixel_step=2)
    stage.process(walker_frames(1)[0], world)
    chair = stage._priors.class_prior("chair")
    assert (chair.cu_mps, chair.sigma_mps) == (None, None)
