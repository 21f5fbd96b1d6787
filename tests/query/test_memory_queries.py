"""Questions about change: what changed / moved / is missing / is new, where is X now, when was X
last seen; as plain words, as MCP tools, and over SPARQL. Answers name session and time."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.agent.tools import ToolContext, call_tool
from hiper_cli.errors import QueryError
from hiper_cli.graph import open_kb
from hiper_cli.graph.history import Change
from hiper_cli.model import Box3D, Instance
from hiper_cli.pipeline import perceive
from hiper_cli.query import ask
from hiper_cli.query.history import match
from tests.kb_helpers import FrameList, ProbeStage, make_frame

T0 = 1_800_000_000.0  # logs stamped in Unix time: 2027-01-15 08:00 UTC
CHAIR, CUP, PLANT = ("0b7e2f4c-1c8e-4d0b-9a59-0f3c1d2e3a4" + str(k) for k in (1, 2, 3))


def _inst(cls, xyz, uuid, first, last, **data):
    box = Box3D(np.array(xyz, float), np.array([0.4, 0.4, 0.8]))
    return Instance(layer="foreground", class_name=cls, box=box, first_seen_s=first, last_seen_s=last,
                    uuid=uuid, data=dict(data))


@pytest.fixture
def kb(tmp_path):
    """Two sessions of one place: a chair moved, a bottle gone, a plant brought in (the probe
    stage adds cups of its own)."""
    with open_kb(tmp_path / "kb") as kb:
        for name, start in (("/logs/monday", T0), ("/logs/tuesday", T0 + 7200)):
            frames = [make_frame(i) for i in range(3)]
            for f in frames:
                object.__setattr__(f, "stamp_s", start + f.pose_id)
            perceive(FrameList(frames, name), kb, [ProbeStage()])
        env = kb.environments()[0]
        kb.put_documents([_inst("chair", [3.0, 1.0, 0.4], CHAIR, T0, T0 + 7201).to_dict(),
                          _inst("bottle", [1.0, 1.0, 0.8], CUP, T0, T0 + 2, vacated_s=T0 + 7201).to_dict(),
                          _inst("potted plant", [4.0, 4.0, 0.4], PLANT, T0 + 7202, T0 + 7202).to_dict()],
                         env_uuid=env.uuid)
        tuesday = kb.docs.sessions()[1]
        kb.write_changes(tuesday, [
            Change("moved", "chair", CHAIR, 2, T0 + 7201, [1.0, 2.0, 0.4], [3.0, 1.0, 0.4]),
            Change("removed", "bottle", CUP, 2, T0 + 7201, [1.0, 1.0, 0.8], None),
            Change("added", "potted plant", PLANT, 2, T0 + 7202, None, [4.0, 4.0, 0.4])])
        kb.sync_graph()
        yield kb


def test_the_questions_are_recognised_and_others_are_left_to_the_grammar():
    assert match("What changed since 10:00?").when == "since 10:00"
    assert match("what moved today").kind == "moved"
    assert match("what is missing").kind == "removed"
    assert match("where is the mug now").class_name == "cup"
    assert match("when was the bottle last seen").intent == "last_seen"
    assert match("how many chairs") is None and match("where was the bottle last seen") is None
    with pytest.raises(QueryError, match="no class 'unicorn'"):
        match("where is the unicorn now")


def test_what_changed_names_session_and_time(kb):
    a = ask(kb, "what changed")
    assert a.count == 3 and [c["kind"] for c in a.parsed["changes"]] == ["moved", "removed", "added"]
    assert "session 2 (tuesday)" in a.text and "2027-01-15 10:00:01 UTC" in a.text
    assert ask(kb, "what changed since 09:00").count == 3
    assert ask(kb, "what changed since 10:00:02").count == 1  # the plant, brought at 10:00:02
    assert ask(kb, "what changed in the last 5 minutes", now_s=T0 + 7202 + 60).count == 3
    assert ask(kb, "what changed in the last 5 minutes", now_s=T0 + 7202 + 3600).count == 0
    assert ask(kb, "what moved today").parsed["changes"][0]["from_m"] == [1.0, 2.0, 0.4]
    assert ask(kb, "what changed since yesterday").count == 3


def test_missing_new_where_and_last_seen(kb):
    missing = ask(kb, "what is missing")
    assert missing.count == 1 and missing.hits[0].uuid == CUP
    assert ask(kb, "what is new").hits[0].uuid == PLANT
    where = ask(kb, "where is the chair now")
    assert where.kind == "location" and where.hits[0].center_map_m == (3.0, 1.0, 0.4)
    assert "moved there from (1.00, 2.00, 0.40)" in where.text and "session 2 (tuesday)" in where.text
    assert "no bottle is known to be anywhere now" in ask(kb, "where is the bottle now").text
    seen = ask(kb, "when was the bottle last seen")
    assert seen.kind == "time" and seen.time.stamp_s == T0 + 2
    assert "its place was seen empty at 2027-01-15 10:00:01 UTC" in seen.text


def test_mcp_tools_changes_and_where_is(kb):
    ctx = ToolContext(kb)
    result = call_tool(ctx, "changes", {"kind": "removed"})
    assert not result.is_error and [c["class"] for c in result.data["parsed"]["changes"]] == ["bottle"]
    result = call_tool(ctx, "where_is", {"what": "chairs"})
    assert not result.is_error and result.data["hits"][0]["uuid"] == CHAIR
    assert call_tool(ctx, "changes", {"kind": "exploded"}).is_error


def test_sparql_over_the_events(kb):
    rows = kb.query("SELECT ?cls ?kind ?session WHERE { GRAPH ?g { ?c a hiper:Change ; "
                    "hiper:changeKind ?kind ; hiper:className ?cls ; hiper:inSession ?s . } "
                    "GRAPH ?e { ?s hiper:logPath ?session } } "
                    "ORDER BY ?kind")
    assert [(r["cls"].value, r["kind"].value, r["session"].value) for r in rows] == [
        ("potted plant", "added", "/logs/tuesday"), ("chair", "moved", "/logs/tuesday"),
        ("bottle", "removed", "/logs/tuesday")]
