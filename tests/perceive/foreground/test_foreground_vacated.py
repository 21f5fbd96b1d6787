"""Places seen empty (``vacated.py``): a chair's place seen with the chair gone is vacated, with
the chair there it is not, nor when someone stands in front of it; a cup's place on a table
only from the side."""

from __future__ import annotations

import numpy as np

from hiper_cli.model import Box3D, Instance
from hiper_cli.perceive.foreground.vacated import MIN_EMPTY_FRAMES, EmptyPlaces

CAMERA = np.array([0.0, 0.0, 1.2])  # looking along map +x, level
CHAIR = (np.array([2.0, -0.25, 0.0]), np.array([2.5, 0.25, 0.9]))
PERSON = (np.array([1.0, -0.4, 0.0]), np.array([1.3, 0.4, 1.8]))  # between the camera and the chair
TABLE = (np.array([1.5, -0.6, 0.0]), np.array([2.3, 0.6, 0.75]))  # a solid block standing in for it
CUP = (np.array([1.9, -0.05, 0.75]), np.array([2.0, 0.05, 0.85]))


def _inst(lower, upper, cls="chair"):
    return Instance(layer="foreground", class_name=cls, box=Box3D((lower + upper) / 2, upper - lower),
                    first_seen_s=0.0, last_seen_s=1.0)


def _projector(solids, camera=CAMERA):
    """A camera at ``camera`` looking along +x over a floor at z = 0 and these solid boxes: per
    point, in view, its depth (x - camera x) and the depth of the first surface on its ray."""

    def project(points):
        ray = points - camera
        z = ray[:, 0]
        t_hit = np.full(len(points), np.inf)
        down = ray[:, 2] < 0
        t_hit[down] = -camera[2] / ray[down, 2]  # the floor
        for lower, upper in solids:
            with np.errstate(divide="ignore", invalid="ignore"):
                t1, t2 = (lower - camera) / ray, (upper - camera) / ray
            entry = np.nanmax(np.minimum(t1, t2), axis=1)
            exit_ = np.nanmin(np.maximum(t1, t2), axis=1)
            hits = (entry <= exit_) & (entry > 0)
            t_hit = np.where(hits, np.minimum(t_hit, entry), t_hit)
        measured = np.where(np.isfinite(t_hit), t_hit * z, 0.0)
        return z > 0.3, z, measured

    return project


def _look(places, solids, frames=MIN_EMPTY_FRAMES, camera=CAMERA):
    project = _projector(solids, camera)
    for k in range(frames):
        places.look(project, camera, 10.0 + k)
    return places.vacated()


def test_a_chairs_place_seen_empty_is_vacated_from_the_first_empty_frame():
    chair = _inst(*CHAIR)
    assert _look(EmptyPlaces([chair]), []) == {chair.uuid: 10.0}


def test_a_chair_still_there_is_not_vacated():
    places = EmptyPlaces([_inst(*CHAIR)])
    assert _look(places, [CHAIR], frames=20) == {}
    assert places.present[0] == 20 and places.empty[0] == 0


def test_too_few_empty_frames_or_someone_in_front_say_nothing():
    assert _look(EmptyPlaces([_inst(*CHAIR)]), [], frames=MIN_EMPTY_FRAMES - 1) == {}
    places = EmptyPlaces([_inst(*CHAIR)])
    assert _look(places, [PERSON], frames=20) == {}  # the chair gone, but hidden behind a person
    assert places.empty[0] == 0 and places.present[0] == 0


def test_more_frames_with_the_object_than_without_keep_it():
    places = EmptyPlaces([_inst(*CHAIR)])
    _look(places, [CHAIR], frames=10)
    assert _look(places, [], frames=MIN_EMPTY_FRAMES) == {}  # 10 present, 5 empty: a bad stretch


def test_a_cup_gone_from_a_table_is_told_gone_from_the_side_not_from_above():
    """Seen from the side the rays pass the cup's far side above the table; seen from above,
    the table top is the far side of the cup's box, and no ray passes through it (by more than
    the margin and the depth noise: the side view is a low one)."""
    side = np.array([0.0, 0.0, 1.0])
    assert len(_look(EmptyPlaces([_inst(*CUP, cls="cup")]), [TABLE], frames=20, camera=side)) == 1
    above = np.array([1.2, 0.0, 2.5])
    assert _look(EmptyPlaces([_inst(*CUP, cls="cup")]), [TABLE], frames=20, camera=above) == {}
    assert _look(EmptyPlaces([_inst(*CUP, cls="cup")]), [TABLE, CUP], frames=20) == {}


WALL = (np.array([2.5, -3.0, 0.0]), np.array([2.6, 3.0, 2.5]))  # right behind the chair's back
TOP = (np.array([1.5, -0.6, 0.72]), np.array([2.3, 0.6, 0.75]))
LEGS = [(np.array([x, y, 0.0]), np.array([x + 0.05, y + 0.05, 0.72]))
        for x in (1.5, 2.25) for y in (-0.6, 0.55)]


def _observed(lower, upper, points, cls="chair"):
    """An earlier instance with the surface points its session observed."""
    inst = _inst(lower, upper, cls=cls)
    inst.data["surface_map"] = [list(map(float, p)) for p in points]
    return inst


def _chair_front():
    return [(2.0, y, z) for y in (-0.2, 0.0, 0.2) for z in (0.3, 0.5, 0.7)]


def test_a_place_against_a_wall_is_told_empty_from_the_surface_seen_there():
    """The wall is the chair box's far side, so box rays cannot tell the chair gone; rays to
    the chair's observed front pass on to the wall half a metre behind it."""
    assert _look(EmptyPlaces([_inst(*CHAIR)]), [WALL], frames=20) == {}
    chair = _observed(*CHAIR, _chair_front())
    assert _look(EmptyPlaces([chair]), [WALL]) == {chair.uuid: 10.0}
    places = EmptyPlaces([_observed(*CHAIR, _chair_front())])
    assert _look(places, [WALL, CHAIR], frames=20) == {}
    assert places.present[0] == 20


def test_a_table_still_standing_is_not_taken_for_an_empty_place():
    """A table's box is mostly air under its top: box rays pass under it and call it gone;
    rays to its observed top and legs meet them."""
    table = [TOP, *LEGS]
    assert len(_look(EmptyPlaces([_inst(*TABLE, cls="table")]), table, frames=20)) == 1
    seen = [(1.6, y, 0.75) for y in (-0.4, -0.1, 0.2, 0.4)] + [(1.5, -0.58, 0.3), (1.5, 0.57, 0.3)]
    places = EmptyPlaces([_observed(*TABLE, seen, cls="table")])
    assert _look(places, table, frames=20) == {}
    assert places.present[0] == 20
    gone = _observed(*TABLE, seen, cls="table")
    assert _look(EmptyPlaces([gone]), []) == {gone.uuid: 10.0}


def test_places_with_and_without_surfaces_are_judged_together():
    """Each verdict from its own rays: a chair with observed points gone, another without
    them still there beside it."""
    beside = (CHAIR[0] + [0.0, 1.0, 0.0], CHAIR[1] + [0.0, 1.0, 0.0])
    gone, kept = _observed(*CHAIR, _chair_front()), _inst(*beside)
    places = EmptyPlaces([kept, gone])
    assert _look(places, [WALL, beside], frames=5) == {gone.uuid: 10.0}
    assert list(places.present) == [5, 0]


def test_a_cup_gone_from_a_table_is_told_by_its_points_above_the_foot():
    """The table returns at the depth of the cup's lowest points whether the cup is there or
    not: those are left out, and the rest pass on to the table top behind."""
    front = [(1.9, y, z) for y in (-0.04, 0.0, 0.04) for z in (0.75, 0.8, 0.85)]
    cup = _observed(*CUP, front, cls="cup")
    assert _look(EmptyPlaces([cup]), [TABLE]) == {cup.uuid: 10.0}
    places = EmptyPlaces([_observed(*CUP, front, cls="cup")])
    assert _look(places, [TABLE, CUP], frames=5) == {}
    assert places.present[0] == 5


def test_a_cup_seen_a_few_centimetres_off_its_old_points_is_not_taken_for_gone():
    """Two sessions' poses differ by drift and alignment, more than a cup's size: the rays at
    its old points pass it by and end on the table behind, but a surface stands within the
    pose slack of them, so the place is not seen empty."""
    front = [(1.9, y, z) for y in (-0.04, 0.0, 0.04) for z in (0.78, 0.84)]
    off = 0.12  # the cup now appears this far to the side (within the slack of its old points)
    there = (CUP[0] + [0.0, off, 0.0], CUP[1] + [0.0, off, 0.0])
    places = EmptyPlaces([_observed(*CUP, front, cls="cup")])
    assert _look(places, [TABLE, there], frames=10) == {}
    assert places.empty[0] == 0
    gone = _observed(*CUP, front, cls="cup")
    assert _look(EmptyPlaces([gone]), [TABLE]) == {gone.uuid: 10.0}


def test_a_chair_gone_from_beside_a_wall_is_not_kept_by_the_wall():
    """The pose slack is for objects it is a large share of: probes 10 cm around a chair's
    points by a side wall would meet the wall; the chair is wider than ``SMALL_M``, its rays
    alone judge, and its place is told empty."""
    side = (np.array([0.0, 0.3, 0.0]), np.array([4.0, 0.4, 2.5]))  # along the view, by the chair
    back = (np.array([3.5, -3.0, 0.0]), np.array([3.6, 3.0, 2.5]))
    points = [(x, y, z) for x in (2.06, 2.25, 2.45) for y in (-0.2, 0.0, 0.2) for z in (0.5, 0.8)]
    gone = _observed(*CHAIR, points)
    assert _look(EmptyPlaces([gone]), [side, back]) == {gone.uuid: 10.0}
