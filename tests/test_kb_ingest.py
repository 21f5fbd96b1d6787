"""The ingest fast paths of the document store: cached link counts, the (cell, id) keyed
spatial grid and the migration of stores written with the former 1 m ``obs_grid`` table."""

from __future__ import annotations

import sqlite3
import uuid

import numpy as np
import pytest

from hiper_cli.graph.documents import GRID_CELL_M, DocumentStore
from hiper_cli.graph.kb import open_kb
from hiper_cli.model import Box3D, Instance, Observation, new_uuid
from hiper_cli.perceive.stage import FrameResult


def test_new_uuids_are_version_7_and_time_ordered():
    first = new_uuid()
    later = [new_uuid() for _ in range(200)]
    parsed = uuid.UUID(first)
    assert parsed.version == 7 and parsed.variant == uuid.RFC_4122
    assert len(set(later)) == 200
    assert all(u[:8] >= first[:8] for u in later)  # the millisecond prefix never goes back


def _instance_track(kb, frames: int, fail_at: int | None = None) -> Instance:
    env = kb.environment("lab")
    session = kb.start_session(env, "/logs/track", [])
    inst = Instance("foreground", "person", Box3D(np.zeros(3), np.ones(3)), 0.0, 0.0, state="dynamic")
    for f in range(frames):
        obs = Observation("foreground", "person", 0.9, float(f), f, Box3D(np.array([0, 0, 2.0]), np.ones(3)),
                          instance_uuid=inst.uuid if f % 2 else None)
        inst.observation_uuids.append(obs.uuid)
        inst.last_seen_s = float(f)
        result = FrameResult([obs], [inst])
        if f == fail_at:
            with pytest.raises(RuntimeError), kb.docs.transaction():
                kb._put_result(result, session.id, env.uuid, np.eye(4))
                raise RuntimeError("crash inside the frame")
            inst.observation_uuids.pop()
            continue
        kb.write_frame(session, result, pose_id=f, stamp_s=float(f), T_map_cam=np.eye(4))
    return inst


def test_links_follow_the_instance_through_a_rolled_back_frame(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        inst = _instance_track(kb, 12, fail_at=5)
        stored = kb.docs.get(inst.uuid)
        assert stored is not None
        assert sorted(stored["observation_uuids"]) == sorted(inst.observation_uuids)
        assert len(kb.docs.observations_of(inst.uuid)) == 11
    with open_kb(tmp_path / "kb") as kb:  # a fresh connection (empty cache) sees the same
        assert len(kb.docs.observations_of(inst.uuid)) == 11
        assert kb.check(repair=False).ok


def test_rewritten_observation_moves_to_its_new_cell(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        env = kb.environment("lab")
        session = kb.start_session(env, "/logs/move", [])
        obs = Observation("foreground", "cup", 0.5, 0.0, 0, Box3D(np.zeros(3), np.full(3, 0.2)))
        kb.write_frame(session, FrameResult([obs]), pose_id=0, stamp_s=0.0, T_map_cam=np.eye(4))
        T = np.eye(4)
        T[:3, 3] = (10.0, 0.0, 0.0)
        kb.write_frame(session, FrameResult([obs]), pose_id=1, stamp_s=0.1, T_map_cam=T)
        assert kb.docs.in_box([-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]) == []
        assert [d["uuid"] for d in kb.docs.in_box([9.5, -0.5, -0.5], [10.5, 0.5, 0.5])] == [obs.uuid]
        assert kb.docs.integrity_problems() == []


def test_a_store_with_the_former_grid_table_is_migrated(tmp_path):
    path = tmp_path / "documents.sqlite"
    store = DocumentStore(path)
    with store.transaction():
        doc = Observation("foreground", "cup", 0.5, 0.0, 0, Box3D(np.full(3, 0.5), np.full(3, 0.2))).to_dict()
        store.put(doc, box_map=([0.4] * 3, [0.6] * 3))
    store.close()
    db = sqlite3.connect(path)  # rewrite it as the previous schema left it: 1 m cells in obs_grid
    db.executescript(
        "CREATE TABLE obs_grid (id INTEGER PRIMARY KEY, cell INTEGER NOT NULL, min_x REAL, max_x REAL, "
        "min_y REAL, max_y REAL, min_z REAL, max_z REAL);"
        "INSERT INTO obs_grid SELECT id, cell, min_x, max_x, min_y, max_y, min_z, max_z FROM obs_cells;"
        "DELETE FROM obs_cells; DELETE FROM meta WHERE key = 'grid_cell_m';"
    )
    db.close()
    store = DocumentStore(path)
    assert store.meta("grid_cell_m") == "1.0" and GRID_CELL_M != 1.0
    assert [d["uuid"] for d in store.in_box([0.0] * 3, [1.0] * 3)] == [doc["uuid"]]
    assert store.integrity_problems() == []
    store.close()
