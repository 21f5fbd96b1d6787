"""Time phrases read into windows (``timewords.py``): relative spans, clock times on the day of
now (or the day before), day parts, "ago" with a tolerance, event bounds, and refusals."""

from __future__ import annotations

from datetime import UTC, datetime

import pytest

from hiper_cli.errors import QueryError
from hiper_cli.query.timewords import TimeAnchor, TimeWindow, read_time_phrase, time_window

NOW = datetime(2026, 12, 7, 14, 30, tzinfo=UTC).timestamp()


def _at(hour: int, minute: int = 0, day: int = 7) -> float:
    return datetime(2026, 12, day, hour, minute, tzinfo=UTC).timestamp()


@pytest.mark.parametrize(
    ("text", "window"),
    [
        ("in the last 5 minutes", TimeWindow(NOW - 300, None)),
        ("past hour", TimeWindow(NOW - 3600, None)),
        ("over the last few seconds", TimeWindow(NOW - 3, None)),
        ("last couple of minutes", TimeWindow(NOW - 120, None)),
        ("in the last half hour", TimeWindow(NOW - 1800, None)),
        ("recently", TimeWindow(NOW - 600, None)),
        ("right now", TimeWindow(NOW - 2, None)),
        ("since 10:00", TimeWindow(_at(10), None)),
        ("since 3pm", TimeWindow(_at(15, day=6), None)),  # 15:00 today is still to come
        ("before noon", TimeWindow(None, _at(12))),
        ("after 9 am", TimeWindow(_at(9), None)),
        ("between 9 and 11:30", TimeWindow(_at(9), _at(11, 30))),
        ("from 11:30 to 9:00", TimeWindow(_at(9), _at(11, 30))),
        ("at 10:15", TimeWindow(_at(10, 15), _at(10, 16))),
        ("at 2pm", TimeWindow(_at(14), _at(15))),
        ("today", TimeWindow(_at(0), NOW)),
        ("earlier today", TimeWindow(_at(0), NOW)),
        ("yesterday", TimeWindow(_at(0, day=6), _at(0))),
        ("since yesterday", TimeWindow(_at(0, day=6), None)),
        ("this morning", TimeWindow(_at(6), _at(12))),
        ("this evening", TimeWindow(_at(18, day=6), _at(0))),  # this evening has not begun
        ("since the start", TimeWindow()),
        ("5 minutes ago", TimeWindow(NOW - 330, NOW - 270)),
        ("today after 9am", TimeWindow(_at(9), NOW)),
        ("since 2026-12-07T08:00", TimeWindow(_at(8), None)),
    ],
)
def test_time_windows(text, window):
    assert time_window(text, NOW) == window


def test_events_are_anchors():
    assert time_window("after the person left", NOW) == TimeWindow(
        since_event=TimeAnchor("person", "last"))
    assert time_window("before a cup was first seen", NOW) == TimeWindow(
        until_event=TimeAnchor("cup", "first"))
    assert time_window("since someone came in", NOW).since_event == TimeAnchor("person", "first")


def test_a_phrase_is_read_where_it_stands():
    tokens = ["people", "seen", "in", "the", "last", "10", "minutes", "near", "me"]
    assert read_time_phrase(tokens, 0, NOW) is None
    assert read_time_phrase(tokens, 2, NOW) == (TimeWindow(NOW - 600, None), 5)


@pytest.mark.parametrize("text", ["since 25:00", "at 10:75"])
def test_a_time_that_does_not_exist_is_named(text):
    with pytest.raises(QueryError, match="is not a time of day"):
        time_window(text, NOW)


def test_words_that_are_no_time_are_named():
    with pytest.raises(QueryError, match=r'cannot read "last fortnight" in the time "the last fortnight"'):
        time_window("the last fortnight", NOW)


def test_an_agent_time_may_be_any_time_phrase():
    from hiper_cli.agent.times import resolve_time

    assert resolve_time("this morning", NOW) == _at(6)
    assert resolve_time("since 9am", NOW) == _at(9)
    assert resolve_time("10:30", NOW) == _at(10, 30)
    with pytest.raises(QueryError, match="time 'banana': expected a stamp"):
        resolve_time("banana", NOW)
