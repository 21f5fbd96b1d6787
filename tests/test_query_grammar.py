"""The plain-words grammar: classes, synonyms and plurals; space, time and state phrases;
question words; unknown words answered with a quote, what is understood and a suggestion."""

from __future__ import annotations

from datetime import UTC, datetime

import pytest

from hiper_cli.errors import QueryError
from hiper_cli.query import parse
from hiper_cli.query.spec import Near, On
from hiper_cli.query.vocabulary import counted, plural, resolve_class, singular

NOW = datetime(2026, 12, 2, 12, 30, tzinfo=UTC).timestamp()


@pytest.mark.parametrize(
    ("words", "name"),
    [
        ("mugs", "cup"),
        ("mug", "cup"),
        ("cups", "cup"),
        ("sofas", "couch"),
        ("people", "person"),
        ("persons", "person"),
        ("potted plants", "potted plant"),
        ("benches", "bench"),
        ("shelves", "shelf"),
        ("tables", "table"),
        ("desks", "table"),
        ("tvs", "tv"),
        ("objects", "objects"),
        ("wine glasses", "wine glass"),
        ("cell phones", "cell phone"),
        ("bottle", "bottle"),
    ],
)
def test_class_words(words, name):
    assert resolve_class(words) == name


def test_singular_rules():
    assert [singular(w) for w in ("cups", "glasses", "knives", "batteries", "benches", "grass")] == [
        "cup",
        "glass",
        "knife",
        "battery",
        "bench",
        "grass",
    ]


def test_spatial_phrases():
    assert parse("cups in FOV").spec.in_fov and parse("cups in the field of view").spec.in_fov
    closest = parse("closest table").spec
    assert closest.classes == ("table",) and closest.sort == "distance" and closest.limit == 1
    assert parse("3 nearest chairs").spec.limit == 3
    assert parse("chairs within 2.5 m of me").spec.near == Near("me", 2.5)
    assert parse("chairs within 50 cm of the table").spec.near == Near("table", 0.5)
    assert parse("bottles near the couch").spec.near == Near("couch", 1.0)
    assert parse("objects on the closest table").spec.on == On("table", True)
    on = parse("cups on tables").spec
    assert on.on == On("table", False) and on.classes == ("cup",)
    assert parse("when did a person last pass here").spec.passed_here


def test_time_and_state_phrases():
    spec = parse("people moving in the last 10 minutes", now_s=NOW).spec
    assert spec.state == "dynamic" and spec.since_s == NOW - 600 and spec.classes == ("person",)
    assert parse("static chairs").spec.state == "static"
    assert parse("cups in the past 2 hours", now_s=NOW).spec.since_s == NOW - 7200
    since = parse("people since 10:00", now_s=NOW).spec
    assert since.since_s == datetime(2026, 12, 2, 10, 0, tzinfo=UTC).timestamp()
    between = parse("people between 9:15 and 11:00", now_s=NOW).spec
    assert (between.since_s, between.until_s) == (
        datetime(2026, 12, 2, 9, 15, tzinfo=UTC).timestamp(),
        datetime(2026, 12, 2, 11, 0, tzinfo=UTC).timestamp(),
    )
    yesterday = parse("chairs yesterday", now_s=NOW).spec
    assert yesterday.since_s == datetime(2026, 12, 1, tzinfo=UTC).timestamp()
    assert yesterday.until_s == datetime(2026, 12, 2, tzinfo=UTC).timestamp()
    # a time of day later than now means yesterday's
    assert (
        parse("people since 23:00", now_s=NOW).spec.since_s
        == datetime(2026, 12, 1, 23, tzinfo=UTC).timestamp()
    )
    assert parse("people now", now_s=NOW).spec.since_s == NOW - 2.0


@pytest.mark.parametrize(
    ("words", "answer"),
    [
        ("how many chairs", "count"),
        ("where was the bottle last seen", "location"),
        ("when was a cup first seen", "time"),
        ("is there a cup on the table", "yes_no"),
        ("go to the closest couch", "goal"),
        ("how long was the person in view", "duration"),
        ("cups in FOV", "list"),
    ],
)
def test_question_words(words, answer):
    parsed = parse(words)
    assert parsed.answer == answer
    if answer == "duration":
        assert not parsed.spec.in_fov  # "in view" is the time in view here, not a filter


def test_plurals_are_the_words_the_grammar_reads_back():
    names = ("cup", "person", "couch", "shelf", "potted plant", "wine glass", "bus", "stairs", "knife")
    assert [plural(n) for n in names] == [
        "cups", "people", "couches", "shelves", "potted plants", "wine glasses", "buses", "stairs", "knives"
    ]
    assert all(resolve_class(plural(n)) == n for n in names)
    assert [counted(k, "chair") for k in (0, 1, 2)] == ["0 chairs", "1 chair", "2 chairs"]


@pytest.mark.parametrize("words", ["chairs after 25:00", "cups since 10:75", "people between 9:00 and 24:30",
                                   "cups before 0:99"])
def test_a_clock_time_that_does_not_exist_is_named(words):
    with pytest.raises(QueryError, match=r'is not a time of day; write HH:MM'):
        parse(words, now_s=NOW)


def test_unknown_words_are_quoted_with_a_suggestion():
    with pytest.raises(QueryError, match=r'cannot read "chiars".*did you mean "how many chairs"'):
        parse("how many chiars")
    with pytest.raises(QueryError, match=r'"kitchen".*hiper understands: classes'):
        parse("cups in the kitchen")
    with pytest.raises(QueryError, match="empty query"):
        parse("   ")
