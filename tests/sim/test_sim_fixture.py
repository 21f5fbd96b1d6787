"""The committed fixtures/house_small log: readable, with truth, mapping then one person."""

import numpy as np

from hiper_cli.perceive.logs import open_log
from hiper_cli.sim import load_truth
from tests import REPO_ROOT

FIXTURE = REPO_ROOT / "fixtures" / "house_small"


def test_fixture_is_a_readable_simulated_log():
    reader = open_log(FIXTURE)
    info = reader.info()
    assert info.frames == 60 and (info.camera.width, info.camera.height) == (256, 192)
    truth = load_truth(FIXTURE)
    assert truth.world == "house" and truth.seed == 4
    assert [p.name for p in truth.phases] == ["mapping", "operation"]
    (pid,) = [i for i, inst in truth.instances.items() if inst.class_name == "person"]
    seen = []
    for frame in reader:
        ids = truth.load_instance_ids(f"rgb/{frame.stamp_s:.6f}.png")
        visible = bool(np.any(ids == pid))
        assert not (visible and truth.phase_at(frame.stamp_s) == "mapping")
        seen.append(visible)
    assert sum(seen) >= 20
    dets = truth.load_detections()
    assert len(dets) == 60
