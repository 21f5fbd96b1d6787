"""The document store's SQLite tables (``documents.DocumentStore``).

``docs`` holds every document as JSON with its indexed columns; ``docs_box`` (R*Tree) and
``obs_cells`` (a grid of observation boxes) answer spatial reads; ``links`` tie observations to
their instance; the ``*_new`` tables stage index rows before they move into their clustered
tables; ``tombstones`` remember deletions for the graph's sync; ``sessions`` and ``poses`` are
the perceive runs and the camera's pose per frame.
"""

__all__ = ["DOCUMENTS_SCHEMA"]

DOCUMENTS_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS docs (
    id INTEGER PRIMARY KEY,
    uuid TEXT NOT NULL UNIQUE,
    type TEXT NOT NULL,
    layer TEXT,
    class TEXT,
    stamp_s REAL,
    instance_uuid TEXT,
    session_id INTEGER,
    env_uuid TEXT,
    seq INTEGER NOT NULL,
    body TEXT NOT NULL,
    created_seq INTEGER
);
DROP INDEX IF EXISTS docs_type_class_stamp;
CREATE INDEX IF NOT EXISTS docs_type_stamp_class ON docs (type, stamp_s, class);
CREATE INDEX IF NOT EXISTS docs_seq ON docs (seq);
CREATE VIRTUAL TABLE IF NOT EXISTS docs_box USING rtree(id, min_x, max_x, min_y, max_y, min_z, max_z);
CREATE TABLE IF NOT EXISTS obs_cells (
    cell INTEGER NOT NULL, id INTEGER NOT NULL,
    min_x REAL, max_x REAL, min_y REAL, max_y REAL, min_z REAL, max_z REAL,
    PRIMARY KEY (cell, id)
) WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS obs_cells_id ON obs_cells (id);
CREATE TABLE IF NOT EXISTS links (
    instance_uuid TEXT NOT NULL,
    observation_uuid TEXT NOT NULL,
    seq INTEGER NOT NULL,
    PRIMARY KEY (instance_uuid, observation_uuid)
) WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS links_seq ON links (seq);
CREATE TABLE IF NOT EXISTS obs_cells_new (
    id INTEGER PRIMARY KEY, cell INTEGER NOT NULL,
    min_x REAL, max_x REAL, min_y REAL, max_y REAL, min_z REAL, max_z REAL
);
CREATE TABLE IF NOT EXISTS links_new (instance_uuid TEXT NOT NULL, observation_uuid TEXT NOT NULL,
                                      seq INTEGER NOT NULL);
CREATE VIEW IF NOT EXISTS all_links AS
    SELECT instance_uuid, observation_uuid, seq FROM links
    UNION ALL SELECT instance_uuid, observation_uuid, seq FROM links_new;
CREATE TABLE IF NOT EXISTS tombstones (
    uuid TEXT PRIMARY KEY, type TEXT NOT NULL, layer TEXT, seq INTEGER NOT NULL
) WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS tombstones_seq ON tombstones (seq);
CREATE TABLE IF NOT EXISTS sessions (
    id INTEGER PRIMARY KEY,
    env_uuid TEXT NOT NULL,
    log_path TEXT NOT NULL,
    stages TEXT NOT NULL,
    started_s REAL NOT NULL,
    ended_s REAL,
    frames INTEGER NOT NULL DEFAULT 0,
    last_pose_id INTEGER,
    last_stamp_s REAL,
    seq INTEGER NOT NULL
);
CREATE INDEX IF NOT EXISTS sessions_seq ON sessions (seq);
CREATE TABLE IF NOT EXISTS poses (
    session_id INTEGER NOT NULL,
    pose_id INTEGER NOT NULL,
    stamp_s REAL NOT NULL,
    T_map_cam TEXT NOT NULL,
    PRIMARY KEY (session_id, pose_id)
) WITHOUT ROWID;
"""
