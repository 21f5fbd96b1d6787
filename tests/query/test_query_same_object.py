"""One real object is one instance to the reader, whatever layers found it: a mapped table is a
background top and a foreground body linked by ``same_object_as`` (``geometry_only.py``). "How
many tables" counts it once, "closest table" answers it once, the JSON export names the body
``table`` in the foreground with the link, and the link survives export and import."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hiper_cli.graph import open_kb
from hiper_cli.graph.exchange import export_kb, import_kb
from hiper_cli.model import Box3D, FrameResult, Instance, Observation
from hiper_cli.query import ask, count


def _top(x_m: float) -> Instance:
    box = Box3D(np.array([x_m, 0.0, 0.74]), np.array([1.6, 0.9, 0.02]))
    return Instance("background", "table", box, 1.0, 10.0)


def _body(top: Instance, class_name: str = "table") -> Instance:
    centre = top.box.center_m.copy()
    centre[2] = 0.375
    body = Instance("foreground", class_name, Box3D(centre, np.array([1.6, 0.9, 0.75])), 1.0, 10.0)
    body.data["same_object_as"] = top.uuid
    return body


@pytest.fixture
def kb_path(tmp_path):
    """Two tables found by both layers (one body named by the detector, one not), one table only
    the background maps, and a chair."""
    near, far, alone = _top(2.0), _top(5.0), _top(8.0)
    chair_box = Box3D(np.array([2.0, 1.0, 0.45]), np.array([0.5, 0.5, 0.9]))
    chair = Instance("foreground", "chair", chair_box, 1.0, 10.0)
    path = tmp_path / "kb"
    with open_kb(path) as kb:
        session = kb.start_session(kb.environment("lab"), "probe", ["probe"])
        obs = Observation("foreground", "chair", 0.9, 1.0, 0, chair.box, instance_uuid=chair.uuid)
        chair.observation_uuids.append(obs.uuid)
        result = FrameResult(observations=[obs],
                             instances=[near, far, alone, chair, _body(near), _body(far, "unknown")])
        kb.write_frame(session, result, pose_id=0, stamp_s=10.0, T_map_cam=np.eye(4))
        kb.end_session(session)
        kb.sync_graph()
    return path


def _ask(path, text: str, **when):
    with open_kb(path) as kb:
        return ask(kb, text, **when)


def test_a_table_found_by_both_layers_is_counted_once(kb_path):
    assert _ask(kb_path, "how many tables").count == 3
    assert _ask(kb_path, "how many chairs").count == 1
    assert _ask(kb_path, "how many unknown objects").count == 0  # the unnamed body is its table
    with open_kb(kb_path) as kb:  # the agent's and MCP's count verb
        assert count(kb, "table") == 3


def test_the_closest_table_answers_the_table_once(kb_path):
    with open_kb(kb_path) as kb:
        answer = ask(kb, "closest table", pose=(2.0, -2.0, 0.0, 0.0))
    assert [(hit.layer, hit.class_name) for hit in answer.hits] == [("background", "table")]
    assert answer.hits[0].center_map_m[0] == pytest.approx(2.0)
    listed = _ask(kb_path, "find tables").hits
    assert sorted(round(hit.center_map_m[0]) for hit in listed) == [2, 5, 8]  # each table once


def test_the_export_names_the_body_a_table_and_links_it(kb_path, tmp_path):
    out = tmp_path / "export.json"
    with open_kb(kb_path) as kb:
        export_kb(kb, out, "json")
    instances = json.loads(out.read_text())["instances"]
    tops = {i["uuid"]: i for i in instances if i["layer"] == "background"}
    bodies = [i for i in instances if i.get("same_object_as")]
    assert sorted(b["class"] for b in bodies) == ["table", "unknown"]
    for body in bodies:
        assert body["layer"] == "foreground" and tops[body["same_object_as"]]["class"] == "table"
    # a reader counts each real object once: an instance linked to another one in the export is that one
    uuids = {i["uuid"] for i in instances}
    real = [i for i in instances if i.get("same_object_as") not in uuids]
    assert sum(i["class"] == "table" for i in real) == 3


def test_the_link_is_in_the_graph(kb_path):
    with open_kb(kb_path) as kb:
        rows = kb.query("SELECT ?body ?top WHERE { GRAPH ?g { ?body hiper:sameObjectAs ?top } }")
    assert len(rows) == 2


@pytest.mark.parametrize("fmt", ["json", "turtle"])
def test_the_link_survives_export_and_import(kb_path, tmp_path, fmt):
    out = tmp_path / f"export.{'json' if fmt == 'json' else 'ttl'}"
    with open_kb(kb_path) as kb:
        export_kb(kb, out, fmt)
    copy = tmp_path / "copy"
    with open_kb(copy) as kb:
        import_kb(kb, out)
        kb.sync_graph()
    assert _ask(copy, "how many tables", now_s=10.0).count == 3  # an import has no robot path
