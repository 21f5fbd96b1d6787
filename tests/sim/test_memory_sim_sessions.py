"""``hiper sim --sessions N --changes K``: logs of one place, each in its own frame, with the true
changes between them."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.perceive.logs import LogOptions, open_log

runner = CliRunner()


def test_sessions_have_their_own_frames_and_the_true_changes(tmp_path):
    out = tmp_path / "days"
    result = runner.invoke(app, ["sim", "--sessions", "3", "--changes", "3", "-s", "1", "--rate-hz", "2",
                                 "--width", "80", "--height", "60", "--seed", "4", "-o", str(out), "--json"])
    assert result.exit_code == 0, result.output
    truth = json.loads((out / "changes.json").read_text())
    assert [c["kind"] for c in truth["changes"]] == ["moved", "removed", "added"]
    assert [c["session"] for c in truth["changes"]] == [2, 2, 3]  # changes spread over the two gaps
    for c in truth["changes"]:
        assert c["class"] in ("chair", "potted plant")
        assert (c["from_m"] is None) == (c["kind"] == "added")
        assert (c["to_m"] is None) == (c["kind"] == "removed")
    moved = truth["changes"][0]
    assert 1.2 <= np.hypot(*np.subtract(moved["to_m"][:2], moved["from_m"][:2])) <= 3.1
    worlds = [json.loads((out / f"session_{s}" / "gt" / "world.json").read_text()) for s in (1, 2, 3)]
    ids = [{i["id"] for i in w["instances"]} for w in worlds]
    removed, added = truth["changes"][1]["object_id"], truth["changes"][2]["object_id"]
    assert removed in ids[0] and removed not in ids[1] and added not in ids[1] and added in ids[2]
    # the same first frame (same route) seen from each session's own odometry frame
    first = [open_log(out / f"session_{s}", LogOptions()).read_frame(0).T_map_cam for s in (1, 2, 3)]
    for s in (1, 2):
        T_log_map = np.asarray(truth["sessions"][s]["T_log_map"])
        assert np.allclose(first[s], T_log_map @ first[0], atol=1e-4)
        yaw = np.degrees(np.arctan2(T_log_map[1, 0], T_log_map[0, 0]))
        assert 15 <= abs(yaw) <= 40 and 1.0 <= np.linalg.norm(T_log_map[:2, 3]) <= 3.0


def test_changes_need_a_second_session(tmp_path):
    result = runner.invoke(app, ["sim", "--changes", "2", "-s", "1", "-o", str(tmp_path / "x")])
    assert result.exit_code != 0
    assert "changes happen between sessions" in " ".join(result.output.split())


def test_a_removal_and_an_addition_of_one_class_stay_apart(tmp_path):
    """Where an object was taken away (removed, moved from) and where one of its class was put
    (added, moved to) are ``APART_M`` apart: closer, no one who cannot tell two chairs apart
    could say which moved (seed 8 moved a chair to 0.8 m from one removed after it)."""
    from hiper_cli.sim.sessions import APART_M

    for seed in (8, 9):
        out = tmp_path / f"days{seed}"
        result = runner.invoke(app, ["sim", "--sessions", "3", "--changes", "6", "-s", "1", "--rate-hz", "2",
                                     "--width", "80", "--height", "60", "--seed", str(seed), "-o", str(out)])
        assert result.exit_code == 0, result.output
        changes = json.loads((out / "changes.json").read_text())["changes"]
        for a in changes:
            for b in changes:
                if a is not b and a["class"] == b["class"] and a["from_m"] and b["to_m"]:
                    assert np.hypot(*np.subtract(a["from_m"][:2], b["to_m"][:2])) >= APART_M, (seed, a, b)
