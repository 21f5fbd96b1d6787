"""Bounded storage: summarising observations that add nothing, dropping debris; every named query
of ``queries/`` and the plain-words queries answer the same before and after."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.graph import open_kb
from hiper_cli.graph.compact import compact
from hiper_cli.graph.ontology import node
from hiper_cli.model import Box3D, FrameResult, Instance, Observation, World
from hiper_cli.pipeline import PerceiveOptions, perceive
from hiper_cli.query import ask
from hiper_cli.query.templates import template, template_names
from hiper_cli.query.verbs import when
from tests.kb_helpers import FrameList, ProbeStage, make_frame


class StillStage(ProbeStage):
    """The probe's floor and walking cups, plus a chair that stands still and is seen in every
    frame (twice taken for a couch), and a blob in frame 3 that never becomes an object."""

    name = "still"

    def __init__(self, **kw):
        super().__init__(**kw)
        self.chair: Instance | None = None

    def process(self, frame, world: World):
        result: FrameResult = super().process(frame, world)
        chair = self.chair or next((i for i in world.foreground.values() if i.class_name == "chair"), None)
        if chair is None:
            box = Box3D(np.array([2.0, 1.0, 0.45]), np.array([0.5, 0.5, 0.9]))
            chair = Instance("foreground", "chair", box, frame.stamp_s, frame.stamp_s)
        self.chair = chair
        cls = "couch" if frame.pose_id in (7, 8) else "chair"
        o = Observation("foreground", cls, 0.7, frame.stamp_s, frame.pose_id,
                        Box3D(np.array([0.0, 0.0, 2.0]), np.full(3, 0.5)), instance_uuid=chair.uuid)
        chair.observation_uuids.append(o.uuid)
        chair.last_seen_s = max(chair.last_seen_s, frame.stamp_s)
        result.observations.append(o)
        result.instances.append(chair)
        if frame.pose_id == 3:
            result.observations.append(Observation("foreground", "unknown", 0.3, frame.stamp_s, frame.pose_id,
                                                   Box3D(np.array([0.5, 0.5, 1.0]), np.full(3, 0.1))))
        return result


def _log(name, n=60, gap_at=30):
    frames = [make_frame(i) for i in range(n)]
    for f in frames:  # 10 Hz, with a 5 s gap out of view half way
        object.__setattr__(f, "stamp_s", 100.0 + 0.1 * f.pose_id + (5.0 if f.pose_id >= gap_at else 0.0))
    return FrameList(frames, name)


def _answers(kb):
    """Every named query (bound to this KB and to each instance) and some plain-words ones."""
    prefix = f"urn:hiper:kb:{kb.kb_id}:"
    out = {}
    uuids = sorted(i.uuid for i in kb.instances())
    for name in template_names():
        if "?i " in template(name) and "Bound: ?i" in template(name):
            rows = [kb.query_bound(template(name), {"i": node(u)}) for u in uuids]
        else:
            rows = [kb.query_bound(template(name), {"graphPrefix": prefix})]
        out[name] = sorted(json.dumps({k: str(v) for k, v in r.items()}, sort_keys=True)
                           for rs in rows for r in rs)
    for q in ("how many chairs", "where was the chair last seen", "when was the chair first seen", "objects",
              "where is the chair now", "when was the chair last seen", "what changed"):
        a = ask(kb, q).to_dict()
        for hit in a["hits"]:  # the observations a hit names as evidence are those kept
            hit.pop("evidence_uuids")
        out[q] = json.dumps({k: a[k] for k in ("text", "count", "hits", "time")}, sort_keys=True, default=str)
    out["time in view"] = [when(kb, u).to_dict() for u in uuids]
    return out


def test_compaction_keeps_every_answer_and_drops_what_adds_nothing(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        perceive(_log("/logs/a"), kb, [StillStage()], PerceiveOptions())
        perceive(_log("/logs/a2"), kb, [StillStage()], PerceiveOptions())  # the same stamps again
        before = _answers(kb)
        n_before = kb.docs.count(type="observation")
        report = compact(kb)
        after = _answers(kb)
        assert kb.check(repair=False).ok
        assert not kb.docs.find(type="observation", class_name="unknown")
        chair = kb.instances(class_name="chair")[0]
    assert after == before
    assert report.debris_dropped >= 2  # the blob of frame 3 in each session, and merged-away cups
    assert report.bytes_after < report.bytes_before
    assert report.observations_after < 0.5 * n_before
    assert chair.data["observations_summarised"] > 0
    couch_seen = [o for o in chair.observation_uuids]
    assert len(couch_seen) >= 4  # stretch ends and the class changes stay


def test_perceive_summarises_at_the_end_of_a_session_and_kb_compact_reports(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        summary = perceive(_log("/logs/a"), kb, [StillStage()], PerceiveOptions(keep_observations_s=2.0))
        assert summary.storage is not None and summary.storage["summarised"] > 0
        kept = [s for (s,) in kb.docs._db.execute(
            "SELECT stamp_s FROM docs WHERE type = 'observation' AND class IN ('chair', 'couch')")]
        assert sum(s >= 110.9 - 2.0 - 1e-6 for s in kept) == 21  # the last 2 s of raw observations stay
    result = CliRunner().invoke(app, ["kb", "compact", "--kb", str(tmp_path / "kb"), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["observations_after"] <= json.loads(result.output)["observations_before"]
    bad = CliRunner().invoke(app, ["kb", "compact", "--kb", str(tmp_path / "kb"),
                                   "--keep-observations", "soon"])
    assert bad.exit_code != 0 and "expected a duration" in " ".join(bad.output.split())
