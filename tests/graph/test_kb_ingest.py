"""The ingest fast paths of the document store: cached link counts, the (cell, id) keyed
spatial grid and the migration of stores written with the former 1 m ``obs_grid`` table."""

from __future__ import annotations

import sqlite3
import uuid

import numpy as np
import pytest

from hiper_cli.graph import documents
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
        kb.sync_graph()
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


@pytest.mark.parametrize("staged_rows", [7, 10_000])
def test_staged_and_clustered_rows_answer_the_same(tmp_path, monkeypatch, staged_rows):
    monkeypatch.setattr(documents, "STAGED_ROWS", staged_rows)
    rng = np.random.default_rng(3)
    with open_kb(tmp_path / "kb") as kb:
        env = kb.environment("lab")
        session = kb.start_session(env, "/logs/rand", [])
        tracks = [Instance("foreground", "cup", Box3D(np.zeros(3), np.ones(3)), 0.0, 0.0) for _ in range(3)]
        expected = {}
        for pose in range(30):
            T = np.eye(4)
            T[:3, 3] = rng.uniform(-5, 5, 3)
            obs = [Observation("foreground", "cup", 0.5, float(pose), pose,
                               Box3D(rng.uniform(-2, 2, 3), rng.uniform(0.05, 3.0, 3)), instance_uuid=t.uuid)
                   for t in tracks]
            for o, t in zip(obs, tracks, strict=True):
                expected[o.uuid] = o.box.transformed(T).aabb()
                t.observation_uuids.append(o.uuid)
            kb.write_frame(session, FrameResult(obs, list(tracks)), pose_id=pose, stamp_s=float(pose),
                           T_map_cam=T)
        staged = kb.docs._db.execute("SELECT COUNT(*) FROM obs_cells_new").fetchone()[0]
        assert (staged < 7) if staged_rows == 7 else (staged == 90)
        for _ in range(30):
            lo = rng.uniform(-8, 8, 3)
            hi = lo + rng.uniform(0.1, 3.0, 3)
            truth = {u for u, (a, b) in expected.items() if np.all(b >= lo) and np.all(a <= hi)}
            assert {d["uuid"] for d in kb.docs.in_box(lo.tolist(), hi.tolist(), type="observation")} == truth
        for t in tracks:
            assert kb.docs.get(t.uuid)["observation_uuids"] == t.observation_uuids
            assert len(kb.docs.observations_of(t.uuid)) == 30
        assert kb.docs.link_count() == 90
        kb.sync_graph()
        assert kb.check(repair=False).ok


def test_documents_keep_non_finite_numbers_and_numpy_values():
    doc = {"uuid": "u", "data": {"trajectory": np.array([[0.0, np.nan], [1.0, 2.0]]), "n": np.int64(3)},
           "speed": float("inf"), "none": None}
    text = documents.dumps(doc)
    back = documents.loads(text)
    assert np.isnan(back["data"]["trajectory"][0][1]) and back["speed"] == float("inf")
    assert back["data"]["n"] == 3 and back["none"] is None
    finite = {"uuid": "v", "box": np.arange(3.0), "name": "é"}
    assert documents.loads(documents.dumps(finite)) == {"uuid": "v", "box": [0.0, 1.0, 2.0], "name": "é"}


def test_moving_instances_are_found_where_they_are(tmp_path):
    """Instance boxes are indexed with slack (small moves skip the R*Tree): box queries must
    still answer exactly, before and after a reopen (which forgets the cached index rows)."""
    rng = np.random.default_rng(11)
    kb = open_kb(tmp_path / "kb")
    env = kb.environment("lab")
    session = kb.start_session(env, "/logs/walk", [])
    size_m = np.array([0.5, 0.5, 1.7])
    walkers = [Instance("foreground", "person", Box3D(rng.uniform(-3, 3, 3), size_m), 0.0, 0.0)
               for _ in range(4)]

    def check() -> None:
        for _ in range(40):
            lo = rng.uniform(-5, 5, 3)
            hi = lo + rng.uniform(0.05, 1.5, 3)
            truth = {w.uuid for w in walkers
                     if np.all(w.box.aabb()[1] >= lo) and np.all(w.box.aabb()[0] <= hi)}
            assert {d["uuid"] for d in kb.docs.in_box(lo.tolist(), hi.tolist(), type="instance")} == truth

    for pose in range(60):
        for w in walkers:  # small steps mostly, now and then a jump beyond the slack
            step = rng.normal(0, 0.6 if pose % 10 == 0 else 0.04, 3)
            w.box = Box3D(w.box.center_m + step, w.box.extent_m)
            w.last_seen_s = float(pose)
        kb.write_frame(session, FrameResult([], list(walkers)), pose_id=pose, stamp_s=float(pose))
        if pose % 7 == 0:
            check()
    kb.close()
    kb = open_kb(tmp_path / "kb")
    check()
    for w in walkers:  # after the reopen, one small step each: indexed anew, still exact
        w.box = Box3D(w.box.center_m + 0.05, w.box.extent_m)
    kb.write_frame(session, FrameResult([], list(walkers)), pose_id=60, stamp_s=60.0)
    check()
    kb.close()
