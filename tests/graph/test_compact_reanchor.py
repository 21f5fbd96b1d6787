"""Summarising keeps what ``hiper reanchor`` needs: a knowledge base perceived with the default
(observations summarised at the end of the session) re-anchors its walls where one that kept
every observation does."""

import json
import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.graph import open_kb
from hiper_cli.perceive.logs import Trajectory, TumWriter, write_tum_trajectory
from tests._bg_scenes import CAMERA, box_room, look_at, make_frame

N = 32  # a camera crossing the room while it turns, twice: each wall seen from many poses
LAP = 16


def _poses():
    out = []
    for k in range(N):
        a = 2.0 * np.pi * (k % LAP) / LAP + 0.02 * (k // LAP)
        p = (2.0 + 2.0 * (k % LAP) / LAP, 1.5 + 1.0 * (k % LAP) / LAP + 0.03 * (k // LAP), 1.2)
        out.append(look_at(p, (p[0] + 3.0 * np.cos(a), p[1] + 3.0 * np.sin(a), 1.1)))
    return out


@pytest.fixture(scope="module")
def kbs(tmp_path_factory):
    root = tmp_path_factory.mktemp("compact_reanchor")
    with TumWriter(root / "log", CAMERA) as writer:
        for i, T in enumerate(_poses()):
            writer.write(make_frame(box_room(), T, pose_id=i, stamp_s=0.5 * i, noise_m=0.001))
    out = {}
    for keep in ("all", None):  # None: the default
        kb = root / f"kb_{keep}.hiper"
        args = ["perceive", str(root / "log"), "--kb", str(kb), "--stages", "background"]
        result = CliRunner().invoke(app, args + (["--keep-observations", keep] if keep else []))
        assert result.exit_code == 0, result.output
        out[keep] = kb
    shutil.copytree(out[None], root / "kb_copy.hiper")  # untouched by the re-anchoring test
    out["copy"] = root / "kb_copy.hiper"
    return out


def _planes(kb):
    """Per background instance: class, plane offset along its axis and box extent, sorted."""
    with open_kb(kb) as knowledge:
        rows = []
        for i in knowledge.instances(layer="background"):
            n = np.asarray(i.data["plane_map"][:3])
            axis = int(np.argmax(np.abs(n)))
            rows.append((i.class_name, axis, -i.data["plane_map"][3] / n[axis],
                         sorted(float(e) for e in i.box.extent_m)))
        n_obs = knowledge.docs.count(type="observation", layer="background")
    return sorted(rows, key=lambda r: (r[0], r[1], r[2])), n_obs


def test_a_summarised_kb_reanchors_its_walls_as_one_that_kept_everything(kbs, tmp_path):
    before_all, n_all = _planes(kbs["all"])
    before_sum, n_sum = _planes(kbs[None])
    assert n_sum < 0.6 * n_all  # summarised: not every observation of a wall stays
    assert [r[:2] for r in before_sum] == [r[:2] for r in before_all]
    shifted = np.stack(_poses())
    shifted[:, 0, 3] += 0.5
    traj = tmp_path / "optimised.txt"
    write_tum_trajectory(traj, Trajectory.from_matrices(0.5 * np.arange(N), shifted))
    for kb in (kbs["all"], kbs[None]):
        result = CliRunner().invoke(app, ["reanchor", "--kb", str(kb), "--poses", str(traj), "--json"])
        assert result.exit_code == 0, result.output
        assert json.loads(result.output)["merged"] == 0
    after_all, _ = _planes(kbs["all"])
    after_sum, _ = _planes(kbs[None])
    assert len(after_sum) == len(after_all)
    for (cls, _, offset, extent), (_, _, offset_all, extent_all) in zip(after_sum, after_all, strict=True):
        assert offset == pytest.approx(offset_all, abs=0.02), cls
        assert extent == pytest.approx(extent_all, abs=0.1), cls
    moved = [r for r in after_all if r[1] == 0 and r[0] == "wall"]  # walls across x went with the poses
    assert moved and all(any(abs(r[2] - b[2] - 0.5) < 0.03 for b in before_all) for r in moved)


def test_a_plane_seen_again_where_it_was_covered_keeps_little(kbs):
    """The same log again: its views of each plane lie inside what the first session kept."""
    kb = kbs["copy"]
    _, n_first = _planes(kb)
    log = kbs[None].parent / "log"
    args = ["perceive", str(log), "--kb", str(kb), "--stages", "background", "--again"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    with open_kb(kb) as knowledge:
        second = knowledge.docs.count(type="observation", layer="background") - n_first
        planes = len(knowledge.instances(layer="background"))
    assert second <= planes + 2  # about the first sighting of each plane in the session (its evidence)
