"""Every example query of the query issue, on a KB built from a ``hiper sim`` house log,
answers what the simulator's ground truth says (expectations computed here from the truth:
pinhole projection with the log's camera, truth boxes, truth tracks and id images)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiper_cli.graph import open_kb
from hiper_cli.query import ask
from hiper_cli.query.geometry import Frustum
from hiper_cli.query.spec import QueryConfig
from tests.query_truth_kb import TruthKb, house_truth_kb


@pytest.fixture(scope="module")
def house() -> TruthKb:
    return house_truth_kb()


def _config(h: TruthKb) -> QueryConfig:
    w, hgt, fx, fy = (h.camera[k] for k in ("width", "height", "fx", "fy"))
    return QueryConfig(
        frustum=Frustum(
            math.degrees(2 * math.atan(w / 2 / fx)), math.degrees(2 * math.atan(hgt / 2 / fy)), 5.0
        )
    )


def _seen_by(h: TruthKb, stamp: float) -> set[int]:
    return {tid for tid, stamps in h.seen.items() if stamps[0] <= stamp}


def _ids(h: TruthKb, answer) -> set[int]:
    return {h.id_of(hit.uuid) for hit in answer.hits}


def _footprint_distance(xy, box) -> float:
    lo, hi = box.aabb()
    gap = np.maximum(np.maximum(lo[:2] - xy, xy - hi[:2]), 0.0)
    return float(np.linalg.norm(gap))


def _in_image(h: TruthKb, T_map_cam, point) -> bool:
    p = np.linalg.inv(T_map_cam) @ np.append(point, 1.0)
    if p[2] <= 0 or np.linalg.norm(p[:3]) > 5.0:
        return False
    u = h.camera["fx"] * p[0] / p[2] + h.camera["cx"]
    v = h.camera["fy"] * p[1] / p[2] + h.camera["cy"]
    return -0.5 <= u <= h.camera["width"] - 0.5 and -0.5 <= v <= h.camera["height"] - 0.5


def _of_class(h: TruthKb, name: str) -> list[int]:
    return [tid for tid, ti in h.truth.instances.items() if ti.class_name == name]


def test_cups_in_fov(house):
    h = house
    # a frame in which the camera sees at least one cup
    cups = set(_of_class(h, "cup"))
    stamp = max(t for tid in cups & set(h.seen) for t in h.seen[tid])
    T = dict(h.poses)[stamp]
    expected = {
        tid for tid in cups & _seen_by(h, stamp) if _in_image(h, T, h.truth.instances[tid].box.center_m)
    }
    assert expected, "the chosen frame must show a cup"
    with open_kb(h.path) as kb:
        answer = ask(kb, "cups in FOV", at_s=stamp, config=_config(h))
    assert answer.kind == "list"
    assert _ids(h, answer) == expected


def test_closest_table(house):
    h = house
    with open_kb(h.path) as kb:
        answer = ask(kb, "closest table")
    _stamp, T = h.poses[-1]
    tables = [tid for tid in _of_class(h, "table") if tid in h.seen]
    expected = min(tables, key=lambda tid: _footprint_distance(T[:2, 3], h.truth.instances[tid].box))
    assert _ids(h, answer) == {expected}
    assert answer.goal is not None and answer.goal.target_uuid == h.uuid_of[expected]


def test_people_moving_in_the_last_10_minutes(house):
    h = house
    now = h.poses[-1][0]
    expected = {
        tid
        for tid in _of_class(h, "person")
        if tid in h.seen and h.truth.instances[tid].state == "dynamic" and h.seen[tid][-1] >= now - 600
    }
    assert expected
    with open_kb(h.path) as kb:
        assert _ids(h, ask(kb, "people moving in the last 10 minutes")) == expected
        assert _ids(h, ask(kb, "static people")) == set()
        # a window that ends before the person appeared holds nobody
        first = min(h.seen[tid][0] for tid in expected)
        assert _ids(h, ask(kb, "people moving in the last 2 s", at_s=first - 0.5)) == set()


def test_where_was_the_bottle_last_seen(house):
    h = house
    bottles = [tid for tid in _of_class(h, "bottle") if tid in h.seen]
    last = max(h.seen[tid][-1] for tid in bottles)
    expected = {tid for tid in bottles if h.seen[tid][-1] == last}
    with open_kb(h.path) as kb:
        answer = ask(kb, "where was the bottle last seen")
    assert answer.kind == "location" and len(answer.hits) == 1
    (tid,) = _ids(h, answer)
    assert tid in expected
    assert np.allclose(answer.hits[0].center_map_m, h.truth.instances[tid].box.center_m, atol=1e-4)
    assert answer.hits[0].last_seen_s == pytest.approx(last)


def test_how_many_chairs(house):
    h = house
    expected = len([tid for tid in _of_class(h, "chair") if tid in h.seen])
    with open_kb(h.path) as kb:
        answer = ask(kb, "how many chairs")
    assert answer.kind == "count" and answer.count == expected


def test_objects_on_the_closest_table(house):
    h = house
    T = h.poses[-1][1]
    tables = [tid for tid in _of_class(h, "table") if tid in h.seen]
    table = min(tables, key=lambda tid: _footprint_distance(T[:2, 3], h.truth.instances[tid].box))
    lo, hi = h.truth.instances[table].box.aabb()
    expected = set()
    for tid in h.seen:
        ti = h.truth.instances[tid]
        if ti.layer != "foreground" or ti.state != "static":
            continue
        blo, _bhi = ti.box.aabb()
        c = ti.box.center_m
        if lo[0] <= c[0] <= hi[0] and lo[1] <= c[1] <= hi[1] and abs(blo[2] - hi[2]) < 0.05:
            expected.add(tid)
    assert expected, "the closest table must carry something"
    with open_kb(h.path) as kb:
        answer = ask(kb, "objects on the closest table")
    assert _ids(h, answer) == expected
    assert all(hit.support is not None and hit.support.uuid == h.uuid_of[table] for hit in answer.hits)


def test_when_did_a_person_last_pass_here(house):
    h = house
    (person,) = [tid for tid in _of_class(h, "person") if tid in h.seen]
    stamps = h.seen[person]
    here = h.truth.position_at(person, stamps[len(stamps) // 2])
    near = [t for t in stamps if np.hypot(*(h.truth.position_at(person, t)[:2] - here[:2])) <= 1.0]
    with open_kb(h.path) as kb:
        answer = ask(kb, "when did a person last pass here", pose=(here[0], here[1], 1.2, 0.0))
        assert answer.kind == "time"
        assert answer.time is not None and answer.time.stamp_s == pytest.approx(max(near))
        assert _ids(h, answer) == {person}
        # from a place nobody walked past, no time
        far = ask(kb, "when did a person last pass here", pose=(-50.0, -50.0, 1.2, 0.0))
        assert far.time is None and far.hits == ()


def test_hits_carry_evidence_and_times(house):
    h = house
    with open_kb(h.path) as kb:
        answer = ask(kb, "how many chairs")
        hit = ask(kb, "closest chair").hits[0]
        assert len(hit.evidence_uuids) == hit.observation_count == len(h.seen[h.id_of(hit.uuid)])
        assert {o.uuid for o in kb.observations_of(hit.uuid)} == set(hit.evidence_uuids)
        data = hit.to_dict(answer.now_s)
        assert data["last_seen"]["iso"] is None  # a simulated log's clock has no date
        assert data["last_seen"]["ago"].endswith("ago") or data["last_seen"]["ago"] == "just now"


@pytest.mark.parametrize("far_first", [True, False])
def test_a_tie_goes_to_the_nearer_in_any_write_order(tmp_path, far_first):
    """Two cups last seen in one frame: "where was the cup last seen" names the nearer one,
    whichever was written (and given its uuid) first; the same question, the same answer."""
    from hiper_cli.model import Box3D, FrameResult, Instance, Observation

    def cup(x_m: float) -> Instance:
        return Instance("foreground", "cup", Box3D(np.array([x_m, 0.0, 0.8]), np.full(3, 0.1)), 1.0, 2.0)

    cups = [cup(3.0), cup(1.0)] if far_first else [cup(1.0), cup(3.0)]
    with open_kb(tmp_path / "kb") as kb:
        session = kb.start_session(kb.environment("lab"), "probe", ["probe"])
        for pose_id, stamp in enumerate((1.0, 2.0)):
            result = FrameResult()
            for inst in cups:
                obs = Observation("foreground", "cup", 0.9, stamp, pose_id, inst.box, instance_uuid=inst.uuid)
                inst.observation_uuids.append(obs.uuid)
                result.observations.append(obs)
                result.instances.append(inst)
            kb.write_frame(session, result, pose_id=pose_id, stamp_s=stamp, T_map_cam=np.eye(4))
        kb.end_session(session)
        kb.sync_graph()
        answer = ask(kb, "where was the cup last seen", pose=(0.0, 0.0, 1.2, 0.0))
    assert answer.hits, answer.text
    assert answer.hits[0].center_map_m[0] == pytest.approx(1.0)
