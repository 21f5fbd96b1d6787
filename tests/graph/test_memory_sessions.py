"""One knowledge base, one place: logs perceived without ``--env`` join the place already there,
and every session is listed with its log, stamps and alignment in both stores."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.graph import open_kb
from hiper_cli.graph.sessions import Alignment, record_alignment
from hiper_cli.pipeline import PerceiveOptions, perceive
from tests.kb_helpers import FrameList, ProbeStage, make_frame

runner = CliRunner()


def _perceive(kb, name, n, env=None):
    log = FrameList([make_frame(i) for i in range(n)], name)
    return perceive(log, kb, [ProbeStage()], PerceiveOptions(env_name=env))


def test_logs_without_env_join_the_one_place(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        for name, n in (("/logs/monday", 4), ("/logs/tuesday", 3), ("/logs/wednesday", 2)):
            _perceive(kb, name, n)
        assert [e.name for e in kb.environments()] == ["monday"]
        assert [s.frames for s in kb.docs.sessions()] == [4, 3, 2]
        (floor,) = kb.instances(layer="background")  # one floor, not three
        assert len(floor.observation_uuids) == 9
        assert kb.session_records()[2]["environment"] == "monday"


def test_a_new_env_name_starts_another_place_and_then_the_choice_is_asked(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        _perceive(kb, "/logs/home", 2)
        _perceive(kb, "/logs/office", 2, env="office")
        assert sorted(e.name for e in kb.environments()) == ["home", "office"]
        with pytest.raises(ConfigError, match=r"holds 2 places \(home, office\); pass --env"):
            _perceive(kb, "/logs/third", 2)
        _perceive(kb, "/logs/third", 2, env="home")
        assert len(kb.environments()) == 2


def test_kb_sessions_lists_sessions_with_stamps_and_alignment(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        _perceive(kb, "/logs/a", 4)
        _perceive(kb, "/logs/b", 3)
        T = np.eye(4)
        T[:3, 3] = [1.0, -2.0, 0.0]
        with kb.docs.transaction():
            record_alignment(kb.docs, 2, Alignment(T, "registration", fitness=0.9, rmse_m=0.02))
        kb.sync_graph()
        rows = kb.query("SELECT ?s ?f WHERE { GRAPH ?g { ?s a hiper:Session ; hiper:alignmentFitness ?f } }")
        assert sorted(float(r["f"].value) for r in rows) == [0.9, 1.0]
        assert kb.check(repair=False).ok
    result = runner.invoke(app, ["kb", "sessions", "--kb", str(tmp_path / "kb"), "--json"])
    assert result.exit_code == 0, result.output
    sessions = json.loads(result.output)["sessions"]
    assert [s["id"] for s in sessions] == [1, 2]
    assert [s["environment"] for s in sessions] == ["a", "a"]
    assert sessions[0]["first_stamp_s"] < sessions[0]["last_stamp_s"]
    assert sessions[0]["alignment"]["method"] == "identity"  # the first session defines the map frame
    assert sessions[1]["alignment"]["T_map_log"][1][3] == -2.0
    text = runner.invoke(app, ["kb", "sessions", "--kb", str(tmp_path / "kb")])
    assert text.exit_code == 0 and "0.90" in text.output
