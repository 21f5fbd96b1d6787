"""A realistic world's gt/ folder (instances.json, frames.jsonl, ids every 5th frame) as Truth."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.truth import load_truth
from tests import WORLDS


def _write_world(root: Path) -> None:
    gt = root / "gt"
    (gt / "instances").mkdir(parents=True)
    walk = [[1000.0 + 0.1 * k, 0.06 * k, 2.0, 0.85] for k in range(30)]
    instances = [
        {"id": 1, "name": "Floor::floor_000", "class": "floor", "alt_classes": [],
         "layer": "background", "static": True, "aabb_min": [-5, -5, 0], "aabb_max": [5, 5, 0],
         "plane": [0, 0, 1, 0], "observed": True, "first_seen_t": 1000.0, "last_seen_t": 1002.9},
        {"id": 2, "name": "Desk_01", "class": "table", "alt_classes": ["dining table"],
         "layer": "foreground", "static": True, "aabb_min": [1, 1, 0], "aabb_max": [2, 1.6, 0.75],
         "observed": True, "first_seen_t": 1000.5, "last_seen_t": 1001.0},
        {"id": 3, "name": "walker_0", "class": "person", "alt_classes": [], "layer": "foreground",
         "static": False, "aabb_min": [-0.3, 1.7, 0], "aabb_max": [2.0, 2.3, 1.7],
         "body_size": [0.5, 0.4, 1.7], "speed_mps": 0.6, "active_from_t": 1001.0,
         "trajectory": walk, "observed": True, "first_seen_t": 1001.2, "last_seen_t": 1002.9},
    ]
    doc = {"log": "tiny", "t0": 1000.0, "duration_s": 2.9, "seed": 4, "instances": instances}
    (gt / "instances.json").write_text(json.dumps(doc))
    frames = [{"i": k, "t": 1000.0 + 0.1 * k, "visible": {"1": 500, "3": 40 * (k > 12)}}
              for k in range(30)]
    (gt / "frames.jsonl").write_text("".join(json.dumps(f) + "\n" for f in frames))
    cv2.imwrite(str(gt / "instances" / "1000.000000.png"), np.full((4, 6), 3, np.uint16))


def test_world_truth_reads_into_hiper_conventions(tmp_path: Path) -> None:
    _write_world(tmp_path)
    truth = load_truth(tmp_path)
    assert truth.world == "tiny" and set(truth.instances) == {1, 2, 3}
    assert truth.instances[2].layer == "background"  # a table is a background class in hiper
    assert truth.instances[2].alt_classes == ("dining table",)
    walker = truth.instances[3]
    assert walker.state == "dynamic" and walker.speed_mps == 0.6
    np.testing.assert_allclose(walker.box.extent_m, [0.5, 0.4, 1.7])
    np.testing.assert_allclose(walker.box.center_m, [0.0, 2.0, 0.85])
    np.testing.assert_allclose(truth.position_at(3, 1001.05), [0.63, 2.0, 0.85], atol=1e-9)
    np.testing.assert_allclose(truth.tracks[3][5, 4:7], [0.6, 0.0, 0.0], atol=1e-9)
    assert [p.name for p in truth.phases] == ["mapping", "operation"]
    assert truth.phase_at(1000.5) == "mapping" and truth.phase_at(1002.0) == "operation"
    assert truth.has_instance_ids("rgb/1000.000000.jpg")
    assert not truth.has_instance_ids("rgb/1000.100000.jpg")
    assert truth.load_instance_ids("rgb/1000.000000.jpg").max() == 3
    visible = truth.load_visibility()
    assert len(visible) == 30 and visible[1002.0][3] == 40


def test_malformed_world_truth_names_the_file(tmp_path: Path) -> None:
    (tmp_path / "gt").mkdir()
    (tmp_path / "gt" / "instances.json").write_text('{"instances": [{"id": 1}]}')
    with pytest.raises(LogError, match=r"gt/instances.json: malformed ground truth"):
        load_truth(tmp_path)


def test_missing_truth_names_both_layouts(tmp_path: Path) -> None:
    with pytest.raises(LogError, match=r"world.json.*instances.json"):
        load_truth(tmp_path)


@pytest.mark.skipif(not (WORLDS / "bookstore" / "gt").is_dir(), reason="../shared/worlds absent")
def test_shared_worlds_load() -> None:
    for name in ("bookstore", "warehouse"):
        truth = load_truth(WORLDS / name)
        walkers = [t for t in truth.instances.values() if t.state == "dynamic"]
        assert len(walkers) == 2 and all(t.speed_mps in (0.6, 0.9) for t in walkers)
        assert all(len(truth.tracks[t.id]) > 100 for t in walkers)
