"""Which detector classes name blobs: the indoor exclusion list, per-environment allow-lists."""

import numpy as np
import pytest

from hiper_cli.perceive.foreground import ForegroundConfig, ForegroundStage
from hiper_cli.perceive.foreground.classes import INDOOR_EXCLUDED, filter_classes
from hiper_cli.perceive.stage import World
from hiper_cli.types import Detections
from tests.fg_scene import background_instances, make_frame, person, pose_looking_x, room


def dets(*names):
    return Detections(np.tile([0.0, 0.0, 10.0, 10.0], (len(names), 1)), names, np.full(len(names), 0.9))


def test_default_drops_outdoor_classes_and_tables_only():
    cfg = ForegroundConfig()
    assert {"fire hydrant", "boat", "traffic light", "dining table"} <= set(cfg.exclude_classes)
    assert not {"person", "chair", "couch", "bed", "bottle", "cup", "tv", "vase"} & set(INDOOR_EXCLUDED)
    kept = filter_classes(
        dets("chair", "fire hydrant", "dining table", "person"), cfg.classes, cfg.exclude_classes
    )
    assert kept.class_names == ("chair", "person") and kept.xyxy.shape == (2, 4) and len(kept.scores) == 2


def test_allow_list_and_empty_lists():
    d = dets("chair", "bed", "person")
    assert filter_classes(d, ("person", "chair")).class_names == ("chair", "person")
    assert filter_classes(d) is d  # nothing to filter: unchanged
    assert len(filter_classes(d, exclude=("chair", "bed", "person"))) == 0


def test_command_line_lists_are_split_on_commas():
    cfg = ForegroundConfig.from_options(classes="person, chair", exclude_classes="")
    assert cfg.classes == ("person", "chair") and cfg.exclude_classes == ()
    assert ForegroundConfig.from_options(classes=["cup"]).classes == ("cup",)


@pytest.mark.parametrize(("options", "expected"), [({}, "person"), ({"exclude_classes": "person"}, "unknown"),
                                                  ({"classes": "chair,bed"}, "unknown")])
def test_stage_applies_the_lists_to_the_detections(options, expected):
    stage = ForegroundStage(detector="log", pixel_step=2, **options)
    frame = make_frame([*room(), person(10, 3.0, 0.0)], pose_looking_x(), 0.0, 0)
    result = stage.process(frame, World(background=background_instances(room())))
    assert [o.class_name for o in result.observations] == [expected]


def test_eval_reports_the_class_lists_it_applied(tmp_path):
    import json

    from typer.testing import CliRunner

    from hiper_cli.cli import app
    from tests.fg_scene import write_sim_log

    log = tmp_path / "log"
    write_sim_log(log, seconds=1.0)
    base = ["eval", "foreground", str(log), "--json", "--no-ablation", "--background", "truth",
            "--set", "pixel_step=2"]
    report = json.loads(CliRunner().invoke(app, [*base, "--exclude-classes", "person"]).output)
    assert report["exclude_classes"] == ["person"] and report["classes"] == []
    assert "person" not in report["ours"]["classification"]
    report = json.loads(CliRunner().invoke(app, base).output)
    assert "fire hydrant" in report["exclude_classes"] and "person" in report["ours"]["classification"]


def _boxes(*rows):
    """Detections from (class, score, x0, y0, x1, y1) rows."""
    return Detections(np.array([r[2:] for r in rows], dtype=np.float64), tuple(r[0] for r in rows),
                      np.array([r[1] for r in rows]))


def test_an_object_the_detector_named_twice_keeps_its_surer_name():
    from hiper_cli.perceive.foreground.classes import one_name_per_box

    twice = _boxes(("vase", 0.45, 100, 100, 130, 180), ("bottle", 0.6, 101, 99, 131, 181))
    kept = one_name_per_box(twice, 0.8)
    assert kept.class_names == ("bottle",) and np.allclose(kept.xyxy, [[101, 99, 131, 181]])
    assert one_name_per_box(twice, 1.0) is twice  # off


def test_objects_that_overlap_less_or_share_a_class_keep_their_boxes():
    from hiper_cli.perceive.foreground.classes import one_name_per_box

    seated = _boxes(("person", 0.9, 100, 50, 200, 300), ("chair", 0.7, 90, 150, 210, 320))  # IoU 0.54
    cup_in_hand = _boxes(("person", 0.9, 100, 50, 200, 300), ("cup", 0.6, 180, 120, 200, 140))
    bottles = _boxes(("bottle", 0.9, 100, 100, 130, 180), ("bottle", 0.5, 102, 100, 132, 180))  # NMS's job
    for d in (seated, cup_in_hand, bottles):
        assert one_name_per_box(d, 0.8) is d


def test_a_person_seated_in_an_armchair_keeps_both_boxes():
    from hiper_cli.perceive.foreground.classes import one_name_per_box

    seated = _boxes(("chair", 0.8, 100, 100, 200, 260), ("person", 0.6, 102, 98, 198, 255))  # IoU 0.92
    assert one_name_per_box(seated, 0.8, apart=("person",)) is seated
    assert one_name_per_box(seated, 0.8).class_names == ("chair",)  # without the exception
