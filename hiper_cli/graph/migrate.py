"""Carrying a knowledge base of an older schema version forward (``hiper kb migrate``).

A migration first copies the document store (the source of truth) into a backup knowledge base
next to the base (``PATH.v1-backup/``: the release that wrote it opens it as it was), then runs
every step from the stored version to ``SCHEMA_VERSION`` and records the new version in one
SQLite transaction: a crash leaves the old base, never half a migration. The scene graph is
derived data: a step that changes what the graph holds marks it for a rebuild (``meta``
``graph_rebuild``), done by the next writable open, so a crash during the rebuild is finished by
the open after it.
"""

from __future__ import annotations

import json
import shutil
import sqlite3
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hiper_cli import DEFAULT_KB
from hiper_cli.errors import KnowledgeBaseError
from hiper_cli.graph.door import DOCUMENTS_FILE
from hiper_cli.graph.location import kb_location
from hiper_cli.graph.sqlite_guard import GuardedConnection, connect_read_only, inspect_existing, translate
from hiper_cli.graph.versions import SCHEMA_VERSION, check_version, stored_version

__all__ = ["GRAPH_REBUILD_KEY", "STEPS", "MigrationReport", "MigrationStep", "backup_path",
           "migrate_documents"]

GRAPH_REBUILD_KEY = "graph_rebuild"


@dataclass(frozen=True)
class MigrationStep:
    """From ``version`` to ``version + 1``: ``apply`` runs inside the migration's transaction."""

    version: int
    what: str
    apply: Callable[[GuardedConnection], None]
    rebuild_graph: bool


def _sessions_aligned(db: GuardedConnection) -> None:
    """Version 1 had no alignment: every session's poses were the map frame (identity)."""
    identity = {"T_map_log": [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0],
                              [0.0, 0.0, 0.0, 1.0]], "method": "identity", "fitness": 1.0, "rmse_m": 0.0}
    for (session_id,) in db.execute("SELECT id FROM sessions").fetchall():
        db.execute("INSERT OR IGNORE INTO meta VALUES (?, ?)",
                   (f"session_align:{int(session_id)}", json.dumps(identity)))


STEPS: dict[int, MigrationStep] = {
    1: MigrationStep(1, "sessions get their alignment (identity: version 1 logs were in the map frame); "
                        "the graph is rebuilt so that instances carry their validity",
                     _sessions_aligned, rebuild_graph=True),
}


@dataclass
class MigrationReport:
    kb: str
    from_version: int
    to_version: int
    backup: str | None = None
    steps: list[str] = field(default_factory=list)

    @property
    def migrated(self) -> bool:
        return self.from_version != self.to_version

    def to_dict(self) -> dict[str, Any]:
        return {"kb": self.kb, "from_version": self.from_version, "to_version": self.to_version,
                "migrated": self.migrated, "backup": self.backup, "steps": self.steps}


def backup_path(root: Path, version: int) -> Path:
    """Where the migration of ``root`` from ``version`` leaves its backup: beside it."""
    return root.with_name(f"{root.name}.v{version}-backup")


def migrate_documents(location: str | Path, *, docs_dir: str | Path | None = None) -> MigrationReport:
    """Migrate the document store of the knowledge base at ``location`` (a directory, or an
    endpoint URL with its documents in ``docs_dir``) to ``SCHEMA_VERSION``, after a backup copy;
    nothing to do when it is current. A newer version than this hiper's is refused. The graph is
    rebuilt by the next writable open (``kb.migrate_kb`` does that at once)."""
    remote, text = kb_location(location)
    root = Path(docs_dir) if docs_dir is not None else (Path(DEFAULT_KB) if remote else Path(text))
    docs_path = root / DOCUMENTS_FILE
    if not docs_path.is_file():
        raise KnowledgeBaseError(f"{root}: no knowledge base there ({DOCUMENTS_FILE} missing); check the "
                                 "--kb path")
    inspect_existing(docs_path)
    found = stored_version(docs_path)
    if found is None or found == SCHEMA_VERSION:
        return MigrationReport(str(root), found or SCHEMA_VERSION, SCHEMA_VERSION)
    if found > SCHEMA_VERSION:
        check_version(root, found)  # raises: newer than this hiper
    missing = [v for v in range(found, SCHEMA_VERSION) if v not in STEPS]
    if missing:
        raise KnowledgeBaseError(f"{root}: schema version {found} has no migration to {SCHEMA_VERSION} "
                                 f"(none from {missing[0]}); export it with the hiper that wrote it and "
                                 "import the export here")
    backup = _backup(docs_path, backup_path(root, found))
    steps = [STEPS[v] for v in range(found, SCHEMA_VERSION)]
    _apply(docs_path, steps)
    return MigrationReport(str(root), found, SCHEMA_VERSION, str(backup), [s.what for s in steps])


def _backup(docs_path: Path, target: Path) -> Path:
    """A consistent copy of the document store (its WAL included) as the knowledge base
    ``target``; one left by an interrupted migration is replaced."""
    if target.exists():
        shutil.rmtree(target)
    try:
        target.mkdir(parents=True)
        src = connect_read_only(docs_path)
        dst = sqlite3.connect(str(target / DOCUMENTS_FILE))
        try:
            src.backup(dst)
        finally:
            dst.close()
            src.close()
    except OSError as err:
        raise KnowledgeBaseError(f"{target}: cannot write the backup before migrating ({err.strerror}); "
                                 "free some space or make the folder beside the base writable") from err
    except sqlite3.Error as err:
        raise translate(target / DOCUMENTS_FILE, err) from err
    return target


def _apply(docs_path: Path, steps: list[MigrationStep]) -> None:
    """Every step and the new version, in one transaction."""
    try:
        raw = sqlite3.connect(str(docs_path), isolation_level=None, timeout=30.0)
    except sqlite3.Error as err:
        raise translate(docs_path, err) from err
    db = GuardedConnection(raw, docs_path)
    try:
        db.execute("BEGIN IMMEDIATE")
        try:
            for step in steps:
                step.apply(db)
            if any(s.rebuild_graph for s in steps):
                db.execute("INSERT OR REPLACE INTO meta VALUES (?, 'pending')", (GRAPH_REBUILD_KEY,))
            db.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION),))
        except BaseException:
            db.execute("ROLLBACK")
            raise
        db.execute("COMMIT")
    finally:
        db.close()
