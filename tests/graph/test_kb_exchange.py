"""Export to every format and import back: the counts round-trip."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import DataError
from hiper_cli.graph import open_kb
from hiper_cli.graph.exchange import export_kb, import_kb, json_export
from hiper_cli.model import Analysis
from hiper_cli.pipeline import PerceiveOptions, perceive
from tests import kb_helpers
from tests.kb_helpers import FrameList, ProbeStage, make_frame

sparql_url = kb_helpers.sparql_url  # fixtures shared with test_kb_graph
kb_location = kb_helpers.kb_location

runner = CliRunner()

SUFFIX = {"turtle": "ttl", "nquads": "nq", "jsonld": "jsonld", "graphml": "graphml", "json": "json"}


def _filled(location, docs_dir):
    kb = open_kb(location, docs_dir=docs_dir)
    log = FrameList([make_frame(i, x_m=0.3 * i) for i in range(10)])
    perceive(log, kb, [ProbeStage()], PerceiveOptions(env_name="lab"))
    kb.put_analyses([Analysis("ods", "cup", 0.0, 9.0, {"mean_mps": 0.3, "cl_mps": 0.1}, 5.0)])
    kb.sync_graph()
    return kb


def _counts(kb):
    """Document counts without sessions (an import does not replay perception runs)."""
    return {k: v for k, v in kb.document_counts().items() if not k.endswith("/Session")}


@pytest.mark.parametrize("fmt", ["turtle", "nquads", "jsonld", "graphml", "json"])
def test_export_import_round_trips_the_counts(kb_location, tmp_path, fmt):
    location, docs_dir = kb_location
    source = _filled(location, docs_dir)
    try:
        out = tmp_path / f"scene.{SUFFIX[fmt]}"
        export_kb(source, out, fmt, observations=True)
        assert out.stat().st_size > 0
        with open_kb(tmp_path / "copy.hiper") as copy:
            summary = import_kb(copy, out)
            assert summary["format"] == fmt
            assert _counts(copy) == _counts(source)
            assert copy.check(repair=False).ok
            src = {i.uuid: i for i in source.instances()}
            for inst in copy.instances():
                original = src[inst.uuid]
                assert inst.class_name == original.class_name and inst.layer == original.layer
                assert inst.state == original.state
                assert inst.last_seen_s == pytest.approx(original.last_seen_s)
                assert inst.box.center_m == pytest.approx(original.box.center_m, abs=1e-4)
                assert sorted(inst.observation_uuids) == sorted(original.observation_uuids)
            (analysis,) = copy.docs.find(type="analysis")
            assert analysis["values"] == {"mean_mps": 0.3, "cl_mps": 0.1}
    finally:
        source.close()


def test_json_export_schema(tmp_path):
    with _filled(str(tmp_path / "kb"), None) as kb:
        data = json_export(kb)
    assert data["format"] == "hiper-kb-export" and data["version"] == 2
    assert [e["name"] for e in data["environments"]] == ["lab"]
    assert data["sessions"][0]["frames"] == 10
    assert data["observations"] == []  # only with observations=True
    # 10 frames, cup tracks of 4 frames: 0-3 (merged away at frame 5), 4-7 and 8-9 live
    cups = sorted((i for i in data["instances"] if i["class"] == "cup"), key=lambda i: i["first_seen_s"])
    assert [c["observation_count"] for c in cups] == [4, 2]
    cup = cups[0]
    assert set(cup) >= {"uuid", "layer", "class", "box", "first_seen_s", "last_seen_s", "motion", "state",
                        "valid_from_s", "valid_to_s", "observation_count", "speed_mps"}
    assert cup["layer"] == "foreground" and cup["motion"] == "dynamic" and cup["state"] == "present"
    assert data["changes"] == []
    # the camera moves 0.3 m and the cup 0.1 m in the camera frame per frame, at 10 Hz
    assert cup["speed_mps"] == pytest.approx(4.0, rel=1e-6)
    assert set(cup["box"]) == {"center_m", "extent_m", "R"}
    (floor,) = [i for i in data["instances"] if i["class"] == "floor"]
    assert floor["observation_count"] == 10 and floor["speed_mps"] is None
    assert data["analyses"][0]["kind"] == "ods"


def test_cli_export_and_import(tmp_path):
    with _filled(str(tmp_path / "kb"), None):
        pass
    for fmt in ("json", "nquads"):
        out = tmp_path / f"out.{SUFFIX[fmt]}"
        result = runner.invoke(app, ["export", str(out), "--kb", str(tmp_path / "kb"), "--json"])
        assert result.exit_code == 0, result.output
        assert json.loads(result.output)["format"] == fmt
        result = runner.invoke(app, ["import", str(out), "--kb", str(tmp_path / f"copy-{fmt}"), "--json"])
        assert result.exit_code == 0, result.output
        counts = json.loads(result.output)["counts"]
        assert counts["instance"] == 3 and counts["environment"] == 1
    result = runner.invoke(app, ["import", str(out), "--kb", str(tmp_path / "copy-text")])
    assert result.exit_code == 0, result.output
    assert "imported 1 environment, 3 instances, 1 analysis into" in result.output
    result = runner.invoke(app, ["export", str(tmp_path / "x.csv"), "--kb", str(tmp_path / "kb")])
    assert result.exit_code == 1 and "cannot tell the format" in " ".join(result.output.split())


def test_import_errors(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "something-else"}')
    broken = tmp_path / "broken.ttl"
    broken.write_text("this is not turtle <<<")
    with open_kb(tmp_path / "kb") as kb:
        with pytest.raises(DataError, match="not a hiper JSON export"):
            import_kb(kb, bad)
        with pytest.raises(DataError, match="cannot read it as turtle"):
            import_kb(kb, broken)
        with pytest.raises(DataError, match="no such file"):
            import_kb(kb, tmp_path / "missing.nq")
