"""`hiper perceive` takes the same log flags as `hiper info`, and bad flags leave no knowledge base."""

import json

from typer.testing import CliRunner

from hiper_cli.cli import app
from tests import REPO_ROOT

FIXTURE = REPO_ROOT / "fixtures" / "house_small"
runner = CliRunner()


def test_wrong_camera_flags_fail_before_a_knowledge_base_is_created(tmp_path):
    kb = tmp_path / "kb.hiper"
    result = runner.invoke(app, ["perceive", str(FIXTURE), "--kb", str(kb), "--preset", "fr1"])
    assert result.exit_code != 0
    assert "256×192" in result.output and "640×480" in result.output
    assert not kb.exists()


def test_log_flags_reach_the_reader(tmp_path):
    kb = tmp_path / "kb.hiper"
    args = ["perceive", str(FIXTURE), "--kb", str(kb), "--stages", "background", "--max-dt", "0.01", "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    assert summary["frames_read"] == 60 and summary["stages"] == ["background"]
    assert summary["observations"]["background"]["wall"] > 0
