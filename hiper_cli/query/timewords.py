"""Time phrases as people write them, read into a ``TimeWindow``: "in the last 5 seconds",
"recently", "since 10:00", "today", "yesterday", "this morning", "between 9 and 11:30",
"at 3pm", "2 minutes ago", "after the person left", "before a cup was first seen".

One reader serves the plain-words grammar (``read_time_phrase`` at a token position) and any
other intent that needs a window from words (``time_window`` for a whole phrase, e.g. the
change questions "what changed since 10:00"). Clock times are UTC on the day of ``now`` (the
day before when that would be after now). A phrase about an event (a class's first or last
sighting) carries a ``TimeAnchor`` that the answer resolves against the knowledge base.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta

from hiper_cli.errors import QueryError
from hiper_cli.query.vocabulary import resolve_class

__all__ = [
    "TIME_PHRASES",
    "TIME_UNITS_S",
    "TimeAnchor",
    "TimeWindow",
    "clock_stamp",
    "number_word",
    "read_time_phrase",
    "time_window",
]

TIME_PHRASES = (
    "now, recently, in the last N seconds|minutes|hours|days (or 'last minute', 'past few minutes'), "
    "N minutes ago, since|after|before|until HH:MM|3pm|noon, at HH:MM, between A and B, from A to B, "
    "today, yesterday, this morning|afternoon|evening, last night, before/after/since an event "
    "('after the person left', 'before a cup was first seen')"
)
TIME_UNITS_S = {
    "s": 1.0, "sec": 1.0, "secs": 1.0, "second": 1.0, "seconds": 1.0,
    "min": 60.0, "mins": 60.0, "minute": 60.0, "minutes": 60.0,
    "h": 3600.0, "hr": 3600.0, "hrs": 3600.0, "hour": 3600.0, "hours": 3600.0,
    "d": 86400.0, "day": 86400.0, "days": 86400.0,
}
_NUMBER_WORDS = {
    "a": 1, "an": 1, "one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7,
    "eight": 8, "nine": 9, "ten": 10, "eleven": 11, "twelve": 12, "fifteen": 15, "twenty": 20,
    "thirty": 30, "forty": 40, "fifty": 50, "sixty": 60, "ninety": 90, "hundred": 100,
    "couple": 2, "few": 3, "several": 5,
}
# Parts of the day (hours, UTC): "this morning", "since this afternoon".
_DAY_PARTS = {"morning": (6, 12), "afternoon": (12, 18), "evening": (18, 24), "tonight": (18, 24)}
# Verbs of an event: which sighting of the class they name.
_FIRST_VERBS = frozenset(["arrived", "arrive", "appeared", "appear", "came", "come", "entered", "enter",
                          "showed", "show", "started", "start", "turned"])
_LAST_VERBS = frozenset(["left", "leave", "went", "go", "gone", "disappeared", "disappear", "exited",
                         "exit", "passed", "pass", "vanished", "stopped"])
_EVENT_TAIL = frozenset(["up", "in", "away", "by", "out", "off", "around"])
_STARTS = frozenset(["since", "after", "from"])
_ENDS = frozenset(["before", "until", "till", "til", "by"])
_AUX = frozenset(["was", "were", "is", "has", "had", "got", "did", "does"])


@dataclass(frozen=True)
class TimeAnchor:
    """An event a window starts or ends at: the ``sighting`` ("first" or "last") of the
    instances of ``class_name`` (the earliest first sighting, the latest last one)."""

    class_name: str
    sighting: str

    def words(self) -> str:
        return f"the {self.class_name} was {self.sighting} seen"


@dataclass(frozen=True)
class TimeWindow:
    """Stamps (s) bounding when an instance was seen; None = open. ``since_event`` and
    ``until_event`` are bounds still to be resolved against a knowledge base."""

    since_s: float | None = None
    until_s: float | None = None
    since_event: TimeAnchor | None = None
    until_event: TimeAnchor | None = None

    def __and__(self, other: TimeWindow) -> TimeWindow:
        """Both windows at once (the later start, the earlier end)."""
        starts = [s for s in (self.since_s, other.since_s) if s is not None]
        ends = [s for s in (self.until_s, other.until_s) if s is not None]
        return TimeWindow(
            max(starts) if starts else None,
            min(ends) if ends else None,
            other.since_event or self.since_event,
            other.until_event or self.until_event,
        )

    @property
    def is_open(self) -> bool:
        return self == TimeWindow()


def number_word(token: str) -> float | None:
    """A count written as digits or a word ("5", "2.5", "five", "a", "few")."""
    try:
        value = float(token)
    except ValueError:
        found = _NUMBER_WORDS.get(token)
        return None if found is None else float(found)
    return value if math.isfinite(value) and value >= 0 else None


def _day_start_s(now_s: float) -> float:
    return datetime.fromtimestamp(now_s, UTC).replace(hour=0, minute=0, second=0, microsecond=0).timestamp()


def _clock_parts(token: str) -> tuple[int, int, int, float] | None:
    """(hour, minute, second, precision s) of '10:00', '9:30:15', '3pm', '10am', 'noon'."""
    if token in ("noon", "midday"):
        return 12, 0, 0, 60.0
    if token == "midnight":
        return 0, 0, 0, 60.0
    match = re.fullmatch(r"(\d{1,2})(?::(\d{2}))?(?::(\d{2}))?(am|pm|h)?", token)
    if not match or not (match.group(2) or match.group(4)):
        return None
    hour, minute, second = int(match.group(1)), int(match.group(2) or 0), int(match.group(3) or 0)
    if match.group(4) == "pm" and hour < 12:
        hour += 12
    if match.group(4) == "am" and hour == 12:
        hour = 0
    if hour > 23 or minute > 59 or second > 59:
        return None
    precision = 1.0 if match.group(3) else 60.0 if match.group(2) else 3600.0
    return hour, minute, second, precision


def clock_stamp(token: str, now_s: float) -> float | None:
    """'10:00', '9:30:15', '3pm', '10am', 'noon' on the UTC day of ``now`` (the day before
    when that would be after now), or an ISO date-time; as a stamp (s). None: not a time."""
    found = _clock_span(token, now_s)
    return None if found is None else found[0]


def _clock_span(token: str, now_s: float) -> tuple[float, float] | None:
    """The stamp of a clock time and how long the written time lasts (its precision, s)."""
    parts = _clock_parts(token)
    if parts is not None:
        hour, minute, second, precision = parts
        day = datetime.fromtimestamp(_day_start_s(now_s), UTC)
        stamp = (day + timedelta(hours=hour, minutes=minute, seconds=second)).timestamp()
        return (stamp - 86400 if stamp > now_s else stamp), precision
    if not re.fullmatch(r"\d{4}-\d{2}-\d{2}([t ][\d:.]+)?(z|[+-]\d{2}:?\d{2})?", token):
        return None
    try:
        when = datetime.fromisoformat(token.upper())
    except ValueError:
        return None
    return (when if when.tzinfo else when.replace(tzinfo=UTC)).timestamp(), 1.0


def _not_a_time(token: str) -> None:
    """Raise for a token written like a clock time that is none ("25:00", "10:75")."""
    if re.fullmatch(r"\d{1,2}(:\d{1,2}){1,2}(am|pm)?|\d{1,2}(am|pm)", token):
        raise QueryError(f'"{token}" is not a time of day; write HH:MM or HH:MM:SS from 00:00 to 23:59:59, '
                         'or 3pm, or an ISO date-time such as 2026-12-07T10:00')


class _Reader:
    """Reads one time phrase at a token position: each ``_*`` method returns (window, tokens
    used) or None."""

    def __init__(self, t: Sequence[str], now_s: float, now_window_s: float, recent_s: float) -> None:
        self.t, self.now_s, self.now_window_s, self.recent_s = t, now_s, now_window_s, recent_s

    def word(self, i: int) -> str:
        return self.t[i] if 0 <= i < len(self.t) else ""

    def at(self, i: int, *words: str) -> bool:
        return all(self.word(i + k) == w for k, w in enumerate(words))

    # -- amounts and points in time -------------------------------------------------------

    def amount(self, i: int) -> tuple[float, int] | None:
        """A span: "5 minutes", "a minute", "few seconds", "couple of hours", "half an hour",
        "minute" (one); (seconds, tokens used)."""
        if self.at(i, "half", "an", "hour") or self.at(i, "half", "hour"):
            return 1800.0, 3 if self.word(i + 1) == "an" else 2
        j = i + (1 if self.word(i) in ("a", "an") and self.word(i + 1) in ("couple", "few") else 0)
        n = number_word(self.word(j))
        k = j + (1 if n is not None else 0)
        k += 1 if self.word(k) == "of" and self.word(j) == "couple" else 0
        if self.word(k) in TIME_UNITS_S:
            return (1.0 if n is None else n) * TIME_UNITS_S[self.word(k)], k - i + 1
        return None

    def point(self, i: int) -> tuple[float | TimeAnchor, int] | None:
        """A moment: a clock time ("10:00", "10 am", "3 o'clock"), "yesterday", "today",
        "this morning", "N minutes ago", "the start", or an event; (stamp or anchor, used)."""
        w = self.word(i)
        if w in ("yesterday", "today"):
            return _day_start_s(self.now_s) - (86400.0 if w == "yesterday" else 0.0), 1
        if self.at(i, "this") and self.word(i + 1) in _DAY_PARTS:
            return self.day_part(self.word(i + 1))[0], 2
        if (self.word(i), self.word(i + 1)) in (("the", "start"), ("the", "beginning")):
            return -math.inf, 2
        if (ago := self.ago(i)) is not None:
            return self.now_s - ago[0], ago[1]
        if (span := self.clock(i)) is not None:
            return span[0], span[2]
        if re.fullmatch(r"\d{1,2}", w) and int(w) <= 23 and self.word(i + 1) not in TIME_UNITS_S:
            found = _clock_span(f"{w}:00", self.now_s)  # "between 10 and 11": hours
            if found is not None:
                return found[0], 1
        if (event := self.event(i)) is not None:
            return event
        return None

    def day_part(self, part: str) -> tuple[float, float]:
        """The window of "this morning|afternoon|evening", "tonight": on the latest day on
        which it has begun (as for clock times)."""
        lo, hi = _DAY_PARTS[part]
        start = _day_start_s(self.now_s) + lo * 3600.0
        start -= 86400.0 if start > self.now_s else 0.0
        return start, start + (hi - lo) * 3600.0

    def clock(self, i: int) -> tuple[float, float, int] | None:
        """(stamp, precision s, tokens used) of a clock time; raises for an impossible one."""
        w = self.word(i)
        if re.fullmatch(r"\d{1,2}", w) and self.word(i + 1) in ("am", "pm", "oclock", "o'clock", "h"):
            found = _clock_span(w + ("pm" if self.word(i + 1) == "pm" else "am"), self.now_s)
            if found is not None:
                return found[0], found[1], 2
        found = _clock_span(w, self.now_s)
        if found is None:
            _not_a_time(w)
            return None
        return found[0], found[1], 1

    def ago(self, i: int) -> tuple[float, int] | None:
        found = self.amount(i)
        if found is not None and self.word(i + found[1]) == "ago":
            return found[0], found[1] + 1
        return None

    def event(self, i: int) -> tuple[TimeAnchor, int] | None:
        """"the person left", "a cup was first seen", "someone came in"."""
        k = i + (1 if self.word(i) in ("the", "a", "an", "my") else 0)
        for n in (3, 2, 1):
            name = resolve_class(" ".join(self.t[k : k + n])) if k + n <= len(self.t) else None
            if name is not None:
                k += n
                break
        else:
            return None
        k += 1 if self.word(k) in _AUX else 0
        if self.word(k) in ("first", "last") and self.word(k + 1) in ("seen", "spotted", "detected"):
            return TimeAnchor(name, self.word(k)), k + 2 - i
        if self.word(k) in ("seen", "spotted", "detected"):
            return TimeAnchor(name, "last"), k + 1 - i
        verb = self.word(k)
        if verb in _FIRST_VERBS or verb in _LAST_VERBS:
            k += 1
            k += 1 if self.word(k) in _EVENT_TAIL else 0
            return TimeAnchor(name, "first" if verb in _FIRST_VERBS else "last"), k - i
        return None

    # -- phrases ----------------------------------------------------------------------------

    def phrase(self, i: int) -> tuple[TimeWindow, int] | None:
        for rule in (self._now, self._recent, self._last_span, self._between, self._bound,
                     self._at, self._day, self._ago):
            found = rule(i)
            if found is not None:
                return found
        return None

    def _now(self, i: int) -> tuple[TimeWindow, int] | None:
        for words in (("right", "now"), ("just", "now"), ("at", "the", "moment"), ("at", "present"),
                      ("now",)):
            if self.at(i, *words):
                return TimeWindow(self.now_s - self.now_window_s, None), len(words)
        return None

    def _recent(self, i: int) -> tuple[TimeWindow, int] | None:
        for words in (("recently",), ("lately",), ("of", "late"), ("a", "moment", "ago"),
                      ("a", "while", "ago"), ("not", "long", "ago")):
            if self.at(i, *words):
                return TimeWindow(self.now_s - self.recent_s, None), len(words)
        return None

    def _last_span(self, i: int) -> tuple[TimeWindow, int] | None:
        """"(in|during|within|over|for) (the) last|past N units"."""
        k = i + (1 if self.word(i) in ("in", "during", "within", "over", "for") else 0)
        k += 1 if self.word(k) == "the" else 0
        if self.word(k) not in ("last", "past", "previous") or self.word(k + 1) in ("seen", "time"):
            return None
        found = self.amount(k + 1)
        if found is None:
            return None
        return TimeWindow(self.now_s - found[0], None), k + 1 + found[1] - i

    def _between(self, i: int) -> tuple[TimeWindow, int] | None:
        """"between A and B", "from A to|until B"."""
        if self.word(i) not in ("between", "from"):
            return None
        a = self.point(i + 1)
        if a is None:
            return None
        k = i + 1 + a[1]
        if self.word(k) not in (("and",) if self.word(i) == "between" else ("to", "until", "till", "til")):
            return None
        b = self.point(k + 1)
        if b is None:
            return None
        lo, hi = a[0], b[0]
        if isinstance(lo, float) and isinstance(hi, float) and lo > hi:
            lo, hi = hi, lo
        return _window(lo, hi), k + 1 + b[1] - i

    def _bound(self, i: int) -> tuple[TimeWindow, int] | None:
        """"since|after|from X", "before|until|by X"."""
        w = self.word(i)
        if w not in _STARTS and w not in _ENDS:
            return None
        found = self.point(i + 1)
        if found is None:
            return None
        return (_window(found[0], None) if w in _STARTS else _window(None, found[0])), 1 + found[1]

    def _at(self, i: int) -> tuple[TimeWindow, int] | None:
        """"at 10:15" (the minute written), "at 3pm" (that hour), "around 10:00"."""
        if self.word(i) not in ("at", "around", "about", "near"):
            return None
        found = self.clock(i + 1)
        if found is None:
            return None
        stamp, precision, used = found
        return TimeWindow(stamp, stamp + precision), 1 + used

    def _day(self, i: int) -> tuple[TimeWindow, int] | None:
        """"today", "earlier today", "yesterday", "this morning", "last night", "tonight"."""
        start = _day_start_s(self.now_s)
        k = i + (1 if self.word(i) in ("earlier", "so") else 0)
        k += 1 if self.word(i) == "so" and self.word(k) == "far" else 0
        if self.word(k) == "today":
            return TimeWindow(start, self.now_s), k + 1 - i
        if self.word(i) == "yesterday":
            return TimeWindow(start - 86400.0, start), 1
        if self.at(i, "last", "night"):
            return TimeWindow(start - 6 * 3600.0, start + 6 * 3600.0), 2
        part = {"this": self.word(i + 1), "tonight": "tonight"}.get(self.word(i), "")
        if part in _DAY_PARTS:
            lo, hi = self.day_part(part)
            return TimeWindow(lo, hi), 2 if self.word(i) == "this" else 1
        return None

    def _ago(self, i: int) -> tuple[TimeWindow, int] | None:
        """"5 minutes ago": about then, within a tenth of the span (at least the "now" window)."""
        found = self.ago(i)
        if found is None:
            return None
        tolerance_s = max(self.now_window_s, 0.1 * found[0])
        then = self.now_s - found[0]
        return TimeWindow(then - tolerance_s, then + tolerance_s), found[1]


def _window(since: float | TimeAnchor | None, until: float | TimeAnchor | None) -> TimeWindow:
    since = None if since == -math.inf else since  # "since the start": no bound
    return TimeWindow(
        None if since is None or isinstance(since, TimeAnchor) else float(since),
        None if until is None or isinstance(until, TimeAnchor) else float(until),
        since if isinstance(since, TimeAnchor) else None,
        until if isinstance(until, TimeAnchor) else None,
    )


def read_time_phrase(
    tokens: Sequence[str], i: int, now_s: float, *, now_window_s: float = 2.0, recent_s: float = 600.0
) -> tuple[TimeWindow, int] | None:
    """The time phrase at ``tokens[i]`` (lower-case words) and how many tokens it used, or
    None. ``now_window_s``: how long "now" reaches back; ``recent_s``: "recently". A word
    written as a clock time that is none ("25:00") raises ``QueryError``."""
    return _Reader(tokens, now_s, now_window_s, recent_s).phrase(i)


def time_window(text: str, now_s: float, *, now_window_s: float = 2.0, recent_s: float = 600.0) -> TimeWindow:
    """The window of a whole time phrase ("since 10:00", "today after 9am", "in the last 5
    minutes"); several phrases intersect. Raises ``QueryError`` naming the words it cannot read."""
    tokens = [t for t in re.split(r"[\s,;!?]+", text.lower().strip().rstrip(".")) if t]
    window, i = TimeWindow(), 0
    while i < len(tokens):
        found = read_time_phrase(tokens, i, now_s, now_window_s=now_window_s, recent_s=recent_s)
        if found is None:
            if tokens[i] in ("the", "and", "of", "in"):
                i += 1
                continue
            rest = " ".join(tokens[i:])
            raise QueryError(f'cannot read "{rest}" in the time "{text}"; write e.g. {TIME_PHRASES}')
        window, i = window & found[0], i + found[1]
    if not tokens:
        raise QueryError(f"empty time; write e.g. {TIME_PHRASES}")
    return window

