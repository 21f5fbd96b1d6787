"""Two pieces of one table cut apart by a chair in front of it are one table
(``table_pieces.py``): joined only when the band between them is hidden from the camera."""

import numpy as np

from hiper_cli.perceive.foreground.config import RefineConfig
from hiper_cli.perceive.foreground.segment import Blob
from hiper_cli.perceive.foreground.table_pieces import join_hidden_pieces
from tests.fg_constants import constants

W, H = 640, 480


def _piece(x0, x1, y0, y1, top_m=0.75, u0=0):
    """A table top piece with its edge under it: points on a 2 cm grid, map frame."""
    xs, ys = np.meshgrid(np.arange(x0, x1, 0.02), np.arange(y0, y1, 0.02))
    top = np.c_[xs.ravel(), ys.ravel(), np.full(xs.size, top_m)]
    edge = top[::7].copy()
    edge[:, 2] -= 0.03
    points = np.r_[top, edge]
    uv = np.c_[u0 + np.arange(len(points)) % 50, 200 + np.arange(len(points)) // 50].astype(np.int32)
    return Blob(points.copy(), points, uv, np.array([u0, 200.0, u0 + 50.0, 260.0]))


def _hidden_everywhere(points):
    n = len(points)
    return np.ones(n, dtype=bool), np.ones(n, dtype=bool)


def _seen_through(points):
    n = len(points)
    return np.ones(n, dtype=bool), np.zeros(n, dtype=bool)


def test_pieces_with_the_band_between_them_hidden_are_one_table():
    left, right = _piece(8.6, 9.2, 1.0, 1.3), _piece(8.6, 9.2, 1.7, 2.2, u0=300)
    (table,) = join_hidden_pieces([left, right], _hidden_everywhere, RefineConfig(), W, H)
    assert len(table.points_map) == len(left.points_map) + len(right.points_map)
    lo, hi = table.bounds_map
    assert hi[1] - lo[1] > 1.1  # the whole 1.2 m table
    # the camera sees past the band: floor between two tables
    assert len(join_hidden_pieces([left, right], _seen_through, RefineConfig(), W, H)) == 2


def test_pieces_that_touch_at_one_height_are_one_top():
    left, right = _piece(8.6, 9.2, 1.0, 1.62), _piece(8.6, 9.2, 1.6, 2.2, u0=300)
    assert len(join_hidden_pieces([left, right], _seen_through, RefineConfig(), W, H)) == 1


def test_pieces_apart_in_height_length_or_line_stay_apart():
    config = RefineConfig()
    left = _piece(8.6, 9.2, 1.0, 1.3)
    cases = [
        _piece(8.6, 9.2, 1.7, 2.2, top_m=0.45, u0=300),  # a seat, not the top
        _piece(8.6, 9.2, 2.2, 2.6, u0=300),  # 0.9 m away: past the largest gap
        _piece(9.6, 10.2, 1.7, 2.2, u0=300),  # beside, not in line
    ]
    for other in cases:
        assert len(join_hidden_pieces([left, other], _hidden_everywhere, config, W, H)) == 2
    desks = [_piece(0.0, 1.6, 0.0, 0.7), _piece(2.2, 3.8, 0.0, 0.7, u0=300)]  # 3.8 m together
    assert len(join_hidden_pieces(desks, _hidden_everywhere, config, W, H)) == 2
    right = _piece(8.6, 9.2, 1.7, 2.2, u0=300)
    with constants(table_pieces_max_gap_m=0.0):
        assert len(join_hidden_pieces([left, right], _hidden_everywhere, config, W, H)) == 2


def _table_tracker(config):
    """A tracker that saw one piece of a table for 2 s, then only the other piece for 2 s."""
    from hiper_cli.perceive.foreground.tracking import Measurement, Tracker

    tracker, t_s = Tracker(config), 0.0
    for lower, upper in (([8.6, 1.0, 0.0], [9.2, 1.3, 0.75]), ([8.6, 1.7, 0.0], [9.2, 2.2, 0.75])):
        lower, upper = np.asarray(lower), np.asarray(upper)
        for _ in range(30):
            m = Measurement((lower + upper) / 2, upper - lower, "table", 1.0, f"o{t_s}",
                            bounds_map_m=(lower, upper))
            tracker.step(t_s, [m])
            t_s += 1.0 / 15
    return tracker


def test_tracks_of_two_pieces_seen_in_turn_are_one_table_when_the_band_is_hidden():
    """House 41: a chair hid the middle of the study table, and the two pieces were found in
    different frames (each one table), so no frame held both."""
    from hiper_cli.perceive.foreground.config import ForegroundConfig
    from hiper_cli.perceive.foreground.table_pieces import join_hidden_tracks

    config = ForegroundConfig()
    tracker = _table_tracker(config)
    tables = [t for t in [*tracker.tracks, *tracker.dormant] if t.confirmed]
    assert len(tables) == 2
    older = min(tables, key=lambda t: t.first_seen_s)
    aliases = join_hidden_tracks(tracker, _hidden_everywhere, config)
    assert list(aliases.values()) == [older]
    (table,) = [t for t in [*tracker.tracks, *tracker.dormant] if t.confirmed]
    lo, hi = table.seen.corners()
    assert table is older and hi[1] - lo[1] > 1.1
    tracker = _table_tracker(config)
    assert join_hidden_tracks(tracker, _seen_through, config) == {}  # floor between two tables
