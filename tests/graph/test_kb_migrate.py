"""A knowledge base written by the previous release (ae21d5c, schema version 1) is refused with
the command that migrates it, migrates after a backup in one transaction, and then answers the
queries exactly as that release answered them (its answers are in tests/data)."""

import json
import shutil
import sqlite3
import tarfile
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import KnowledgeBaseError
from hiper_cli.graph import migrate as migrate_module
from hiper_cli.graph import migrate_kb, open_kb, open_kb_for_reading
from hiper_cli.graph.versions import SCHEMA_VERSION, SchemaVersionError, stored_version
from tests import REPO_ROOT

DATA = REPO_ROOT / "tests" / "data"
EXPECTED = json.loads((DATA / "kb_v1_ae21d5c.expected.json").read_text())
runner = CliRunner()


@pytest.fixture
def old_kb(tmp_path: Path) -> Path:
    root = tmp_path / "house.hiper"
    root.mkdir()
    with tarfile.open(DATA / "kb_v1_ae21d5c.tar.gz") as tar:
        tar.extractall(root, filter="data")
    return root


def _bytes(root: Path) -> bytes:
    return (root / "documents.sqlite").read_bytes()


def test_an_old_base_is_refused_with_both_versions_and_the_command(old_kb: Path) -> None:
    before = _bytes(old_kb)
    for opener in (open_kb_for_reading, open_kb):
        with pytest.raises(SchemaVersionError, match=rf"schema version 1, this hiper reads {SCHEMA_VERSION}; "
                           rf"migrate it with 'hiper kb migrate --kb {old_kb}'"):
            opener(old_kb)
    assert _bytes(old_kb) == before  # refused before anything was written
    result = runner.invoke(app, ["query", "chairs", "--kb", str(old_kb)])
    assert result.exit_code == 1 and "hiper kb migrate" in result.output


def test_a_newer_base_is_refused(old_kb: Path) -> None:
    db = sqlite3.connect(old_kb / "documents.sqlite")
    db.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION + 1),))
    db.commit()
    db.close()
    newer = rf"schema version {SCHEMA_VERSION + 1} is newer than this hiper's {SCHEMA_VERSION}"
    with pytest.raises(SchemaVersionError, match=newer):
        open_kb_for_reading(old_kb)
    with pytest.raises(SchemaVersionError, match=newer):
        migrate_kb(old_kb)


def test_migration_keeps_a_backup_and_answers_as_the_old_release(old_kb: Path) -> None:
    result = runner.invoke(app, ["kb", "migrate", "--kb", str(old_kb), "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert (report["from_version"], report["to_version"], report["migrated"]) == (1, SCHEMA_VERSION, True)
    backup = Path(report["backup"])
    assert backup == old_kb.with_name("house.hiper.v1-backup")
    assert stored_version(backup / "documents.sqlite") == 1
    assert stored_version(old_kb / "documents.sqlite") == SCHEMA_VERSION

    for words, expected in EXPECTED["answers"].items():
        out = runner.invoke(app, ["query", words, "--kb", str(old_kb), "--json"])
        assert out.exit_code == 0, out.output
        answer = json.loads(out.output)
        got = {"kind": answer["kind"], "text": answer["text"], "count": answer.get("count"),
               "hits": [h["uuid"] for h in answer.get("hits", [])]}
        assert got == expected, words
    sparql = EXPECTED["sparql"]["query"]
    out = runner.invoke(app, ["query", "--sparql", sparql, "--kb", str(old_kb), "--json"])
    rows = [[b["c"]["value"], b["n"]["value"]] for b in json.loads(out.output)["results"]["bindings"]]
    assert rows == EXPECTED["sparql"]["rows"]

    with open_kb(old_kb, create=False) as kb:
        info = kb.info()
        assert info["totals"] == EXPECTED["totals"] and info["counts"] == EXPECTED["counts"]
        assert kb.check(repair=False).ok  # the graph was rebuilt: instances carry their validity
        assert [r["alignment"]["method"] for r in kb.session_records()] == ["identity"]
    again = migrate_kb(old_kb)
    assert not again.migrated and again.backup is None


def test_a_failed_step_leaves_the_old_base_as_it_was(old_kb: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def boom(db: object) -> None:
        raise KnowledgeBaseError("step failed")

    step = migrate_module.STEPS[1]
    monkeypatch.setitem(migrate_module.STEPS, 1, migrate_module.MigrationStep(1, step.what, boom, True))
    db = sqlite3.connect(old_kb / "documents.sqlite")
    meta_before = sorted(db.execute("SELECT key, value FROM meta"))
    db.close()
    with pytest.raises(KnowledgeBaseError, match="step failed"):
        migrate_kb(old_kb)
    db = sqlite3.connect(old_kb / "documents.sqlite")
    assert sorted(db.execute("SELECT key, value FROM meta")) == meta_before  # rolled back: still version 1
    db.close()
    shutil.rmtree(old_kb.with_name("house.hiper.v1-backup"))
    monkeypatch.undo()
    assert migrate_kb(old_kb).migrated  # and a second try succeeds
