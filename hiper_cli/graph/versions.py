"""The schema version a knowledge base carries, read before anything is written to it.

Every document store holds its layout version in ``meta.schema_version``. A store of an older
version is carried forward by ``hiper kb migrate`` (``migrate.py``); opening it otherwise is
refused with both versions and that command, and a store newer than this hiper is refused
outright. The history of versions is ``HISTORY``: what each one added to what is stored.
"""

from __future__ import annotations

from pathlib import Path

from hiper_cli.errors import KnowledgeBaseError

__all__ = ["HISTORY", "SCHEMA_VERSION", "SchemaVersionError", "check_version", "stored_version"]

SCHEMA_VERSION = 2

HISTORY: dict[int, str] = {
    1: "documents, links, sessions and poses in SQLite; the scene graph derived from them",
    2: "sessions carry their alignment into the map frame; the graph's instances carry their "
       "validity (validFromS, presence, validToS) and change events are stored",
}


class SchemaVersionError(KnowledgeBaseError):
    """A knowledge base of another schema version than this hiper's ``SCHEMA_VERSION``."""

    def __init__(self, message: str, found: int) -> None:
        super().__init__(message)
        self.found = found


def stored_version(docs_path: Path) -> int | None:
    """The schema version of the store at ``docs_path``; None when there is none yet (no file,
    an empty file, a store cut off before its schema). Opens the file read-only."""
    from hiper_cli.graph.sqlite_guard import connect_read_only

    if not docs_path.is_file() or docs_path.stat().st_size == 0:
        return None
    db = connect_read_only(docs_path)
    try:
        tables = {str(r[0]) for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if "meta" not in tables:
            return None
        row = db.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()
    finally:
        db.close()
    return None if row is None else int(row[0])


def check_version(root: Path, found: int | None) -> None:
    """Refuse a knowledge base at ``root`` whose store has schema version ``found`` when it is
    not this hiper's: an older one names the command that migrates it, a newer one asks for a
    newer hiper."""
    if found is None or found == SCHEMA_VERSION:
        return
    if found > SCHEMA_VERSION:
        raise SchemaVersionError(
            f"{root}: schema version {found} is newer than this hiper's {SCHEMA_VERSION}; open it with "
            "the hiper that wrote it, or upgrade hiper (pip install -U hiper)", found)
    raise SchemaVersionError(
        f"{root}: schema version {found}, this hiper reads {SCHEMA_VERSION}; migrate it with "
        f"'hiper kb migrate --kb {root}' (it keeps a backup copy of the old base)", found)
