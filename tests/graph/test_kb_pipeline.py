"""``hiper perceive``: the pipeline writes every frame, resumes after the last committed one."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError, KnowledgeBaseError, LogError
from hiper_cli.graph import open_kb
from hiper_cli.perceive import stage as stage_module
from hiper_cli.perceive.logs import TumWriter
from hiper_cli.pipeline import PerceiveOptions, available_stages, build_stages, perceive
from tests.kb_helpers import CAMERA, FrameList, ProbeStage, make_frame

runner = CliRunner()


def _text(result) -> str:
    """The output with rich's line wrapping undone."""
    return " ".join(result.output.split())


@pytest.fixture
def probe_registry(monkeypatch):
    registry = {"probe": "tests.kb_helpers:ProbeStage", "ghost": "hiper_cli.perceive.ghost_stage:Ghost"}
    monkeypatch.setattr(stage_module, "STAGES", registry)
    import hiper_cli.pipeline as pipeline

    monkeypatch.setattr(pipeline, "STAGES", registry)
    return registry


class Crash(Exception):
    pass


class CrashingStage(ProbeStage):
    """A probe stage that dies on one frame, as an interrupted run would."""

    def __init__(self, crash_at: int) -> None:
        super().__init__()
        self.crash_at = crash_at

    def process(self, frame, world):
        if frame.pose_id == self.crash_at:
            raise Crash(f"frame {frame.pose_id}")
        return super().process(frame, world)


def _log(n=12):
    return FrameList([make_frame(i, x_m=0.5 * i) for i in range(n)])


def test_perceive_writes_every_frame_and_summarises(tmp_path):
    done = []
    with open_kb(tmp_path / "kb") as kb:
        summary = perceive(_log(), kb, [ProbeStage()], PerceiveOptions(env_name="lab"),
                           progress=lambda d, t: done.append((d, t)))
        assert kb.check(repair=False).ok
        (session,) = kb.docs.sessions()
        assert session.finished and session.frames == 12
    data = summary.to_dict()
    assert data["frames_read"] == 12 and data["frames_total"] == 12
    assert data["observations"] == {"background": {"floor": 12}, "foreground": {"cup": 12}}
    assert data["instances"] == {"background": {"floor": 1}, "foreground": {"cup": 1}}
    assert data["deleted_instances"] == 2
    assert data["skipped"] == [{"source": "frame-x", "reason": "unreadable png (test)"}]
    assert data["frames_skipped"] == 1
    assert data["environment"] == "lab" and data["frames_per_s"] > 0
    assert done[-1] == (12, 12)


def _instances(kb):
    return sorted((i.layer, i.class_name, len(i.observation_uuids)) for i in kb.instances())


def test_resume_gives_the_instances_of_an_uninterrupted_run(tmp_path):
    with open_kb(tmp_path / "whole") as kb:
        perceive(_log(), kb, [ProbeStage()])
        whole = _instances(kb)
    with open_kb(tmp_path / "kb") as kb:
        with pytest.raises(Crash):
            perceive(_log(), kb, [CrashingStage(crash_at=7)])
        (session,) = kb.docs.sessions()
        assert not session.finished and session.last_pose_id == 6 and session.frames == 7
    with open_kb(tmp_path / "kb") as kb:
        summary = perceive(_log(), kb, [ProbeStage()], PerceiveOptions(resume=True))
        assert summary.frames_read == 12  # the interrupted session is redone in its place
        (session,) = kb.docs.sessions()
        assert session.finished and session.frames == 12
        assert kb.docs.count(type="observation") == 24
        assert _instances(kb) == whole
        assert kb.check(repair=False).ok
        with pytest.raises(KnowledgeBaseError, match="nothing to resume"):
            perceive(_log(), kb, [ProbeStage()], PerceiveOptions(resume=True))


def test_perceiving_a_log_again_is_refused_unless_asked_for(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        perceive(_log(), kb, [ProbeStage()])
        once = (kb.docs.count(type="observation"), _instances(kb))
        with pytest.raises(KnowledgeBaseError, match=r"already in .* --resume .* --replace .* --again"):
            perceive(_log(), kb, [ProbeStage()])
        assert (kb.docs.count(type="observation"), _instances(kb)) == once
        perceive(_log(), kb, [ProbeStage()], PerceiveOptions(on_existing="replace"))
        assert (kb.docs.count(type="observation"), _instances(kb)) == once
        assert len(kb.docs.sessions()) == 1 and kb.check(repair=False).ok
        perceive(_log(), kb, [ProbeStage()], PerceiveOptions(on_existing="again"))
        assert len(kb.docs.sessions()) == 2
        assert kb.docs.count(type="observation") == 2 * once[0]


class UnreadableAt(FrameList):
    """A log whose reader fails on one frame (a corrupt image), in the reading thread."""

    def __init__(self, frames, bad_pose_id: int) -> None:
        super().__init__(frames)
        self.bad_pose_id = bad_pose_id

    def __iter__(self):
        for frame in self.frames:
            if frame.pose_id == self.bad_pose_id:
                raise LogError(f"/logs/codelog/rgb/{frame.pose_id}.png: cannot decode the image")
            yield frame


def test_a_frame_the_reader_cannot_decode_stops_the_run_after_the_frames_before_it(tmp_path):
    # frames are read one thread ahead: the reader's error reaches the caller, in order
    with open_kb(tmp_path / "kb") as kb:
        with pytest.raises(LogError, match=r"5\.png: cannot decode"):
            perceive(UnreadableAt([make_frame(i) for i in range(12)], 5), kb, [ProbeStage()])
        (session,) = kb.docs.sessions()
        assert not session.finished and session.last_pose_id == 4 and session.frames == 5
        assert kb.docs.count(type="observation") == 10
    with open_kb(tmp_path / "kb") as kb:  # opening brings the graph up to the committed frames
        assert kb.check(repair=False).ok


def test_sessions_of_several_logs_accumulate_in_one_environment(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        for name, n in (("/logs/a", 4), ("/logs/b", 3)):
            log = FrameList([make_frame(i) for i in range(n)], name)
            perceive(log, kb, [ProbeStage()], PerceiveOptions(env_name="house"))
        assert [e.name for e in kb.environments()] == ["house"]
        assert [s.frames for s in kb.docs.sessions()] == [4, 3]
        (floor,) = kb.instances(layer="background")
        assert len(floor.observation_uuids) == 7


def test_stage_factories_get_the_log_path_and_options(tmp_path, probe_registry):
    stages, unavailable = build_stages(["probe"], tmp_path / "log", {"probe": {"track_frames": 3}})
    assert stages[0].log_path == tmp_path / "log" and stages[0].track_frames == 3
    assert unavailable == {}
    ok, missing = available_stages()
    assert ok == ["probe"] and "ghost" in missing
    stages, unavailable = build_stages(None, tmp_path / "log")
    assert [s.name for s in stages] == ["probe"] and "not available" in unavailable["ghost"]
    with pytest.raises(ConfigError, match="not available in this version"):
        build_stages(["ghost"], tmp_path / "log")
    with pytest.raises(ConfigError, match="unknown stage"):
        build_stages(["nope"], tmp_path / "log")
    with pytest.raises(ConfigError, match="options given for stage"):
        build_stages(["probe"], tmp_path / "log", {"ghost": {"x": 1}})


class NeedsModel:
    name = "needs_model"

    def __init__(self, log_path=None, model=None):
        if model is None:
            raise ConfigError("stage needs_model: no model file; pass -o needs_model.model=PATH")


def test_default_stages_that_cannot_build_are_reported_not_fatal(tmp_path, monkeypatch):
    import hiper_cli.pipeline as pipeline

    registry = {"probe": "tests.kb_helpers:ProbeStage",
                "needs_model": "tests.graph.test_kb_pipeline:NeedsModel"}
    monkeypatch.setattr(stage_module, "STAGES", registry)
    monkeypatch.setattr(pipeline, "STAGES", registry)
    stages, unavailable = build_stages(None, tmp_path / "log")
    assert [s.name for s in stages] == ["probe"]
    assert "no model file" in unavailable["needs_model"]
    with pytest.raises(ConfigError, match="no model file"):
        build_stages(["probe", "needs_model"], tmp_path / "log")
    with pytest.raises(ConfigError, match="no model file"):
        build_stages(None, tmp_path / "log", {"needs_model": {"model": None}})


def _tum_log(root: Path, n=6) -> Path:
    with TumWriter(root, CAMERA) as writer:
        for i in range(n):
            writer.write(make_frame(i, x_m=0.2 * i))
    return root


def test_cli_perceive_info_check(tmp_path, probe_registry):
    log = _tum_log(tmp_path / "kitchen")
    kb = tmp_path / "scene.hiper"
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(kb), "--stages", "probe",
                                 "-o", "probe.track_frames=2", "--keep-observations", "all", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["frames_read"] == 6 and data["environment"] == "kitchen"
    assert data["observations"]["foreground"]["cup"] == 6
    assert data["kb"] == str(kb)

    result = runner.invoke(app, ["kb", "info", "--kb", str(kb), "--json"])
    assert result.exit_code == 0, result.output
    info = json.loads(result.output)
    assert info["totals"]["observation"] == 12 and info["totals"]["environment"] == 1
    assert info["sessions"][0]["frames"] == 6 and info["size_bytes"] > 0
    assert info["graph_synced_seq"] == info["change_seq"]

    result = runner.invoke(app, ["kb", "check", "--kb", str(kb), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["ok"] is True

    result = runner.invoke(app, ["perceive", str(log), "--kb", str(kb), "--stages", "probe", "--resume"])
    assert result.exit_code != 0 and "nothing to resume" in _text(result)

    result = runner.invoke(app, ["kb", "info", "--kb", str(kb)])
    assert result.exit_code == 0 and "12 observations" in _text(result)


def test_cli_perceive_errors(tmp_path, probe_registry):
    log = _tum_log(tmp_path / "log")
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(tmp_path / "k"), "--stages", "ghost"])
    assert result.exit_code == 2 and "not available" in _text(result)
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(tmp_path / "k"), "-o", "probe.x"])
    assert result.exit_code == 2 and "STAGE.KEY=VALUE" in _text(result)
    result = runner.invoke(app, ["perceive", str(tmp_path / "none"), "--kb", str(tmp_path / "k")])
    assert result.exit_code == 1 and "no such file" in _text(result)
    result = runner.invoke(app, ["kb", "info", "--kb", str(tmp_path / "empty")])
    assert result.exit_code == 1 and "no knowledge base there" in _text(result)
    assert not (tmp_path / "empty").exists()


def test_cli_perceive_progress_bar_and_table(tmp_path, probe_registry):
    log = _tum_log(tmp_path / "hall", 3)
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(tmp_path / "kb"), "--stages", "probe"])
    assert result.exit_code == 0, result.output
    assert "3 frames read" in _text(result) and "floor" in result.output


def test_cli_perceive_timings_report_each_step(tmp_path, probe_registry):
    log = _tum_log(tmp_path / "hall", 3)
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(tmp_path / "kb"), "--stages", "probe",
                                 "--json"])
    assert result.exit_code == 0, result.output
    steps = json.loads(result.output)["steps"]
    assert steps["kb_write_s"]["frames"] >= 3 and steps["kb_write_s"]["total_s"] >= 0
    result = runner.invoke(app, ["perceive", str(log), "--kb", str(tmp_path / "kb2"), "--stages", "probe",
                                 "--timings"])
    assert result.exit_code == 0 and "kb_write_s" in result.output and "per frame read ms" in _text(result)


def test_cli_kb_bench_reports_every_figure():
    result = runner.invoke(app, ["kb", "bench", "--sizes", "300", "--queries", "5", "--json"])
    assert result.exit_code == 0, result.output
    (row,) = json.loads(result.output)
    assert row["observations"] == 300 and row["consistent"] is True
    assert row["ingest_obs_per_s"] > 0 and row["graph_sync_obs_per_s"] > 0 and row["peak_rss_mb"] > 0
    assert set(row["latency"]) == {"by_uuid", "class_in_10s_window", "observations_of_instance",
                                   "spatial_1m_box", "sparql_instances_of_class"}
    result = runner.invoke(app, ["kb", "bench", "--sizes", "4500", "--queries", "5", "--graph-sync-s", "0",
                                 "--json"])
    assert result.exit_code == 0, result.output
    (row,) = json.loads(result.output)  # more than STAGED_ROWS: staged rows were moved once
    assert row["consistent"] is True and row["config"]["graph_sync_s"] == 0
    assert 0 < row["peak_rss_before_final_sync_mb"] <= row["peak_rss_mb"]
    result = runner.invoke(app, ["kb", "bench", "--sizes", "ten"])
    assert result.exit_code == 2 and "comma-separated integers" in _text(result)


def test_a_replaced_session_takes_the_place_cloud_only_it_built_with_it(tmp_path):
    """Perceived again with --replace, a log must not be registered to its own earlier run."""
    import numpy as np

    with open_kb(tmp_path / "kb") as kb:
        perceive(_log(), kb, [ProbeStage()])
        (session,) = kb.docs.sessions()
        env = next(e for e in kb.environments() if e.uuid == session.env_uuid)
        kb.store_map_cloud(env, np.zeros((10, 3)))
        kb.restart_session(session)
        assert kb.map_cloud(env) is None
        other = kb.start_session(env, "another.log", ["probe"])
        kb.store_map_cloud(env, np.zeros((10, 3)))
        kb.restart_session(other)
        assert kb.map_cloud(env) is not None, "another session's cloud stays"
