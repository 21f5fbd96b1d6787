"""The words users say, answered on a small KB whose truth is written here: a person walks
past a table (within 1 m of its footprint from 5.0 s to 7.0 s), cups stand on the table, a
bottle appears late, a chair's place is seen empty at 11 s. "when did the person pass the
table", "what moved", "anything new", "what is missing", "after the person left" must give
those times and instances."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.errors import QueryError
from hiper_cli.graph import open_kb
from hiper_cli.model import Box3D, FrameResult, Instance, Observation
from hiper_cli.query import ask

STEP_S = 0.5
NOW_S = 12.0


def _box(x_m: float, y_m: float, z_m: float, extent_m: tuple[float, float, float]) -> Box3D:
    return Box3D(np.array([x_m, y_m, z_m]), np.array(extent_m))


@pytest.fixture(scope="module")
def kb_path(tmp_path_factory):
    """Who is seen when (s): the table and cup A 0-12, cup B 1-3, the chair 0-4 (its place
    seen empty at 11), the bottle 10-12, the person 2-12 walking along y = 1 m at 1 m/s from
    x = -4 m (its footprint gap to the table is 1 m at |x| = 1.214 m: stamps 5.0-7.0)."""
    table = Instance("background", "table", _box(0.0, 0.0, 0.375, (1.0, 0.6, 0.75)), 0.0, 0.0)
    cup_a = Instance("foreground", "cup", _box(-0.2, 0.0, 0.8, (0.08, 0.08, 0.1)), 0.0, 0.0)
    cup_b = Instance("foreground", "cup", _box(0.2, 0.0, 0.8, (0.08, 0.08, 0.1)), 1.0, 1.0)
    chair = Instance("foreground", "chair", _box(4.0, 3.0, 0.45, (0.5, 0.5, 0.9)), 0.0, 0.0)
    bottle = Instance("foreground", "bottle", _box(3.0, -2.0, 0.15, (0.08, 0.08, 0.3)), 10.0, 10.0)
    person = Instance("foreground", "person", _box(-4.0, 1.0, 0.9, (0.5, 0.4, 1.8)), 2.0, 2.0,
                      state="dynamic")
    seen = [(table, 0.0, 12.0), (cup_a, 0.0, 12.0), (cup_b, 1.0, 3.0), (chair, 0.0, 4.0),
            (bottle, 10.0, 12.0), (person, 2.0, 12.0)]
    path = tmp_path_factory.mktemp("words") / "kb"
    with open_kb(path) as kb:
        session = kb.start_session(kb.environment("lab"), "probe", ["probe"])
        for pose_id, stamp in enumerate(np.arange(0.0, NOW_S + STEP_S / 2, STEP_S).tolist()):
            result = FrameResult()
            for inst, first, last in seen:
                if not first <= stamp <= last:
                    continue
                if inst is person:
                    inst.box = _box(-4.0 + (stamp - 2.0), 1.0, 0.9, (0.5, 0.4, 1.8))
                obs = Observation(inst.layer, inst.class_name, 0.9, stamp, pose_id, inst.box,
                                  instance_uuid=inst.uuid)
                inst.last_seen_s = stamp
                inst.observation_uuids.append(obs.uuid)
                result.observations.append(obs)
                result.instances.append(inst)
            if stamp == 11.0:  # the chair's place seen empty
                chair.data["vacated_s"] = 11.0
                result.instances.append(chair)
            kb.write_frame(session, result, pose_id=pose_id, stamp_s=stamp, T_map_cam=np.eye(4))
        kb.end_session(session)
        kb.sync_graph()
    return path


def _ask(path, text: str, **kwargs):
    with open_kb(path) as kb:
        return ask(kb, text, pose=(10.0, 10.0, 1.2, 0.0), **kwargs)


def _classes(answer) -> list[str]:
    return sorted(h.class_name for h in answer.hits)


@pytest.mark.parametrize("text", ["when did the person pass the table",
                                  "when did someone walk past the table",
                                  "last time anyone passed the table",
                                  "when was somebody near the table"])
def test_when_did_the_person_pass_the_table(kb_path, text):
    answer = _ask(kb_path, text)
    assert answer.kind == "time" and answer.time is not None
    assert answer.time.stamp_s == pytest.approx(7.0)
    assert _classes(answer) == ["person"]


def test_entering_a_place_is_the_first_sighting_near_it(kb_path):
    assert _ask(kb_path, "when did the person reach the table").time.stamp_s == pytest.approx(5.0)
    assert _ask(kb_path, "when did the person enter the view").time.stamp_s == pytest.approx(2.0)
    assert _ask(kb_path, "when did the person leave").time.stamp_s == pytest.approx(12.0)


def test_counting_and_yes_no_over_passes(kb_path):
    assert _ask(kb_path, "how many people passed the table").count == 1
    assert _ask(kb_path, "did anyone pass the table").value is True
    assert _ask(kb_path, "did anyone pass the chair").value is False  # 1.75 m away at best
    # the window bounds the sightings near the table: none in the last 4 s
    assert _ask(kb_path, "did anyone pass the table in the last 4 seconds").value is False
    assert _ask(kb_path, "did anyone pass the table in the last 6 seconds").value is True


def test_change_words(kb_path):
    assert _classes(_ask(kb_path, "what moved recently")) == ["person"]
    assert _classes(_ask(kb_path, "anything new in the last 5 seconds")) == ["bottle"]
    assert _classes(_ask(kb_path, "what is missing")) == ["chair"]
    assert _ask(kb_path, "is anything missing").value is True
    assert _ask(kb_path, "is anything missing", now_s=10.5).value is False  # before 11 s
    assert _classes(_ask(kb_path, "what changed in the last 5 seconds")) == ["bottle", "chair", "person"]


def test_time_phrases_bound_the_sightings(kb_path):
    assert _classes(_ask(kb_path, "cups seen in the last 3 seconds")) == ["cup"]
    assert _ask(kb_path, "how many cups").count == 2
    assert _ask(kb_path, "how many cups seen in the last 10 seconds").count == 2  # cup B: 1-3 s
    assert _ask(kb_path, "how many cups seen in the last 8 seconds").count == 1
    assert _ask(kb_path, "how many chairs seen 10 seconds ago").count == 1  # at 2 s, +-1 s
    assert _ask(kb_path, "how many chairs seen 2 seconds ago").count == 0


def test_events_bound_the_window(kb_path):
    # the person was last seen at 12 s: after that only what was seen then
    assert sorted(h.uuid for h in _ask(kb_path, "cups seen after the person left").hits) == sorted(
        h.uuid for h in _ask(kb_path, "cups seen in the last 0.5 seconds").hits
    )
    assert _ask(kb_path, "how many cups were on the table before the person arrived").count == 2
    assert _ask(kb_path, "bottles seen before the person arrived").count == 0
    with pytest.raises(QueryError, match=r'no dog was seen .* "the dog was last seen" names no time'):
        _ask(kb_path, "cups seen after the dog left")


def test_closest_to_a_class_ranks_from_it(kb_path):
    with open_kb(kb_path) as kb:
        here = (-10.0, 0.0, 1.2, 0.0)  # cup A (x = -0.2 m) is the nearer to here
        closest = ask(kb, "closest cup", pose=here).hits[0]
        to_bottle = ask(kb, "which cup is closest to the bottle", pose=here).hits  # cup B, x = 0.2 m
    assert closest.center_map_m[0] == pytest.approx(-0.2)
    assert len(to_bottle) == 1 and to_bottle[0].center_map_m[0] == pytest.approx(0.2)


def test_the_name_of_the_whole_place_is_no_filter(kb_path):
    assert _ask(kb_path, "how many cups are there in the lab").count == 2  # the KB's one place
    with pytest.raises(QueryError, match='"kitchen": hiper keeps no named places'):
        _ask(kb_path, "how many cups are there in the kitchen")
