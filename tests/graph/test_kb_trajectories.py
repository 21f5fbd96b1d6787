"""Long instance trajectories are stored apart in chunks: documents read back the same, writes
touch only the chunks that changed, and the graph keeps the instance's mean speed."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.graph import open_kb
from hiper_cli.graph.ontology import speed_mps
from hiper_cli.graph.trajectories import CHUNK_ROWS, INLINE_ROWS
from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.stage import FrameResult


def _chunks(kb, uuid: str) -> int:
    sql = "SELECT COUNT(*) FROM trajectories WHERE instance_uuid = ?"
    return kb.docs._db.execute(sql, (uuid,)).fetchone()[0]


def _body_bytes(kb, uuid: str) -> int:
    return kb.docs._db.execute("SELECT length(body) FROM docs WHERE uuid = ?", (uuid,)).fetchone()[0]


def test_a_long_track_reads_back_the_same_and_writes_little(tmp_path):
    kb = open_kb(tmp_path / "kb")
    env = kb.environment("lab")
    session = kb.start_session(env, "/logs/walk", [])
    walker = Instance("foreground", "person", Box3D(np.zeros(3), np.array([0.5, 0.5, 1.7])), 0.0, 0.0)
    rows: list[list[float]] = []
    walker.data["trajectory"] = rows
    changes = []
    for k in range(700):
        t = k / 30.0
        rows.append([t, 0.6 * t, 0.1 * np.sin(t), 0.9, 0.6, 0.1 * np.cos(t), 0.0])
        walker.last_seen_s = t
        before = kb.docs._db.total_changes
        kb.write_frame(session, FrameResult([], [walker]), pose_id=k, stamp_s=t)
        changes.append(kb.docs._db.total_changes - before)
    doc = kb.docs.get(walker.uuid)
    assert doc["data"]["trajectory"] == rows and "trajectory_rows" not in doc["data"]
    assert _chunks(kb, walker.uuid) == -(-700 // CHUNK_ROWS)
    assert _body_bytes(kb, walker.uuid) < 2000  # the rows are not in the document
    assert max(changes[INLINE_ROWS + 10:]) <= 8  # a frame rewrites one chunk, not the track
    kb.sync_graph()
    got = kb.query(f"SELECT ?v WHERE {{ GRAPH ?g {{ <urn:uuid:{walker.uuid}> hiper:speedMps ?v }} }}")
    assert float(got[0]["v"].value) == pytest.approx(speed_mps({"data": {"trajectory": rows}}), rel=1e-9)
    assert kb.check(repair=False).ok

    # smoothing changes every row, a correction one row in the middle: both come back
    for r in rows:
        r[1] += 0.01
    rows[300][2] = 5.0
    kb.write_frame(session, FrameResult([], [walker]), pose_id=700, stamp_s=23.4)
    assert kb.docs.get(walker.uuid)["data"]["trajectory"] == rows
    rows[301][2] = 6.0  # only this chunk changed
    kb.write_frame(session, FrameResult([], [walker]), pose_id=701, stamp_s=23.5)
    kb.close()

    kb = open_kb(tmp_path / "kb")  # a new connection: nothing cached
    assert kb.docs.get(walker.uuid)["data"]["trajectory"] == rows
    rows.append([24.0, 14.4, 0.0, 0.9, 0.6, 0.0, 0.0])
    kb.write_frame(session, FrameResult([], [walker]), pose_id=702, stamp_s=24.0)
    assert kb.docs.get(walker.uuid)["data"]["trajectory"] == rows
    del rows[100:]  # back under the inline size: the chunks go
    kb.write_frame(session, FrameResult([], [walker]), pose_id=703, stamp_s=24.1)
    assert kb.docs.get(walker.uuid)["data"]["trajectory"] == rows and _chunks(kb, walker.uuid) == 0
    rows.extend([[25.0 + i, 0.0, 0.0, 0.9, 0.0, 0.0, 0.0] for i in range(400)])
    kb.write_frame(session, FrameResult([], [walker]), pose_id=704, stamp_s=25.0)
    assert _chunks(kb, walker.uuid) > 0
    with kb.docs.transaction():
        kb.docs.delete(walker.uuid)
    assert _chunks(kb, walker.uuid) == 0 and kb.docs.get(walker.uuid) is None
    kb.sync_graph()
    assert kb.check(repair=False).ok
    kb.close()


def test_a_failed_frame_leaves_the_stored_trajectory(tmp_path):
    kb = open_kb(tmp_path / "kb")
    env = kb.environment("lab")
    session = kb.start_session(env, "/logs/walk", [])
    cart = Instance("foreground", "cart", Box3D(np.zeros(3), np.ones(3)), 0.0, 0.0)
    cart.data["trajectory"] = [[float(i), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0] for i in range(300)]
    kb.write_frame(session, FrameResult([], [cart]), pose_id=0, stamp_s=0.0)
    stored = [list(r) for r in cart.data["trajectory"]]
    cart.data["trajectory"][-1][1] = 9.0
    with pytest.raises(RuntimeError), kb.docs.transaction():
        kb._put_result(FrameResult([], [cart]), session.id, env.uuid, None)
        raise RuntimeError("the frame fails after its writes")
    assert kb.docs.get(cart.uuid)["data"]["trajectory"] == stored
    kb.write_frame(session, FrameResult([], [cart]), pose_id=1, stamp_s=1.0)  # the cache forgot it
    assert kb.docs.get(cart.uuid)["data"]["trajectory"][-1][1] == 9.0
    kb.close()
