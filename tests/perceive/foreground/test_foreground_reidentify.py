"""Re-identification across sessions (``reidentify.py``): a static object a later session tracks
again joins the earlier session's instance; other classes, objects that moved and things stacked
above one another do not; a walker joins only one seen at the same times and place; and a second
session of one log leaves one instance per object, people included."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from hiper_cli.graph import open_kb
from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground.reidentify import (
    cosighted_pairs,
    fold,
    fold_mover,
    moved_pairs,
    pairs,
    still_seen,
)
from hiper_cli.perceive.foreground.stage import ForegroundStage
from hiper_cli.perceive.foreground.stitch import footprint_share
from hiper_cli.perceive.logs import open_log
from hiper_cli.pipeline import PerceiveOptions, perceive
from tests import REPO_ROOT

FIXTURE = REPO_ROOT / "fixtures" / "house_small"
SHARE, GAP_M = 0.5, 0.3


def _inst(cls, lower, upper, *, obs=("a",), t=(0.0, 1.0), rows=None):
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    return Instance(layer="foreground", class_name=cls, box=Box3D((lower + upper) / 2, upper - lower),
                    first_seen_s=t[0], last_seen_s=t[1], observation_uuids=list(obs),
                    data={"trajectory": rows or []})


def _pairs(new, earlier):
    return [(e.uuid, n.uuid) for e, n in pairs(new, earlier, min_share=SHARE, max_gap_m=GAP_M)]


def test_footprint_share_is_of_the_smaller_footprint_and_nothing_when_stacked():
    chair = Box3D([0.0, 0.0, 0.45], [0.5, 0.5, 0.9]).aabb()
    shifted = Box3D([0.25, 0.0, 0.45], [0.5, 0.5, 0.9]).aabb()
    assert footprint_share(chair, shifted, max_gap_m=GAP_M) == pytest.approx(0.5)
    big = Box3D([0.0, 0.0, 0.45], [2.0, 2.0, 0.9]).aabb()
    assert footprint_share(chair, big, max_gap_m=GAP_M) == pytest.approx(1.0)
    assert footprint_share(chair, big, max_gap_m=GAP_M, larger=True) == pytest.approx(0.0625)
    shelf_above = Box3D([0.0, 0.0, 1.6], [0.5, 0.5, 0.2]).aabb()  # 0.6 m above the chair's top
    assert footprint_share(chair, shelf_above, max_gap_m=GAP_M) == 0.0


def test_a_chair_seen_again_pairs_with_its_earlier_instance_only():
    earlier_chair = _inst("chair", [1.0, 1.0, 0.0], [1.5, 1.5, 0.9])
    earlier_bed = _inst("bed", [3.0, 0.0, 0.0], [5.0, 1.0, 0.6])
    chair = _inst("chair", [1.1, 1.05, 0.0], [1.6, 1.5, 0.85])  # another side seen: 0.1 m off
    moved = _inst("chair", [2.0, 1.0, 0.0], [2.5, 1.5, 0.9])  # a chair somewhere else
    cup_on_bed = _inst("cup", [3.5, 0.5, 0.6], [3.6, 0.6, 0.7])  # another class, inside the bed
    got = _pairs([chair, moved, cup_on_bed], [earlier_chair, earlier_bed])
    assert got == [(earlier_chair.uuid, chair.uuid)]


def test_pairs_are_one_to_one_best_overlap_first():
    left = _inst("chair", [0.0, 0.0, 0.0], [0.5, 0.5, 0.9])
    right = _inst("chair", [0.5, 0.0, 0.0], [1.0, 0.5, 0.9])
    near_right = _inst("chair", [0.3, 0.0, 0.0], [0.8, 0.5, 0.9])  # 60 % on right, 40 % on left
    near_left = _inst("chair", [0.0, 0.0, 0.0], [0.5, 0.5, 0.9])
    got = _pairs([near_right, near_left], [left, right])
    assert sorted(got) == sorted([(right.uuid, near_right.uuid), (left.uuid, near_left.uuid)])
    assert _pairs([near_right], [left, right]) == [(right.uuid, near_right.uuid)]


def test_an_unknown_pairs_only_when_it_fills_the_larger_footprint():
    """An unknown blob around several things is not the object: the larger footprint counts."""
    pile = _inst("unknown", [0.0, 0.0, 0.0], [2.0, 2.0, 0.5])
    box = _inst("unknown", [0.0, 0.0, 0.0], [0.5, 0.5, 0.5])
    assert _pairs([box], [pile]) == []
    again = _inst("unknown", [0.1, 0.0, 0.0], [2.0, 1.9, 0.5])
    assert _pairs([again], [pile]) == [(pile.uuid, again.uuid)]


def _moved(new, gone):
    return sorted((e.uuid, n.uuid) for e, n in moved_pairs(new, gone, max_m=3.0))


def test_moves_are_one_assignment_over_the_class_not_nearest_first():
    """Two chairs taken away, two set down: nearest first pairs the middle one with the right
    chair and leaves the far one unexplained (an addition and a removal); the assignment finds
    both moves."""
    left = _inst("chair", [-0.25, -0.25, 0.0], [0.25, 0.25, 0.9])
    right = _inst("chair", [1.75, -0.25, 0.0], [2.25, 0.25, 0.9])
    middle = _inst("chair", [0.95, -0.25, 0.0], [1.45, 0.25, 0.9])  # 1.2 m from left, 0.8 from right
    far = _inst("chair", [3.05, -0.25, 0.0], [3.55, 0.25, 0.9])  # 3.3 m from left, 1.3 from right
    assert _moved([middle, far], [left, right]) == sorted([(left.uuid, middle.uuid), (right.uuid, far.uuid)])
    assert _moved([middle], [left, right]) == [(right.uuid, middle.uuid)]  # one set down: the nearest


def test_a_move_goes_to_the_object_of_its_shape_and_support():
    tall = _inst("potted plant", [-0.2, -0.2, 0.0], [0.2, 0.2, 1.2])
    small = _inst("potted plant", [1.8, -0.2, 0.0], [2.2, 0.2, 0.5])
    seen = _inst("potted plant", [0.6, -0.2, 0.0], [1.0, 0.2, 0.5])  # 0.8 m from tall, 1.2 from small
    assert _moved([seen], [tall, small]) == [(small.uuid, seen.uuid)]
    on_table = _inst("cup", [0.0, 0.0, 0.75], [0.1, 0.1, 0.85])
    on_floor = _inst("cup", [1.5, 0.0, 0.0], [1.6, 0.1, 0.1])
    on_a_table = _inst("cup", [1.0, 0.0, 0.74], [1.1, 0.1, 0.84])  # nearer the floor one's place
    assert _moved([on_a_table], [on_table, on_floor]) == [(on_table.uuid, on_a_table.uuid)]
    in_reach = _inst("cup", [3.6, 0.0, 0.0], [3.7, 0.1, 0.1])  # 2.1 m
    assert _moved([in_reach], [on_floor]) == [(on_floor.uuid, in_reach.uuid)]
    assert _moved([_inst("cup", [4.7, 0.0, 0.0], [4.8, 0.1, 0.1])], [on_floor]) == []  # beyond 3 m


def test_a_place_seen_empty_with_its_object_seen_there_all_the_same_is_not_vacated():
    """A cup 6 cm off (drift) or a second instance of it: rays to its old points pass, the cup
    stands there; a chair 0.8 m from one taken away, or a cup of another class, does not."""
    duplicate = _inst("cup", [1.77, 1.85, 0.72], [1.87, 1.98, 0.81])
    chair_gone = _inst("chair", [2.0, 2.4, 0.0], [2.44, 2.84, 0.92])
    cup_gone = _inst("cup", [3.0, 0.0, 0.72], [3.08, 0.08, 0.8])
    seen = [_inst("cup", [1.75, 1.92, 0.72], [1.89, 2.02, 0.83]),  # the cup this session
            _inst("chair", [2.8, 2.4, 0.0], [3.24, 2.84, 0.92]),  # the chair beside the one taken away
            _inst("bottle", [3.0, 0.0, 0.72], [3.08, 0.08, 1.0])]  # a bottle where the cup stood
    assert still_seen([duplicate, chair_gone, cup_gone], seen) == {duplicate.uuid}


def test_a_neighbour_found_again_does_not_stand_for_the_chair_taken_away_beside_it():
    """Two dining chairs 0.8 m apart, their boxes grown to 0.72 m by what their blobs caught:
    the one left, found again as its own earlier instance, is that chair, not the one taken
    away 4 cm beyond its box; a cup found again on a second instance of itself still is."""
    chair_gone = _inst("chair", [1.67, 2.18, 0.0], [2.39, 2.90, 0.93])
    neighbour = _inst("chair", [0.91, 2.22, 0.0], [1.63, 2.92, 0.91])
    assert still_seen([chair_gone], [neighbour]) == {chair_gone.uuid}  # unpaired: within the slack
    assert still_seen([chair_gone], [neighbour], found_again=[neighbour]) == set()
    duplicate = _inst("cup", [1.77, 1.85, 0.72], [1.87, 1.98, 0.81])
    cup = _inst("cup", [1.75, 1.92, 0.72], [1.89, 2.02, 0.83])  # found again as the first instance
    assert still_seen([duplicate], [cup], found_again=[cup]) == {duplicate.uuid}


def test_fold_keeps_the_earlier_uuid_and_the_box_seen_last():
    earlier = _inst("bed", [0.0, 0.0, 0.0], [2.0, 1.0, 0.6], obs=("a", "b", "c"), t=(10.0, 20.0),
                    rows=[[10.0, 1, 0.5, 0.3, 0, 0, 0], [20.0, 1, 0.5, 0.3, 0, 0, 0]])
    new = _inst("bed", [0.4, 0.0, 0.0], [2.4, 1.0, 0.6], obs=("c", "d"), t=(5.0, 30.0),
                rows=[[5.0, 1.4, 0.5, 0.3, 0, 0, 0], [30.0, 1.4, 0.5, 0.3, 0, 0, 0]])
    uuid = earlier.uuid
    out = fold(earlier, new)
    assert out.uuid == uuid
    assert out.observation_uuids == ["a", "b", "c", "d"]
    assert (out.first_seen_s, out.last_seen_s) == (5.0, 30.0)
    lower, upper = out.box.aabb()
    assert np.allclose(lower, [0.4, 0.0, 0.0]) and np.allclose(upper, [2.4, 1.0, 0.6])  # moved 0.4 m
    assert [r[0] for r in out.data["trajectory"]] == [5.0, 10.0, 20.0, 30.0]
    older_log = _inst("bed", [1.0, 0.0, 0.0], [3.0, 1.0, 0.6], t=(0.0, 4.0))  # a log of an earlier day
    assert np.allclose(fold(out, older_log).box.aabb()[0], [0.4, 0.0, 0.0])
    same_clock = _inst("bed", [0.6, 0.0, 0.0], [2.6, 1.0, 0.6], t=(1.0, 12.0))  # stamps from 0 again
    out.data["vacated_s"] = 31.0  # a session had seen its place empty
    assert np.allclose(fold(out, same_clock).box.aabb()[0], [0.6, 0.0, 0.0])
    assert "vacated_s" not in out.data


def _walk(t0, t1, *, x0=0.0, y=1.0, speed=1.0, step=0.1, noise_m=0.0, seed=0):
    """Rows of a walker going along x at ``speed`` from ``x0`` at t0."""
    rng = np.random.default_rng(seed)
    return [[t, x0 + speed * (t - t0) + rng.normal(0, noise_m), y + rng.normal(0, noise_m), 0.9,
             speed, 0.0, 0.0] for t in np.round(np.arange(t0, t1 + 1e-9, step), 6)]


def _walker(rows, obs=("w",)):
    xy, half = np.asarray(rows)[-1, 1:4], np.array([0.2, 0.2, 0.9])
    return _inst("person", xy - half, xy + half, obs=obs,
                 t=(rows[0][0], rows[-1][0]), rows=rows)


def _cosighted(new, earlier):
    return [(e.uuid, n.uuid) for e, n in cosighted_pairs(new, earlier, max_m=0.4, min_common=3)]


def test_a_walker_joins_only_one_seen_at_the_same_times_and_place():
    earlier = _walker(_walk(10.0, 20.0))
    again = _walker(_walk(10.0, 20.0, noise_m=0.03, seed=1))  # the same log perceived again
    other_robot = _walker(_walk(10.05, 19.95, noise_m=0.05, seed=2))  # its own clock ticks
    beside = _walker(_walk(10.0, 20.0, y=2.0))  # someone 1 m away at the same times
    later = _walker(_walk(110.0, 120.0, x0=0.0))  # the same path, another time
    got = _cosighted([again, other_robot, beside, later], [earlier])
    assert sorted(got) == sorted([(earlier.uuid, again.uuid), (earlier.uuid, other_robot.uuid)])
    pieces = [_walker(_walk(10.0, 13.0)), _walker(_walk(14.0, 20.0, x0=4.0))]  # tracked in two pieces
    assert sorted(_cosighted(pieces, [earlier])) == sorted((earlier.uuid, p.uuid) for p in pieces)


def test_a_walker_seen_twice_keeps_each_row_once_and_the_place_seen_last():
    earlier = _walker(_walk(10.0, 15.0), obs=("a", "b"))
    new = _walker(_walk(10.0, 18.0, noise_m=0.02, seed=3), obs=("b", "c"))
    new.state = "dynamic"
    uuid = earlier.uuid
    out = fold_mover(earlier, new)
    stamps = [r[0] for r in out.data["trajectory"]]
    assert out.uuid == uuid and out.observation_uuids == ["a", "b", "c"]
    assert stamps == sorted(set(stamps)) and len(stamps) == 81  # 10.0 to 18.0 every 0.1 s, once
    assert (out.first_seen_s, out.last_seen_s, out.state) == (10.0, 18.0, "dynamic")
    assert out.box.center_m[0] == pytest.approx(8.0, abs=0.1)


def test_fold_drops_a_row_seen_twice_but_keeps_a_moved_object_rows_of_the_same_stamps():
    """Logs whose stamps all start at 0 share stamps: only a row at the same place is a repeat."""
    rows = [[float(t), 1.0, 1.0, 0.45, 0, 0, 0] for t in range(5)]
    earlier = _inst("chair", [0.75, 0.75, 0.0], [1.25, 1.25, 0.9], rows=rows)
    fold(earlier, _inst("chair", [0.75, 0.75, 0.0], [1.25, 1.25, 0.9], rows=[r[:] for r in rows]))
    assert len(earlier.data["trajectory"]) == 5
    moved = [[float(t), 1.5, 1.0, 0.45, 0, 0, 0] for t in range(5)]
    fold(earlier, _inst("chair", [1.25, 0.75, 0.0], [1.75, 1.25, 0.9], rows=moved))
    assert len(earlier.data["trajectory"]) == 10


def _foreground_counts(kb_path: Path) -> Counter[str]:
    """Instances per class, ``unknown`` left out (the fixture's one unknown is a blob the
    tracker saw moving: no box tells two moving things apart, so it is never paired)."""
    with open_kb(kb_path) as kb:
        return Counter(i.class_name for i in kb.instances(layer="foreground") if i.class_name != "unknown")


def _run(kb_path: Path, again: bool, **options) -> dict[str, int]:
    """Perceive the fixture into ``kb_path``; the summary's counts of earlier sessions' objects."""
    stage = ForegroundStage(log_path=FIXTURE, detector="truth", **options)
    with open_kb(kb_path) as kb:
        summary = perceive(open_log(FIXTURE), kb, [stage],
                           PerceiveOptions(on_existing="again" if again else "refuse"))
    return summary.to_dict()["earlier_sessions"]


@pytest.mark.parametrize("reidentify", [True, False])
def test_a_second_session_of_one_log_keeps_one_instance_per_static_object(tmp_path, reidentify):
    kb_path = tmp_path / "kb.hiper"
    first = _run(kb_path, again=False, reidentify=reidentify)
    once = _foreground_counts(kb_path)
    assert sum(once.values()) >= 2  # the fixture's chair and table, seen in its mapping phase
    assert first == {"found_again": 0, "moved": 0, "vacated": 0}
    second = _run(kb_path, again=True, reidentify=reidentify)
    twice = _foreground_counts(kb_path)
    if reidentify:
        assert twice == once  # people too: seen at the same times and places
        assert once["person"] >= 1
        assert second["found_again"] >= sum(once.values()) and second["moved"] == second["vacated"] == 0
        with open_kb(kb_path) as kb:
            for inst in kb.instances(layer="foreground"):
                stamps = [r[0] for r in inst.data.get("trajectory") or []]
                assert len(stamps) == len(set(stamps)), inst.class_name  # each row once
    else:  # the switch off: what perceive --again did before
        assert twice == once + once
        assert second == first


def _edit_earlier(kb_path: Path, shift_chair_m: tuple[float, float], add: str,
                  vacated_s: float | None = None) -> tuple[str, str]:
    """Move the first session's chair by ``shift_chair_m`` (as if it had stood there; marked
    vacated at ``vacated_s``) and add an instance of class ``add`` where the chair now seems to
    have been; their uuids."""
    with open_kb(kb_path) as kb:
        (chair,) = [i for i in kb.instances(layer="foreground") if i.class_name == "chair"]
        moved = chair.to_dict()
        moved["box"]["center_m"][0] += shift_chair_m[0]
        moved["box"]["center_m"][1] += shift_chair_m[1]
        assert moved["data"]["surface_map"]  # the chair's observed surface moves with it
        moved["data"]["surface_map"] = [[x + shift_chair_m[0], y + shift_chair_m[1], z]
                                        for x, y, z in moved["data"]["surface_map"]]
        if vacated_s is not None:
            moved["data"]["vacated_s"] = vacated_s
        other = Instance(layer="foreground", class_name=add, box=Box3D.from_dict(moved["box"]),
                         first_seen_s=chair.first_seen_s, last_seen_s=chair.last_seen_s)
        env = kb.environment("house_small")
        kb.put_documents([moved, other.to_dict()], env_uuid=env.uuid)
        # the place's cloud saw it there too: its points above the floor go with it
        cloud = np.array(kb.map_cloud(env), dtype=np.float64)
        lo, hi = chair.box.aabb()
        inside = np.all((cloud >= lo - 0.05) & (cloud <= hi + 0.05), axis=1) & (cloud[:, 2] > lo[2] + 0.08)
        cloud[inside, :2] += shift_chair_m
        kb.store_map_cloud(env, cloud)
        kb.sync_graph()
    return chair.uuid, other.uuid


def test_a_chair_that_moved_keeps_its_instance_and_an_empty_place_is_vacated(tmp_path):
    """The fixture's chair stood 1 m further along x in the first session (the place this
    session sees empty): one chair, the first session's uuid, this session's box; a couch the
    first session left there is marked vacated, and "how many couches" says none."""
    from hiper_cli.query import ask

    kb_path = tmp_path / "kb.hiper"
    _run(kb_path, again=False)
    chair_uuid, couch_uuid = _edit_earlier(kb_path, (1.0, 0.0), add="couch")
    second = _run(kb_path, again=True)
    assert second["moved"] == 1 and second["vacated"] == 1
    with open_kb(kb_path) as kb:
        chairs = [i for i in kb.instances(layer="foreground") if i.class_name == "chair"]
        couch = kb.instance(couch_uuid)
        assert [c.uuid for c in chairs] == [chair_uuid]
        assert chairs[0].box.center_m[0] == pytest.approx(2.1, abs=0.1)  # where it stands now
        assert couch is not None and couch.data["vacated_s"] >= couch.last_seen_s
        assert ask(kb, "how many couches").count == 0
        assert ask(kb, "how many chairs").count == 1


def test_a_chair_an_earlier_session_found_gone_is_found_again_where_it_stands(tmp_path):
    """The chair was marked vacated by some session, at a place this one cannot see (behind
    the table): it is the chair this session finds, and no longer vacated."""
    kb_path = tmp_path / "kb.hiper"
    _run(kb_path, again=False)
    chair_uuid, _ = _edit_earlier(kb_path, (-1.0, 0.0), add="bottle", vacated_s=5.0)
    _run(kb_path, again=True)
    with open_kb(kb_path) as kb:
        (chair,) = [i for i in kb.instances(layer="foreground") if i.class_name == "chair"]
    assert chair.uuid == chair_uuid and "vacated_s" not in chair.data
    assert chair.box.center_m[0] == pytest.approx(2.1, abs=0.1)
