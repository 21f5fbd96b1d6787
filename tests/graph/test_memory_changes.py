"""Changes as data: a session's change events from the place before and after it, stored in both
stores, and the views that say a spot was seen free before."""

from __future__ import annotations

import numpy as np

from hiper_cli.graph import open_kb
from hiper_cli.graph.history import Change, FreeBefore, session_changes, snapshot, validity
from hiper_cli.model import Box3D, Instance
from hiper_cli.pipeline import perceive
from tests.kb_helpers import FrameList, ProbeStage, make_frame


def _inst(cls, x, y, uuid, **data):
    box = Box3D(np.array([x, y, 0.4]), np.array([0.5, 0.5, 0.8]))
    return Instance(layer="foreground", class_name=cls, box=box, first_seen_s=1.0, last_seen_s=5.0,
                    uuid=uuid, data=dict(data))


def _everywhere(_point):
    return True


def test_removed_needs_the_place_seen_empty_unseen_keeps_its_state():
    chair, plant = _inst("chair", 1, 1, "c"), _inst("potted plant", 3, 3, "p")
    before = snapshot([chair, plant])
    chair.data["vacated_s"] = 12.0  # this session saw the chair's place empty; the plant was not seen
    changes = session_changes(before, [chair, plant], 2, seen_before=_everywhere)
    assert [(c.kind, c.instance_uuid, c.stamp_s, c.from_m, c.to_m) for c in changes] == [
        ("removed", "c", 12.0, [1.0, 1.0, 0.4], None)]
    assert validity(chair.to_dict()) == {"valid_from_s": 1.0, "valid_to_s": 12.0, "state": "removed"}
    assert validity(plant.to_dict())["state"] == "present"


def test_moved_when_found_again_elsewhere_and_not_for_jitter():
    chair, bottle = _inst("chair", 1, 1, "c"), _inst("bottle", 2, 2, "b")
    before = snapshot([chair, bottle])
    chair.box = Box3D(np.array([2.5, 1.0, 0.4]), chair.box.extent_m)
    bottle.box = Box3D(np.array([2.2, 2.1, 0.4]), bottle.box.extent_m)  # 0.22 m: noise, not a move
    (moved,) = session_changes(before, [chair, bottle], 2, seen_before=_everywhere)
    assert (moved.kind, moved.from_m[:2], moved.to_m[:2]) == ("moved", [1.0, 1.0], [2.5, 1.0])


def test_added_only_where_earlier_sessions_saw_free_space():
    old = _inst("chair", 0, 0, "old")
    before = snapshot([old])
    free, unseen = _inst("chair", 2, 0, "new1"), _inst("chair", -3, 0, "new2")
    occupied = _inst("chair", 4, 0, "new3")
    floor = np.array([[x, y, 0.0] for x in np.arange(1.0, 5.01, 0.08) for y in np.arange(-0.5, 0.51, 0.08)])
    something = np.array([[4.0, 0.0, 0.5], [4.05, 0.05, 0.3]])  # stood at 4 m, not recognised then
    seen_free = FreeBefore(np.concatenate([floor, something]))
    changes = session_changes(before, [old, free, unseen, occupied], 2, seen_before=seen_free)
    assert [(c.kind, c.instance_uuid) for c in changes] == [("added", "new1")]
    # the first session of a place adds nothing: the place had no objects before
    assert session_changes({}, [old, free], 1, seen_before=seen_free) == []
    assert not FreeBefore(None)(free)


def test_occupied_before_when_the_earlier_cloud_held_its_surface():
    """A chair found where the earlier sessions saw its surface stood there (unrecognised) and
    did not move there; one on floor seen bare, or under a table top (off its surface), did."""
    floor = np.array([[x, y, 0.0] for x in np.arange(-1.0, 5.01, 0.08) for y in np.arange(-0.5, 0.51, 0.08)])
    seat = np.array([[x, y, 0.45] for x in np.arange(3.8, 4.21, 0.08) for y in np.arange(-0.2, 0.21, 0.08)])
    top = np.arange(-0.6, 0.61, 0.08)
    table_top = np.array([[x, y, 0.75] for x in top for y in top[1:-1]])
    before = FreeBefore(np.concatenate([floor, seat, table_top]))
    chair_surface = [[x, y, z] for z in (0.02, 0.45) for x in np.arange(-0.2, 0.21, 0.1) for y in (-0.2, 0.2)]

    def chair(x):
        return _inst("chair", x, 0, f"c{x}", surface_map=[[px + x, py, pz] for px, py, pz in chair_surface])

    assert before.occupied(chair(4.0))  # its seat was in the earlier cloud
    assert not before.occupied(chair(2.0))  # bare floor then
    assert not before.occupied(chair(0.0))  # pushed under the table: the top is 0.3 m above the seat
    assert before.occupied(_inst("chair", 0.0, 0, "box only"))  # no surface: the box holds the top
    assert not FreeBefore(None).occupied(chair(4.0))


def test_walkers_and_debris_make_no_changes():
    person, debris = _inst("person", 0, 0, "p"), _inst("unknown", 1, 0, "u")
    before = snapshot([person, debris])
    person.box = Box3D(np.array([3.0, 0.0, 0.9]), person.box.extent_m)
    assert session_changes(before, [person, debris], 2, seen_before=_everywhere) == []


def test_change_events_are_stored_in_documents_and_graph(tmp_path):
    with open_kb(tmp_path / "kb") as kb:
        perceive(FrameList([make_frame(i) for i in range(3)], "/logs/a"), kb, [ProbeStage()])
        session = kb.docs.sessions()[0]
        kb.write_changes(session, [
            Change("moved", "chair", "c", session.id, 3.5, [1, 1, 0.4], [2, 1, 0.4]),
            Change("removed", "cup", "u", session.id, 4.0, [0, 0, 0.8], None)])
        kb.sync_graph()
        stored = kb.changes()
        assert [(c["kind"], c["class"], c["session"], c["stamp_s"]) for c in stored] == [
            ("moved", "chair", 1, 3.5), ("removed", "cup", 1, 4.0)]
        rows = kb.query("SELECT ?kind ?inst ?t WHERE { GRAPH ?g { ?c a hiper:Change ; "
                        "hiper:changeKind ?kind ; "
                        "prov:used ?inst ; hiper:stampS ?t ; hiper:inSession ?s . } } ORDER BY ?t")
        assert [(r["kind"].value, r["inst"].value) for r in rows] == [("moved", "urn:uuid:c"),
                                                                      ("removed", "urn:uuid:u")]
        report = kb.check(repair=False)
        assert report.ok, report.problems
        assert report.document_counts["foreground/Change"] == 2


def test_json_export_lists_changes_and_validity_and_imports_them_back(tmp_path):
    from hiper_cli.graph.exchange import json_export

    with open_kb(tmp_path / "kb") as kb:
        perceive(FrameList([make_frame(i) for i in range(3)], "/logs/a"), kb, [ProbeStage()])
        session = kb.docs.sessions()[0]
        chair = _inst("chair", 1, 1, "0b7e2f4c-1c8e-4d0b-9a59-0f3c1d2e3a41", vacated_s=9.0)
        kb.put_documents([chair.to_dict()], env_uuid=session.env_uuid)
        gone = Change("removed", "chair", chair.uuid, session.id, 9.0, [1, 1, 0.4], None)
        kb.write_changes(session, [gone])
        data = json_export(kb)
    (change,) = data["changes"]
    keys = ("kind", "class", "instance_uuid", "session", "stamp_s", "from_m", "to_m")
    assert {k: change[k] for k in keys} == {
        "kind": "removed", "class": "chair", "instance_uuid": chair.uuid, "session": 1, "stamp_s": 9.0,
        "from_m": [1, 1, 0.4], "to_m": None}
    (exported,) = [i for i in data["instances"] if i["uuid"] == chair.uuid]
    assert (exported["valid_from_s"], exported["valid_to_s"], exported["state"], exported["motion"]) == (
        1.0, 9.0, "removed", "static")
    import json

    from typer.testing import CliRunner

    from hiper_cli.cli import app

    (tmp_path / "export.json").write_text(json.dumps(data))
    result = CliRunner().invoke(app, ["import", str(tmp_path / "export.json"),
                                      "--kb", str(tmp_path / "copy")])
    assert result.exit_code == 0, result.output
    with open_kb(tmp_path / "copy") as copy:
        assert [c["kind"] for c in copy.changes()] == ["removed"]
        assert copy.instance(chair.uuid).state == "static"


def test_an_addition_whose_box_misses_its_base_tests_the_space_down_to_its_support():
    """A plant stored without its pot (box 0.5-0.8 m) was added where the floor was seen bare,
    from the floor up; not where something stood under it, nor where nothing was seen below."""
    floor = np.array([[x, y, 0.0] for x in np.arange(-0.5, 4.51, 0.08) for y in np.arange(-0.5, 0.51, 0.08)])
    pot = np.array([[3.0 + 0.1 * np.cos(a), 0.1 * np.sin(a), z]
                    for a in np.linspace(0, np.pi, 6) for z in np.arange(0.0, 0.41, 0.05)])
    seen = FreeBefore(np.concatenate([floor[floor[:, 0] < 3.6], pot]))

    def leaves(x):
        return Instance(layer="foreground", class_name="potted plant", uuid=f"p{x}", first_seen_s=1.0,
                        last_seen_s=5.0, box=Box3D(np.array([x, 0.0, 0.65]), np.array([0.3, 0.3, 0.3])))

    assert seen(leaves(1.0))  # bare floor 0.5 m below the box
    assert not seen(leaves(3.0))  # a pot stood there, unrecognised: its side spreads over heights
    assert not seen(leaves(4.0))  # nothing seen under it
    on_top = np.concatenate([floor, np.array([[1.0, 0.0, 0.3], [1.05, 0.02, 0.45]])])
    assert not FreeBefore(on_top)(leaves(1.0))  # something between the floor and the box
