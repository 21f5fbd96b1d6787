"""Reading a log at a lower rate than it was recorded (``IndexedLog.max_rate_hz``, ``--max-hz``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs import open_log
from hiper_cli.pipeline import PerceiveOptions, perceive_log
from tests import REPO_ROOT
from tests.logs_scene import make_frames
from tests.perceive.logs.test_logs_bags import FORMATS, write_log


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    root = tmp_path_factory.mktemp("rate")
    frames = make_frames(n=9)  # 10 Hz
    return frames, {kind: write_log(root, kind, frames) for kind in FORMATS}


@pytest.mark.parametrize("kind", FORMATS)
def test_a_third_of_the_rate_keeps_every_third_frame_with_its_own_pose_id(scene, kind):
    frames, paths = scene
    reader = open_log(paths[kind])
    reader.max_rate_hz = 10.0 / 3.0  # type: ignore[attr-defined]
    got = list(reader)
    assert [f.pose_id for f in got] == [0, 3, 6]
    assert len(reader.kept_ids()) == 3 and len(reader) == 9  # the log still has its nine frames
    for f in got:  # the kept frames are the log's own, images and all
        np.testing.assert_array_equal(f.rgb, frames[f.pose_id].rgb)
        assert f.stamp_s == pytest.approx(frames[f.pose_id].stamp_s, abs=1e-6)


def test_jittered_stamps_keep_an_even_rate(tmp_path):
    # frames 2 and 6 come 15 % of a step late: 4 and 8 are then 0.185 s after the frame kept before
    frames = [replace(f, stamp_s=f.stamp_s + (0.015 if k % 4 == 2 else 0.0))
              for k, f in enumerate(make_frames(n=9))]
    reader = open_log(write_log(tmp_path, "tum", frames))
    reader.max_rate_hz = 5.0  # type: ignore[attr-defined]
    assert [f.pose_id for f in reader] == [0, 2, 4, 6, 8]


def test_a_rate_above_the_logs_keeps_every_frame(scene):
    _, paths = scene
    reader = open_log(paths["tum"])
    reader.max_rate_hz = 100.0  # type: ignore[attr-defined]
    assert [f.pose_id for f in reader] == list(range(9))


def test_a_rate_of_zero_is_refused():
    with pytest.raises(ConfigError, match="--max-hz 0"):
        PerceiveOptions.from_text(max_rate_hz=0.0)


def test_perceive_at_half_the_rate_reads_half_the_frames(tmp_path):
    log = REPO_ROOT / "fixtures" / "house_small"  # 4 Hz
    options = PerceiveOptions(stages=("background",), max_rate_hz=2.0)
    summary = perceive_log(log, str(tmp_path / "kb.hiper"), options=options)
    every = len(open_log(log))
    assert summary.frames_total == summary.frames_read == (every + 1) // 2


def test_a_live_source_refuses_max_hz(tmp_path):
    from typer.testing import CliRunner

    from hiper_cli.cli import app

    result = CliRunner().invoke(app, ["perceive", "zenoh://tcp/127.0.0.1:7447", "--kb", str(tmp_path / "kb"),
                                      "--max-hz", "10"])
    assert result.exit_code != 0 and "--max-hz is for a recorded log" in result.output
    assert not (tmp_path / "kb").exists()
