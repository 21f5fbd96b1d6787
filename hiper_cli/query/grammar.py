"""Plain-words queries ("cups in FOV", "how many chairs", "when did a person last pass here")
parsed into a typed ``ParsedQuery`` by a small deterministic grammar: no language model.

Tokens are read left to right; each position tries the phrase rules below (questions, time,
space, state, confidence, a number, a class phrase of up to three words); filler words are
skipped. A word no rule reads is an error that quotes it, lists what is understood and
suggests the nearest query that parses.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from datetime import UTC, datetime, timedelta
from typing import Any

from hiper_cli.errors import QueryError
from hiper_cli.query.results import ANSWER_KINDS
from hiper_cli.query.spec import Near, On, QueryConfig, QuerySpec
from hiper_cli.query.vocabulary import ANY_FOREGROUND, class_words, resolve_class, singular

__all__ = ["UNDERSTOOD", "ParsedQuery", "parse", "parse_time", "with_limit"]

UNDERSTOOD = (
    "classes (cup, chair, person, table, bottle, ... singular or plural; synonyms such as mug, sofa, "
    "people; 'objects' for all); space: in FOV, closest/nearest, within R m of X|me, near X, "
    "on the (closest) X, pass here; time: now, last N seconds|minutes|hours, since HH:MM, "
    "between HH:MM and HH:MM, before/after HH:MM, today, yesterday, last seen, first seen; "
    "state: moving, static; questions: how many, where, when, how long, is there, go to"
)
FILLER = frozenset(
    [
        "the",
        "a",
        "an",
        "of",
        "is",
        "are",
        "was",
        "were",
        "be",
        "been",
        "did",
        "do",
        "does",
        "there",
        "that",
        "which",
        "what",
        "who",
        "show",
        "list",
        "find",
        "me",
        "give",
        "tell",
        "all",
        "any",
        "some",
        "please",
        "currently",
        "in",
        "at",
        "with",
        "and",
        "by",
    ]
)
_TIME_UNITS = {
    "s": 1,
    "sec": 1,
    "secs": 1,
    "second": 1,
    "seconds": 1,
    "min": 60,
    "mins": 60,
    "minute": 60,
    "minutes": 60,
    "h": 3600,
    "hr": 3600,
    "hrs": 3600,
    "hour": 3600,
    "hours": 3600,
    "d": 86400,
    "day": 86400,
    "days": 86400,
}
_LENGTH_UNITS = {
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
    "cm": 0.01,
    "ft": 0.3048,
    "feet": 0.3048,
    "foot": 0.3048,
}
_MOVING = {"moving", "walking", "dynamic", "running", "driving"}
_STATIC = {"static", "still", "stationary", "parked", "standing"}
_ME = {"me", "here", "robot", "you", "us"}
_FOV = {"fov", "view", "sight"}
_KEYWORDS = (
    set(_TIME_UNITS)
    | set(_LENGTH_UNITS)
    | _MOVING
    | _STATIC
    | _ME
    | _FOV
    | set(FILLER)
    | set(
        [
            "how",
            "many",
            "long",
            "where",
            "when",
            "go",
            "to",
            "navigate",
            "take",
            "closest",
            "nearest",
            "within",
            "near",
            "next",
            "beside",
            "around",
            "on",
            "first",
            "last",
            "past",
            "seen",
            "since",
            "between",
            "before",
            "after",
            "today",
            "yesterday",
            "now",
            "visible",
            "front",
            "pass",
            "passed",
            "confidence",
            "above",
            "over",
            "least",
            "field",
        ]
    )
)


@dataclass(frozen=True)
class ParsedQuery:
    """A plain-words query as data: the answer kind, the selection and, for time answers,
    which sighting ("last" or "first")."""

    text: str
    answer: str
    spec: QuerySpec
    time_of: str = "last"

    def to_dict(self) -> dict[str, Any]:
        return {"answer": self.answer, "time_of": self.time_of, "spec": self.spec.to_dict()}


def _tokens(text: str) -> list[str]:
    text = text.lower().replace("field of view", "fov").replace("in front of", "front")
    text = re.sub(r"(\d)(m|cm|s|min|h|ft)\b", r"\1 \2", text)
    return [t for t in re.split(r"[\s,;!?\"']+", text) if t]


def _number(token: str) -> float | None:
    try:
        value = float(token.rstrip("%"))
    except ValueError:
        return {"one": 1.0, "two": 2.0, "three": 3.0, "five": 5.0, "ten": 10.0}.get(token)
    return value / 100.0 if token.endswith("%") else value if math.isfinite(value) else None


def _clock(token: str, now_s: float) -> float | None:
    """'10:00', '9:30:15', '3pm', '10am' on the UTC day of ``now`` (the day before when that
    would be after now), or an ISO date-time; as a stamp (s)."""
    match = re.fullmatch(r"(\d{1,2})(?::(\d{2}))?(?::(\d{2}))?(am|pm)?", token)
    if match and (match.group(2) or match.group(4)):
        hour, minute, second = int(match.group(1)), int(match.group(2) or 0), int(match.group(3) or 0)
        if match.group(4) == "pm" and hour < 12:
            hour += 12
        if match.group(4) == "am" and hour == 12:
            hour = 0
        if hour > 23 or minute > 59 or second > 59:
            return None
        day = datetime.fromtimestamp(now_s, UTC).replace(hour=0, minute=0, second=0, microsecond=0)
        stamp = (day + timedelta(hours=hour, minutes=minute, seconds=second)).timestamp()
        return stamp - 86400 if stamp > now_s else stamp
    try:
        when = datetime.fromisoformat(token.upper())
    except ValueError:
        return None
    return (when if when.tzinfo else when.replace(tzinfo=UTC)).timestamp()


def _not_a_time(token: str) -> None:
    """Raise for a token written like a clock time that is none ("25:00", "10:75"); any other
    word after "since"/"before" is left to the rest of the grammar."""
    if re.fullmatch(r"\d{1,2}(:\d{1,2}){1,2}(am|pm)?|\d{1,2}(am|pm)", token):
        raise QueryError(f'"{token}" is not a time of day; write HH:MM or HH:MM:SS from 00:00 to 23:59:59, '
                         'or 3pm, or an ISO date-time such as 2026-12-07T10:00')


class _Parser:
    def __init__(self, text: str, now_s: float, config: QueryConfig) -> None:
        self.text, self.now_s, self.cfg = text, now_s, config
        self.t = _tokens(text)
        self.answer: str | None = None
        self.time_of = "last"
        self.fields: dict[str, Any] = {}
        self.classes: list[str] = []
        self.plural = False
        self.unknown: list[str] = []

    # -- helpers ---------------------------------------------------------------------------

    def at(self, i: int, *words: str) -> bool:
        return all(i + k < len(self.t) and self.t[i + k] == w for k, w in enumerate(words))

    def set(self, key: str, value: Any) -> None:
        self.fields[key] = value

    def class_at(self, i: int) -> tuple[str, int, bool] | None:
        """(class name, tokens used, plural) of the longest class phrase at ``i``."""
        for n in (3, 2, 1):
            phrase = " ".join(self.t[i : i + n])
            if len(self.t[i : i + n]) == n and (name := resolve_class(phrase)) is not None:
                last = self.t[i + n - 1]
                return name, n, singular(last) != last or last in ("people", "men", "women", "children")
        return None

    def target_at(self, i: int) -> tuple[str, int] | None:
        """'me'/'here' or a class phrase (after optional 'the'/'a'), and the tokens used."""
        j = i + 1 if self.at(i, "the") or self.at(i, "a") or self.at(i, "an") else i
        if j < len(self.t) and self.t[j] in _ME:
            return "me", j - i + 1
        found = self.class_at(j)
        return (found[0], j - i + found[1]) if found else None

    # -- rules: each returns the number of tokens it read (0: not this rule) ----------------

    def questions(self, i: int) -> int:
        for words, kind in (
            (("how", "many"), "count"),
            (("how", "long"), "duration"),
            (("where",), "location"),
            (("when",), "time"),
            (("is", "there"), "yes_no"),
            (("are", "there"), "yes_no"),
            (("was", "there"), "yes_no"),
            (("were", "there"), "yes_no"),
            (("go", "to"), "goal"),
            (("navigate", "to"), "goal"),
            (("take", "me", "to"), "goal"),
            (("drive", "to"), "goal"),
        ):
            if self.at(i, *words):
                self.answer = self.answer or kind
                return len(words)
        if i == 0 and self.t[0] in ("is", "are", "any", "was", "were"):
            self.answer = "yes_no"
            return 1
        return 0

    def times(self, i: int) -> int:
        t = self.t
        if self.at(i, "last", "seen") or self.at(i, "first", "seen"):
            self.time_of = t[i]
            self.set("sort", "last_seen" if t[i] == "last" else "first_seen")
            return 2
        if i < len(t) and t[i] in ("last", "past"):
            n = _number(t[i + 1]) if i + 1 < len(t) else None
            k = i + (2 if n is not None else 1)
            if k < len(t) and t[k] in _TIME_UNITS:
                self.set("since_s", self.now_s - (n if n is not None else 1.0) * _TIME_UNITS[t[k]])
                return k - i + 1
            if t[i] == "last":  # "when did a person last pass here"
                self.set("sort", "last_seen")
                return 1
            return 0
        if i < len(t) and t[i] in ("since", "after", "before") and i + 1 < len(t):
            stamp = _clock(t[i + 1], self.now_s)
            if stamp is None:
                _not_a_time(t[i + 1])
                return 0
            self.set("until_s" if t[i] == "before" else "since_s", stamp)
            return 2
        if self.at(i, "between") and i + 3 < len(t) and t[i + 2] in ("and", "to"):
            a, b = _clock(t[i + 1], self.now_s), _clock(t[i + 3], self.now_s)
            if a is None or b is None:
                _not_a_time(t[i + 1] if a is None else t[i + 3])
                return 0
            self.set("since_s", min(a, b))
            self.set("until_s", max(a, b))
            return 4
        if i < len(t) and t[i] in ("today", "yesterday"):
            day = datetime.fromtimestamp(self.now_s, UTC).replace(hour=0, minute=0, second=0, microsecond=0)
            start = day.timestamp() - (86400 if t[i] == "yesterday" else 0)
            self.set("since_s", start)
            self.set("until_s", min(start + 86400, self.now_s))
            return 1
        if (i < len(t) and t[i] in ("now",)) or self.at(i, "right", "now"):
            self.set("since_s", self.now_s - self.cfg.now_window_s)
            return 2 if t[i] == "right" else 1
        return 0

    def space(self, i: int) -> int:
        t = self.t
        j = i + 1 if self.at(i, "in") else i
        j = j + 1 if self.at(j, "the") else j
        if j < len(t) and t[j] in _FOV | {"front", "visible"} and (j > i or t[j] in ("visible", "front")):
            if self.answer != "duration":  # "how long was X in view": time in view, not a filter
                self.set("in_fov", True)
            return j - i + 1
        n = _number(t[i]) if i < len(t) else None
        if n is not None and i + 1 < len(t) and t[i + 1] in ("closest", "nearest"):
            self.set("sort", "distance")
            self.set("limit", max(1, int(n)))
            return 2
        if i < len(t) and t[i] in ("closest", "nearest"):
            self.set("sort", "distance")
            self.fields.setdefault("limit", 1)
            return 1
        if (
            self.at(i, "within")
            and i + 2 < len(t)
            and (n := _number(t[i + 1])) is not None
            and t[i + 2] in _LENGTH_UNITS
        ):
            k = i + 3 + (1 if i + 3 < len(t) and t[i + 3] in ("of", "from") else 0)
            target = self.target_at(k) if k < len(t) else None
            self.set("near", Near(target[0] if target else "me", n * _LENGTH_UNITS[t[i + 2]]))
            return k - i + (target[1] if target else 0)
        for words in (("near",), ("close", "to"), ("next", "to"), ("beside",), ("around",)):
            if self.at(i, *words):
                target = self.target_at(i + len(words))
                if target is None:
                    return 0
                self.set("near", Near(target[0], self.cfg.near_radius_m))
                return len(words) + target[1]
        if self.at(i, "on"):
            j = i + 1 + (1 if self.at(i + 1, "the") or self.at(i + 1, "a") else 0)
            closest = j < len(t) and t[j] in ("closest", "nearest")
            found = self.class_at(j + closest)
            if found is None:
                return 0
            self.set("on", On(found[0], closest))
            return j + closest + found[1] - i
        passes: tuple[tuple[str, ...], ...] = (
            ("pass", "here"),
            ("passed", "here"),
            ("pass", "by", "here"),
            ("passed", "by", "here"),
            ("come", "by", "here"),
            ("came", "by", "here"),
            ("walk", "by", "here"),
            ("walked", "by", "here"),
            ("pass", "by"),
            ("passed", "by"),
            ("been", "here"),
        )
        for phrase in passes:
            if self.at(i, *phrase):
                self.set("passed_here", True)
                self.answer = self.answer or "time"
                return len(phrase)
        if self.at(i, "here"):
            self.set("near", Near("me", self.cfg.near_radius_m))
            return 1
        return 0

    def state(self, i: int) -> int:
        if self.at(i, "not", "moving"):
            self.set("state", "static")
            return 2
        if self.at(i, "in", "motion"):
            self.set("state", "dynamic")
            return 2
        if self.t[i] in _MOVING | _STATIC:
            self.set("state", "dynamic" if self.t[i] in _MOVING else "static")
            return 1
        return 0

    def confidence(self, i: int) -> int:
        if self.t[i] not in ("confidence", "confident"):
            return 0
        k = i + 1
        while k < len(self.t) and self.t[k] in ("above", "over", "at", "least", ">", ">=", "of"):
            k += 1
        n = _number(self.t[k]) if k < len(self.t) else None
        if n is None:
            return 0
        self.set("min_confidence", n)
        return k - i + 1

    def noun(self, i: int) -> int:
        n = _number(self.t[i])
        if n is not None and i + 1 < len(self.t) and self.class_at(i + 1) and n >= 1 and n == int(n):
            self.set("limit", int(n))
            return 1
        found = self.class_at(i)
        if found is None:
            return 0
        self.classes.append(found[0])
        self.plural = self.plural or found[2]
        return found[1]

    # -- the parse -------------------------------------------------------------------------

    def run(self, *, suggest: bool = True) -> ParsedQuery:
        rules: list[Callable[[int], int]] = [
            self.questions,
            self.times,
            self.space,
            self.state,
            self.confidence,
            self.noun,
        ]
        i = 0
        while i < len(self.t):
            used = next((n for rule in rules if (n := rule(i)) > 0), 0)
            if used == 0:
                if self.t[i] not in FILLER:
                    self.unknown.append(self.t[i])
                used = 1
            i += used
        if self.unknown:
            raise QueryError(
                _unknown_message(self.text, self.unknown, self.now_s, self.cfg)
                if suggest
                else f"cannot read {self.unknown}"
            )
        if not self.t:
            raise QueryError(
                f'empty query; ask e.g. "cups in FOV" or "how many chairs"; understood: {UNDERSTOOD}'
            )
        return self.build()

    def build(self) -> ParsedQuery:
        f = dict(self.fields)
        passed = f.pop("passed_here", False)
        layer = None
        classes = tuple(dict.fromkeys(c for c in self.classes if c != ANY_FOREGROUND))
        if ANY_FOREGROUND in self.classes and not classes:
            layer = "foreground"
        answer = self.answer or "list"
        if answer in ("location", "time", "duration", "goal") and not self.plural:
            f.setdefault("limit", 1)
        if answer == "goal":
            f.setdefault("sort", "distance")
        if answer in ("time", "duration") and not passed:
            f.setdefault("sort", "first_seen" if self.time_of == "first" else "last_seen")
        if answer == "location" and "sort" not in f:
            f["sort"] = "last_seen"
        spec = QuerySpec(classes=classes, layer=layer, passed_here=passed, **f)
        assert answer in ANSWER_KINDS
        return ParsedQuery(self.text, answer, spec, self.time_of)


def parse(text: str, *, now_s: float = 0.0, config: QueryConfig | None = None) -> ParsedQuery:
    """Parse a plain-words query; ``now_s`` anchors relative times ("last 10 minutes")."""
    return _Parser(text, now_s, config or QueryConfig()).run()


def _vocabulary() -> list[str]:
    words = set(_KEYWORDS)
    for phrase in class_words():
        words.update(phrase.split())
    return sorted(words)


def _unknown_message(text: str, unknown: list[str], now_s: float, cfg: QueryConfig) -> str:
    vocab = _vocabulary()
    fixed = []
    for token in _tokens(text):
        if token in unknown:
            close = difflib.get_close_matches(token, vocab, n=1, cutoff=0.6)
            if close:
                fixed.append(close[0])
        else:
            fixed.append(token)
    suggestion = " ".join(fixed)
    try:
        _Parser(suggestion, now_s, cfg).run(suggest=False)
    except QueryError:
        suggestion = "cups in FOV"
    quoted = ", ".join(f'"{w}"' for w in dict.fromkeys(unknown))
    return f'cannot read {quoted} in "{text}"; did you mean "{suggestion}"? hiper understands: {UNDERSTOOD}'


def with_limit(parsed: ParsedQuery, limit: int | None) -> ParsedQuery:
    """The parsed query with another result limit (the CLI's --limit)."""
    return replace(parsed, spec=replace(parsed.spec, limit=limit)) if limit is not None else parsed


def parse_time(text: str, now_s: float) -> float | None:
    """A time of day ('10:00', '3pm', on the UTC day of ``now_s``) or an ISO date-time, as a
    stamp (s); None when it is neither."""
    return _clock(text.strip().lower(), now_s)
