"""The knowledge base under damage and hostile input, through the library: foreign databases are
refused before any write, a damaged graph is rebuilt from the documents, damaged documents get
recovery advice, imports are validated first, exports never destroy what was there."""

from __future__ import annotations

import json
import sqlite3

import pytest

from hiper_cli.errors import DataError, GraphDamagedError, KnowledgeBaseError
from hiper_cli.files import atomic_output
from hiper_cli.graph import open_kb, open_kb_for_reading
from hiper_cli.graph.exchange import export_kb, import_kb
from hiper_cli.pipeline import PerceiveOptions, perceive
from tests.faults import inputs
from tests.kb_helpers import FrameList, ProbeStage, make_frame


def _filled(path):
    kb = open_kb(path)
    perceive(FrameList([make_frame(i, x_m=0.3 * i) for i in range(6)]), kb, [ProbeStage()],
             PerceiveOptions(env_name="lab"))
    return kb


def _digest(path):
    return {p.name: p.read_bytes() for p in path.iterdir() if p.is_file()}


def test_foreign_database_is_refused_before_any_write(tmp_path):
    db_path = inputs.foreign_sqlite(tmp_path / "theirs")
    before = _digest(tmp_path / "theirs")
    with pytest.raises(KnowledgeBaseError, match=r"not a hiper knowledge base \(its tables: notes\)"):
        open_kb(tmp_path / "theirs")
    assert _digest(tmp_path / "theirs") == before  # no meta table, no WAL, no graph folder
    assert sqlite3.connect(db_path).execute("PRAGMA journal_mode").fetchone()[0] == "delete"


def test_a_store_whose_creation_was_killed_before_its_schema_opens_as_new(tmp_path):
    # what a kill -9 right after the journal-mode pragma leaves: an SQLite file with no tables
    (tmp_path / "cut").mkdir()
    db = sqlite3.connect(tmp_path / "cut" / "documents.sqlite")
    db.execute("PRAGMA journal_mode=WAL")
    db.close()
    with open_kb(tmp_path / "cut") as kb:
        assert kb.docs.meta("schema_version") is not None


def test_unsupported_kb_schemes_are_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for location in ("ftp://example.org/kb", "s3://bucket/kb", "HTTP://"):
        with pytest.raises(KnowledgeBaseError, match="--kb"):
            open_kb(location)
    assert list(tmp_path.iterdir()) == []


def test_a_missing_kb_is_not_created_for_reading(tmp_path):
    with pytest.raises(KnowledgeBaseError, match="no knowledge base there"):
        open_kb_for_reading(tmp_path / "typo.hiper")
    with pytest.raises(KnowledgeBaseError, match="no knowledge base there"):
        open_kb(tmp_path / "typo.hiper", create=False)
    assert not (tmp_path / "typo.hiper").exists()


@pytest.mark.parametrize("how", ["sst", "current", "manifest", "file"])
def test_check_rebuilds_a_damaged_graph(tmp_path, how):
    with _filled(tmp_path / "kb") as kb:
        counts = kb.document_counts()
    inputs.damage_graph(tmp_path / "kb", how)
    with pytest.raises(GraphDamagedError, match="hiper kb check"), open_kb(tmp_path / "kb") as kb:
        kb.graph_counts()  # some damage shows only on reading
    with open_kb(tmp_path / "kb", sync=False, rebuild_damaged_graph=True) as kb:
        report = kb.check()
        assert report.repaired and report.ok, report.problems
        assert kb.graph_counts() == counts
    with open_kb(tmp_path / "kb") as kb:
        assert kb.check(repair=False).ok


def test_damaged_documents_get_recovery_advice(tmp_path):
    _filled(tmp_path / "kb").close()
    inputs.damage_documents(tmp_path / "kb")
    with pytest.raises(KnowledgeBaseError, match=r"damaged .* \.recover .*hiper import"), \
            open_kb(tmp_path / "kb", sync=False) as kb:
        kb.check()


@pytest.mark.parametrize(("name", "match"), [
    ("uuid-with-angle-bracket", r"instances\[0\]\.uuid: 'abc>def': it is not a uuid \(8-4-4-4-12"),
    ("unknown-layer", r"instances\[0\]\.layer: 'basement': it is not one of \['background', 'foreground'\]"),
    ("box-of-text", r"instances\[0\]\.box: 'big': it is not of type 'object'"),
    ("box-extent-nan", r"instances\[0\]\.box\.extent_m\[0\]: 'nan': it is not of type 'number'"),
    ("stamp-infinite", r"not valid JSON \(Infinity is not a JSON number\)"),
    ("missing-uuid", r"instances\[0\]: .*'uuid' is a required property"),
    ("instances-not-a-list", "'instances' is a str, expected a list"),
    ("instance-not-an-object", r"instances\[0\] is a int, expected an object"),
    ("top-level-array", "the top level is a JSON list"),
    ("environment-without-name", r"environments\[0\]: .*'name' is a required property"),
])
def test_import_names_the_bad_document_and_field(tmp_path, name, match):
    source = inputs.write_json(tmp_path / "in.json", inputs.HOSTILE_IMPORTS[name])
    with _filled(tmp_path / "kb") as kb:
        before = kb.info()["totals"]
        with pytest.raises(DataError, match=match):
            import_kb(kb, source)
        assert kb.info()["totals"] == before
        assert kb.check(repair=False).ok


def test_deep_nesting_is_refused(tmp_path):
    with open_kb(tmp_path / "kb") as kb, pytest.raises(DataError, match="nested too deeply"):
        import_kb(kb, inputs.deep_nesting(tmp_path / "deep.json"), "json")


def test_confidence_zero_survives_a_json_round_trip(tmp_path):
    source = inputs.write_json(tmp_path / "in.json", inputs.export_doc())
    with open_kb(tmp_path / "kb") as kb:
        import_kb(kb, source)
        export_kb(kb, tmp_path / "back.json", "json")
    (instance,) = json.loads((tmp_path / "back.json").read_text())["instances"]
    assert instance["confidence"] == 0.0


def test_export_refuses_to_write_inside_a_knowledge_base(tmp_path):
    with _filled(tmp_path / "kb") as kb:
        for target in (tmp_path / "kb" / "documents.sqlite", tmp_path / "kb" / "x.json",
                       tmp_path / "kb" / "graph" / "x.ttl"):
            with pytest.raises(DataError, match="inside the knowledge base"):
                export_kb(kb, target, "json")
        assert kb.check(repair=False).ok


def test_a_failed_write_keeps_the_earlier_file(tmp_path):
    target = tmp_path / "out.json"
    target.write_text("earlier")
    with pytest.raises(RuntimeError), atomic_output(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("disk full")
    assert target.read_text() == "earlier"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]
    with pytest.raises(DataError, match="is a folder"), atomic_output(tmp_path):
        pass


def test_graphml_export_escapes_control_characters(tmp_path):
    import xml.etree.ElementTree as ET

    data = inputs.export_doc(environments=[{"uuid": inputs.ENV_UUID, "name": "hall\x01way"}])
    with open_kb(tmp_path / "kb") as kb:
        import_kb(kb, inputs.write_json(tmp_path / "in.json", data))
        export_kb(kb, tmp_path / "out.graphml", "graphml")
    ET.parse(tmp_path / "out.graphml")
    assert "hall\\x01way" in (tmp_path / "out.graphml").read_text()


def test_restart_session_drops_what_it_wrote(tmp_path):
    with _filled(tmp_path / "kb") as kb:
        (session,) = kb.docs.sessions()
        restarted = kb.restart_session(session)
        assert restarted.frames == 0 and not restarted.finished
        assert kb.docs.count(type="observation") == 0 and kb.docs.count(type="instance") == 0
        assert kb.docs.pose_count(session.id) == 0
        assert kb.check(repair=False).ok
