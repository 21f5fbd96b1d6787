"""The tables whose tops the background maps are objects too (``supports.table_bodies``): one
``unknown`` instance from the floor up to the top, unless an instance already holds the table (its
box covers the table's, or an unnamed piece continues the top); a chair at the table does not."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground import ForegroundStage
from hiper_cli.perceive.foreground.supports import table_bodies
from hiper_cli.perceive.stage import World


def _background(name: str, centre: list[float], extent: list[float]) -> Instance:
    inst = Instance("background", name, Box3D(np.array(centre), np.array(extent)), 2.0, 9.0)
    inst.data["plane_map"] = [0.0, 0.0, 1.0, -(centre[2] + extent[2] / 2.0)]  # its top
    return inst


def _box(centre: list[float], extent: list[float]) -> Box3D:
    return Box3D(np.array(centre), np.array(extent))


FLOOR = _background("floor", [2.0, 2.0, -0.01], [6.0, 6.0, 0.02])
TABLE = _background("table", [1.7, 1.9, 0.74], [1.6, 0.9, 0.02])  # top at 0.75 m


def test_a_mapped_table_is_an_object_from_the_floor_to_its_top() -> None:
    ((table, box, top),) = table_bodies([FLOOR, TABLE], 0.0, [], [])
    lo, hi = box.aabb()
    assert table is TABLE
    np.testing.assert_allclose(lo, [0.9, 1.45, 0.0], atol=1e-9)
    np.testing.assert_allclose(hi, [2.5, 2.35, 0.75], atol=1e-9)
    assert top.shape == (29, 3) and np.allclose(top[:25, 2], 0.75)  # the surface seen: its top ...
    assert np.all((top[:25, 0] > 0.9) & (top[:25, 0] < 2.5)) and np.allclose(top[25:, 2], 0.0)  # ... its feet


def test_a_table_an_instance_holds_is_that_instance() -> None:
    named = _box([1.7, 1.9, 0.38], [1.5, 0.8, 0.76])  # the detector's table
    assert table_bodies([FLOOR, TABLE], 0.0, [named], []) == []
    bottle = _box([1.9, 1.8, 0.9], [0.1, 0.1, 0.3])  # on the top: holds no table
    assert len(table_bodies([FLOOR, TABLE], 0.0, [bottle], [])) == 1


def test_a_piece_continuing_the_top_holds_it_a_chair_at_its_side_does_not() -> None:
    # the map of solid things kept the table's other end (x 0.1-0.85, the top's whole depth)
    end = _box([0.45, 1.9, 0.45], [0.7, 0.9, 0.9])
    assert table_bodies([FLOOR, TABLE], 0.0, [end], [end]) == []
    # an unnamed chair at the long side: narrower than that side
    chair = _box([1.4, 1.2, 0.46], [0.45, 0.45, 0.92])
    assert len(table_bodies([FLOOR, TABLE], 0.0, [chair], [chair])) == 1
    # a low box beside the end: it does not reach the top
    low = _box([0.45, 1.9, 0.2], [0.7, 0.9, 0.4])
    assert len(table_bodies([FLOOR, TABLE], 0.0, [low], [low])) == 1


def test_two_pieces_of_one_top_make_one_object() -> None:
    piece = _background("table", [2.7, 1.9, 0.74], [0.4, 0.9, 0.02])  # beyond the top's end
    bodies = table_bodies([FLOOR, piece, TABLE], 0.0, [], [])
    assert [b[0] for b in bodies] == [TABLE]


def test_the_stage_adds_the_tables_body_as_a_geometry_only_unknown() -> None:
    stage = ForegroundStage(detector="log")
    world = World(background={i.uuid: i for i in (FLOOR, TABLE)})
    (body,) = stage._geometry_only(world, [])
    assert body.class_name == "unknown" and body.data["geometry_only"]
    assert body.box.center_m[2] == pytest.approx(0.375)
    assert (body.first_seen_s, body.last_seen_s) == (2.0, 9.0)
    assert sum(p[2] == pytest.approx(0.75) for p in body.data["surface_map"]) == 25
    held = Instance("foreground", "table", _box([1.7, 1.9, 0.38], [1.5, 0.8, 0.76]), 0.0, 1.0)
    assert stage._geometry_only(world, [held]) == []


def test_a_later_sessions_empty_place_test_aims_at_the_tables_top_not_under_it() -> None:
    from hiper_cli.perceive.foreground.vacated import EmptyPlaces

    stage = ForegroundStage(detector="log")
    (body,) = stage._geometry_only(World(background={i.uuid: i for i in (FLOOR, TABLE)}), [])
    targets = EmptyPlaces([body])._points
    assert len(targets) == 25 and np.allclose(targets[:, 2], 0.75)  # the feet are left out
