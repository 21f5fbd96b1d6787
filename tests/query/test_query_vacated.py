"""An instance whose place a later session saw empty (``data["vacated_s"]``, ``vacated.py``) is
not there after that time: "how many chairs" now leaves it out, asked about an earlier time
it counts, and the mark survives an export and import."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.graph import open_kb
from hiper_cli.graph.exchange import export_kb, import_kb
from hiper_cli.model import Box3D, FrameResult, Instance, Observation
from hiper_cli.query import ask

VACATED_S = 20.0


def _chair(x_m: float) -> Instance:
    box = Box3D(np.array([x_m, 0.0, 0.45]), np.array([0.5, 0.5, 0.9]))
    return Instance("foreground", "chair", box, 1.0, 10.0)


@pytest.fixture
def kb_path(tmp_path):
    kept, gone = _chair(1.0), _chair(3.0)
    path = tmp_path / "kb"
    with open_kb(path) as kb:
        session = kb.start_session(kb.environment("lab"), "probe", ["probe"])
        for pose_id, stamp in enumerate((1.0, 10.0, 30.0)):
            result = FrameResult()
            if stamp <= 10.0:
                for inst in (kept, gone):
                    obs = Observation("foreground", "chair", 0.9, stamp, pose_id, inst.box,
                                      instance_uuid=inst.uuid)
                    inst.observation_uuids.append(obs.uuid)
                    result.observations.append(obs)
                    result.instances.append(inst)
            else:  # a later session saw the second chair's place empty
                gone.data["vacated_s"] = VACATED_S
                result.instances.append(gone)
            kb.write_frame(session, result, pose_id=pose_id, stamp_s=stamp, T_map_cam=np.eye(4))
        kb.end_session(session)
        kb.sync_graph()
    return path


def _count(path, **when) -> int:
    with open_kb(path) as kb:
        answer = ask(kb, "how many chairs", **when)
    assert answer.kind == "count"
    return answer.count


def test_a_vacated_chair_is_not_counted_after_its_place_was_seen_empty(kb_path):
    assert _count(kb_path) == 1  # now: the KB's last stamp, 30 s
    assert _count(kb_path, now_s=VACATED_S + 1.0) == 1
    assert _count(kb_path, now_s=VACATED_S - 1.0) == 2


def test_describe_counts_the_memory_and_says_how_many_are_vacated(kb_path):
    from hiper_cli.query.describe import describe

    with open_kb(kb_path) as kb:
        found = describe(kb)
    (chairs,) = [c for c in found.classes if c.class_name == "chair"]
    assert (chairs.count, chairs.vacated) == (2, 1)
    assert "2 chairs (1 vacated)" in found.text


@pytest.mark.parametrize("fmt", ["json", "turtle"])
def test_the_vacated_mark_survives_export_and_import(kb_path, tmp_path, fmt):
    out = tmp_path / f"export.{'json' if fmt == 'json' else 'ttl'}"
    with open_kb(kb_path) as kb:
        export_kb(kb, out, fmt)
    copy = tmp_path / "copy"
    with open_kb(copy) as kb:
        import_kb(kb, out)
        kb.sync_graph()
    assert _count(copy, now_s=30.0) == 1
