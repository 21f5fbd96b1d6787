"""One place, one object (``ForegroundStage._fold_pieces``): a static named instance whose box lies
inside the box of a static instance of another class seen in more views is a piece of it; two
objects side by side, a walker and an ``unknown`` stay as they are."""

from __future__ import annotations

import numpy as np

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground import ForegroundStage


def _instance(
    name: str, centre: list[float], extent: list[float], views: int, state: str = "static"
) -> Instance:
    return Instance(layer="foreground", class_name=name, box=Box3D(np.array(centre), np.array(extent)),
                    first_seen_s=0.0, last_seen_s=1.0, state=state,  # type: ignore[arg-type]
                    observation_uuids=[f"{name}-{k}" for k in range(views)])


def _stage(*instances: Instance) -> ForegroundStage:
    stage = ForegroundStage(detector="log")
    stage._instances = {i.uuid: i for i in instances}
    return stage


def test_a_couchs_end_taken_for_a_chair_is_the_couch() -> None:
    couch = _instance("couch", [6.45, 7.99, 0.43], [1.07, 1.9, 0.87], views=137)
    chair = _instance("chair", [6.46, 8.52, 0.43], [1.01, 0.94, 0.86], views=24)
    stage = _stage(couch, chair)
    folded, grown = stage._fold_pieces()
    assert folded == [chair.uuid] and grown == [couch]
    assert list(stage._instances) == [couch.uuid] and len(couch.observation_uuids) == 137 + 24


def test_side_by_side_a_walker_and_an_unknown_stay() -> None:
    table = _instance("table", [0.0, 0.0, 0.37], [1.2, 0.8, 0.75], views=80)
    beside = _instance("chair", [0.9, 0.0, 0.45], [0.5, 0.5, 0.9], views=30)  # a quarter inside
    person = _instance("person", [0.0, 0.0, 0.8], [0.4, 0.4, 1.6], views=10)
    box = _instance("unknown", [0.1, 0.0, 0.3], [0.3, 0.3, 0.3], views=12)
    moved = _instance("chair", [-0.1, 0.0, 0.4], [0.5, 0.5, 0.6], views=20, state="dynamic")
    stage = _stage(table, beside, person, box, moved)
    assert stage._fold_pieces() == ([], [])
    assert len(stage._instances) == 5
