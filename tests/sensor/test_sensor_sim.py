"""``hiper sim --sensor``: a simulated log recorded by a real sensor, its truth kept beside it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs import open_log
from hiper_cli.perceive.logs.trajectory import read_tum_trajectory
from hiper_cli.sim import SimConfig, simulate
from hiper_cli.sim.render import RenderConfig

TINY = dict(rate_hz=5.0, mapping_s=1.0, render=RenderConfig(width=128, height=96))


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    root = tmp_path_factory.mktemp("sensor_sim")
    for name in ("ideal", "structured-light"):
        simulate("house", 3.0, 2, root / name, SimConfig(**TINY, sensor=name))
    return root


def test_structured_light_sim_loses_depth_and_drifts_but_keeps_the_exact_trajectory(pair):
    ideal, real = open_log(pair / "ideal"), open_log(pair / "structured-light")
    missing_ideal = np.mean([(f.depth_m == 0).mean() for f in ideal])
    missing_real = np.mean([(f.depth_m == 0).mean() for f in real])
    assert missing_real > missing_ideal + 0.005  # shadows, dropouts
    true = read_tum_trajectory(pair / "structured-light" / "gt" / "groundtruth.txt")
    assert np.allclose(true.positions_m, ideal.info().T_map_cam[:, :3, 3], atol=1e-6)
    drift = np.linalg.norm(real.info().T_map_cam[:, :3, 3] - ideal.info().T_map_cam[:, :3, 3], axis=1)
    assert drift[0] == 0 and drift[1:].max() > 0.001
    sensor = json.loads((pair / "structured-light" / "gt" / "sensor.json").read_text())
    assert sensor["profile"]["name"] == "structured-light"
    assert not (pair / "ideal" / "gt" / "groundtruth.txt").exists()


def test_sensor_sim_is_deterministic(pair, tmp_path):
    simulate("house", 3.0, 2, tmp_path / "again", SimConfig(**TINY, sensor="structured-light"))
    for sub in ("depth", "rgb"):
        for first in sorted((pair / "structured-light" / sub).iterdir()):
            assert first.read_bytes() == (tmp_path / "again" / sub / first.name).read_bytes()
    assert ((pair / "structured-light" / "groundtruth.txt").read_text()
            == (tmp_path / "again" / "groundtruth.txt").read_text())


def test_unknown_sensor_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError, match="sensor profile 'kinect'"):
        simulate("house", 1.0, 0, tmp_path / "x", SimConfig(**TINY, sensor="kinect"))
    result = CliRunner().invoke(app, ["sim", "--sensor", "kinect", "-o", str(tmp_path / "y")])
    assert result.exit_code != 0 and "expected one of ideal, structured-light, tof, stereo" in result.output
