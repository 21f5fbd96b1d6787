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


@pytest.mark.parametrize(
    ("words", "answer", "classes"),
    [
        ("count the chairs", "count", ("chair",)),
        ("number of chairs?", "count", ("chair",)),
        ("where's the table?", "location", ("table",)),
        ("wheres my cup", "location", ("cup",)),
        ("last time a person was seen", "time", ("person",)),
        ("when did the person pass the table", "time", ("person",)),
        ("Is anyone here?", "yes_no", ("person",)),
        ("could you show me the chairs", "list", ("chair",)),
        ("can you count the cups for me", "count", ("cup",)),
        ("any ppl near me?", "yes_no", ("person",)),
    ],
)
def test_common_phrasings(words, answer, classes):
    parsed = parse(words, now_s=NOW)
    assert (parsed.answer, parsed.spec.classes) == (answer, classes)


def test_change_words_and_their_default_window():
    moved = parse("what moved in the last 5 seconds", now_s=NOW).spec
    assert (moved.change, moved.since_s) == ("moved", NOW - 5)
    recent = parse("what moved recently", now_s=NOW).spec
    assert (recent.change, recent.since_s) == ("moved", NOW - 600)
    new = parse("anything new", now_s=NOW).spec  # no time: the recent window
    assert (new.change, new.layer, new.since_s) == ("added", "foreground", NOW - 600)
    assert parse("what is missing", now_s=NOW).spec.change == "removed"
    # asked "when", an appearance is a first sighting, not a filter
    when = parse("when did the cup appear", now_s=NOW)
    assert (when.answer, when.time_of, when.spec.change) == ("time", "first", None)


def test_passing_entering_and_leaving():
    passed = parse("when did the person pass the table").spec
    assert passed.passed_here and passed.near == Near("table", 1.0)
    entered = parse("when did the person reach the couch")
    assert entered.spec.passed_here and entered.time_of == "first"
    view = parse("when did the person leave the view")
    assert (view.answer, view.time_of, view.spec.passed_here) == ("time", "last", False)
    assert parse("when did someone come in").time_of == "first"
    assert parse("when was somebody near the couch").spec.passed_here  # a time near X: a pass


def test_event_bounds_are_kept_for_the_answer():
    parsed = parse("cups seen after the person left", now_s=NOW)
    assert (parsed.since_event.class_name, parsed.since_event.sighting) == ("person", "last")
    arrived = parse("what was on the table before someone arrived", now_s=NOW)
    assert (arrived.until_event.class_name, arrived.until_event.sighting) == ("person", "first")
    assert arrived.spec.on == On("table", False)


@pytest.mark.parametrize(
    ("words", "suggestion"),
    [
        ("count chiars", "count chairs"),
        ("hwo many chairs", "how many chairs"),
        ("whats on teh table", "what is on the table"),
        ("wher is the couch", "where is the couch"),
        ("show me the refridgerator", "show me the refrigerator"),
        ("cups in the kitchen", "cups"),
        ("is the door open", "is the door"),
    ],
)
def test_suggestions_are_near_relative_to_the_word_length(words, suggestion):
    with pytest.raises(QueryError, match=f'did you mean "{suggestion}"'):
        parse(words)


def test_no_far_fetched_suggestion_and_no_class_for_a_place():
    from hiper_cli.query.suggest import nearest_word

    assert nearest_word("count") is None or nearest_word("count") != "computer"
    assert nearest_word("kitchen") is None
    assert nearest_word("open") is None  # not "oven": a short word's typo keeps its letters
    assert nearest_word("chiars") == "chairs"
    with pytest.raises(QueryError, match=r'"kitchen": hiper keeps no named places') as err:
        parse("anything new in the kitchen")
    assert "kite" not in str(err.value) and 'did you mean "anything new"' in str(err.value)
    with pytest.raises(QueryError, match=r'cannot read "forklift".*did you mean "where is the chair"'):
        parse("where is the forklift")


def test_random_word_salad_never_crashes_and_every_suggestion_parses():
    """Seeded word salad from the grammar's own words, numbers, clock times and places: each
    query parses or is refused with a QueryError; a suggested question parses."""
    import random
    import re

    from hiper_cli.query.grammar import keywords
    from hiper_cli.query.vocabulary import class_words

    rng = random.Random(7)
    words = [
        *sorted(keywords() | set(class_words())),
        *("10:00", "25:00", "3pm", "5", "0.5", "2.5m", "kitchen", "xyz", "?", "'s", "-", "1e309", "-3"),
    ]
    for _ in range(800):
        text = " ".join(rng.choice(words) for _ in range(rng.randint(1, 8)))
        try:
            parse(text, now_s=NOW)
        except QueryError as err:
            found = re.search(r'did you mean "([^"]*)"\?', str(err))
            if found:
                parse(found.group(1), now_s=NOW)
    with pytest.raises(QueryError, match="leave no time between them"):
        parse("cups after 11:00 before 10:00", now_s=NOW)
