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
    the table top is the far side of the cup's box, and no ray passes through it."""
    assert len(_look(EmptyPlaces([_inst(*CUP, cls="cup")]), [TABLE], frames=20)) == 1
    above = np.array([1.2, 0.0, 2.5])
    assert _look(EmptyPlaces([_inst(*CUP, cls="cup")]), [TABLE], frames=20, camera=above) == {}
    assert _look(EmptyPlaces([_inst(*CUP, cls="cup")]), [TABLE, CUP], frames=20) == {}
