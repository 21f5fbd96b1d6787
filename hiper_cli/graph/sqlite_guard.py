"""SQLite errors of the document store as ``KnowledgeBaseError``: which file, what happened, the fix.

The store talks to SQLite through ``GuardedConnection``, which turns the errors a user can
meet (a damaged file, a full disk, read-only media, a file of another program) into one-line
errors; cursors are wrapped too, since a damaged page often shows only while rows are read.
``inspect_existing`` looks at an existing file read-only before the store writes anything.
"""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from hiper_cli.errors import KnowledgeBaseError

__all__ = ["GuardedConnection", "connect_read_only", "damaged_error", "inspect_existing", "translate"]


def damaged_error(path: Path, detail: str) -> KnowledgeBaseError:
    return KnowledgeBaseError(
        f"{path}: the document store is damaged ({detail}); recover it with "
        f"'sqlite3 {path} .recover | sqlite3 recovered.sqlite' and put recovered.sqlite in its place, "
        "or import your last export into a new knowledge base ('hiper import EXPORT --kb NEW')"
    )


def translate(path: Path, err: sqlite3.Error) -> KnowledgeBaseError:
    """The one-line error for an SQLite error on the store at ``path``."""
    text = str(err)
    lowered = text.lower()
    if "disk is full" in lowered or "no space" in lowered:
        return KnowledgeBaseError(f"{path}: the disk is full ({text}); free some space and run again "
                                  "(committed frames are kept; --resume continues)")
    if "readonly" in lowered or "read-only" in lowered:
        return KnowledgeBaseError(f"{path}: the knowledge base is read-only ({text}); copy it to a "
                                  "writable folder to change it (reading works in place)")
    if "disk i/o" in lowered:
        return KnowledgeBaseError(f"{path}: the disk failed a read or write ({text}); check the disk "
                                  "and its free space, then run 'hiper kb check'")
    if "locked" in lowered or "busy" in lowered:
        return KnowledgeBaseError(f"{path}: another process holds the knowledge base ({text}); wait for "
                                  "it or use another --kb")
    if type(err) is sqlite3.DatabaseError or "malformed" in lowered or "not a database" in lowered:
        return damaged_error(path, text)
    return KnowledgeBaseError(f"{path}: the document store failed ({text}); run 'hiper kb check'")


class _Cursor:
    def __init__(self, cursor: sqlite3.Cursor, path: Path) -> None:
        self._cursor = cursor
        self._path = path

    def __iter__(self) -> Iterator[Any]:
        try:
            yield from self._cursor
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    def fetchone(self) -> Any:
        try:
            return self._cursor.fetchone()
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    def fetchmany(self, size: int) -> list[Any]:
        try:
            return self._cursor.fetchmany(size)
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    def fetchall(self) -> list[Any]:
        try:
            return self._cursor.fetchall()
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    @property
    def lastrowid(self) -> int | None:
        return self._cursor.lastrowid


class GuardedConnection:
    """An ``sqlite3.Connection`` whose errors name the store's file and the fix."""

    def __init__(self, db: sqlite3.Connection, path: Path) -> None:
        self._db = db
        self._path = path

    def execute(self, sql: str, params: Any = ()) -> _Cursor:
        try:
            return _Cursor(self._db.execute(sql, params), self._path)
        except sqlite3.IntegrityError:
            raise
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    def executemany(self, sql: str, rows: Any) -> _Cursor:
        try:
            return _Cursor(self._db.executemany(sql, rows), self._path)
        except sqlite3.IntegrityError:
            raise
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    def executescript(self, script: str) -> None:
        try:
            self._db.executescript(script)
        except sqlite3.Error as err:
            raise translate(self._path, err) from err

    @property
    def total_changes(self) -> int:
        return self._db.total_changes

    @property
    def in_transaction(self) -> bool:
        return self._db.in_transaction

    def close(self) -> None:
        self._db.close()


def connect_read_only(path: Path) -> sqlite3.Connection:
    """A read-only connection; on read-only media (where SQLite cannot create the WAL index
    beside the file) the file is opened as immutable."""
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True, isolation_level=None)
    try:
        db.execute("SELECT 1 FROM sqlite_master LIMIT 1").fetchone()
        return db
    except sqlite3.OperationalError:
        db.close()
        return sqlite3.connect(f"file:{path}?mode=ro&immutable=1", uri=True, isolation_level=None)


def inspect_existing(path: Path) -> None:
    """Refuse, before anything is written, a ``documents.sqlite`` that is not a hiper store:
    another program's database, a file that is not SQLite, a store too damaged to read its
    header tables. The file is opened read-only."""
    try:
        db = connect_read_only(path)
        try:
            tables = {str(r[0]) for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
            if not tables:  # a store whose creation was cut before its schema: nothing to lose
                return
            if not {"meta", "docs"} <= tables:
                theirs = ", ".join(sorted(tables)[:5]) or "none"
                raise KnowledgeBaseError(
                    f"{path}: not a hiper document store, not a hiper knowledge base (its tables: {theirs}); "
                    "nothing was changed; pass another --kb directory"
                )
            if db.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone() is None:
                raise KnowledgeBaseError(f"{path}: not a hiper document store (no schema version); nothing "
                                         "was changed; pass another --kb directory")
            db.execute("SELECT MAX(id) FROM docs").fetchone()
        finally:
            db.close()
    except sqlite3.DatabaseError as err:
        if "not a database" in str(err).lower():
            raise KnowledgeBaseError(f"{path}: not a hiper document store (not an SQLite file); nothing "
                                     "was changed; pass another --kb directory") from err
        raise translate(path, err) from err
