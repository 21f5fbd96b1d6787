"""Plain-words queries ("cups in FOV", "count the chairs", "what moved in the last 5 seconds",
"when did the person pass the table") parsed into a typed ``ParsedQuery`` by a small
deterministic grammar: no language model.

Words are normalised (case, contractions, punctuation, "5min"), then read left to right; at
each position the phrase rules below try in turn: question words (what answer is wanted),
time phrases (``timewords.py``), change words (new, gone, moved), passing (pass, enter, leave
a place), space, state, confidence, a number, a class phrase of up to three words. Filler
words are skipped. A word no rule reads makes the query a refusal (``suggest.py``) that quotes
it and offers a question that parses.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

from hiper_cli.errors import QueryError
from hiper_cli.query.phrases import (
    ARRIVE_LEAVE_VERBS,
    AT_LEAST_WORDS,
    AUX_WORDS,
    CHANGE_WORDS,
    CONFIDENCE_WORDS,
    FILLER,
    FOV_WORDS,
    LENGTH_UNITS,
    ME_WORDS,
    MOVING_WORDS,
    NEAR_WORDS,
    NUMBER_WORDS,
    ORDER_WORDS,
    PASS_VERBS,
    QUESTION_PHRASES,
    REQUEST_WORDS,
    SEEN_WORDS,
    SIGHTING_VERBS,
    STATIC_WORDS,
    UNDERSTOOD,
    VERTICAL_CLASSES,
    keywords,
    tokens,
)
from hiper_cli.query.results import ANSWER_KINDS
from hiper_cli.query.spec import Near, On, QueryConfig, QuerySpec
from hiper_cli.query.suggest import refusal
from hiper_cli.query.timewords import TimeAnchor, TimeWindow, clock_stamp, read_time_phrase
from hiper_cli.query.vocabulary import ANY_FOREGROUND, PLACE_WORDS, plural, resolve_class, singular

__all__ = ["FILLER", "UNDERSTOOD", "ParsedQuery", "keywords", "parse", "parse_time", "tokens", "with_limit"]

@dataclass(frozen=True)
class ParsedQuery:
    """A plain-words query as data: the answer kind, the selection and, for time answers,
    which sighting ("last" or "first"). ``since_event``/``until_event``: window bounds set by
    an event ("after the person left"), resolved against the knowledge base by the answer."""

    text: str
    answer: str
    spec: QuerySpec
    time_of: str = "last"
    since_event: TimeAnchor | None = None
    until_event: TimeAnchor | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"answer": self.answer, "time_of": self.time_of, "spec": self.spec.to_dict()}
        for key, anchor in (("since_event", self.since_event), ("until_event", self.until_event)):
            if anchor is not None:
                out[key] = {"class": anchor.class_name, "sighting": anchor.sighting}
        return out


def _number(token: str) -> float | None:
    try:
        value = float(token.rstrip("%"))
    except ValueError:
        return NUMBER_WORDS.get(token)
    return value / 100.0 if token.endswith("%") else value if math.isfinite(value) else None


class _Parser:
    def __init__(
        self, text: str, now_s: float, config: QueryConfig, whole_place: frozenset[str] = frozenset()
    ) -> None:
        self.text, self.now_s, self.cfg, self.whole_place = text, now_s, config, whole_place
        self.t = tokens(text)
        self.answer: str | None = None
        self.ask_yes_no = False  # "is the cup on the table": yes/no unless a question word says otherwise
        self.request = False
        self.time_of: str | None = None
        self.window = TimeWindow()
        self.fields: dict[str, Any] = {}
        self.classes: list[str] = []
        self.plural = False
        self.passed = False
        self.implies_time = False  # "pass the table", "leave", "last time": a time is asked for
        self.change: str | None = None
        self.arrival: str | None = None  # "came in", "left": a change unless a time or place is asked
        self.unknown: list[str] = []
        self.places: list[str] = []

    # -- helpers ---------------------------------------------------------------------------

    def word(self, i: int) -> str:
        return self.t[i] if 0 <= i < len(self.t) else ""

    def at(self, i: int, *words: str) -> bool:
        return all(self.word(i + k) == w for k, w in enumerate(words))

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
        """'me'/'here', 'view', or a class phrase (after optional 'the'/'a'/'my'), and the
        tokens used."""
        j = i + 1 if self.word(i) in ("the", "a", "an", "my", "your") else i
        if self.word(j) in ME_WORDS:
            return "me", j - i + 1
        if self.word(j) in FOV_WORDS:
            return "view", j - i + 1
        found = self.class_at(j)
        return (found[0], j - i + found[1]) if found else None

    # -- rules: each returns the number of tokens it read (0: not this rule) ----------------

    def questions(self, i: int) -> int:
        for words, kind in QUESTION_PHRASES:
            if self.at(i, *words):
                self.answer = self.answer or kind
                return len(words)
        if self.at(i, "last", "time") or self.at(i, "first", "time"):
            self.implies_time = True
            self.time_of = self.time_of or self.word(i)
            return 2
        if i == 0 and self.word(0) in AUX_WORDS:
            self.ask_yes_no = True
            return 1
        if self.word(i) in REQUEST_WORDS and not self.at(i, "show", "up"):  # "could you list ...": not yes/no
            self.request = True
            return 1
        if self.word(i) == "see" and not {"did", "have", "had", "last", "first"} & set(self.t[:i]):
            self.set("in_fov", True)  # "do you see", "what can you see": in view now
            self.ask_yes_no = self.ask_yes_no or self.t[:i] == ["you"]  # "you see any cup?"
            return 1
        return 0

    def times(self, i: int) -> int:
        found = read_time_phrase(self.t, i, self.now_s, now_window_s=self.cfg.now_window_s,
                                 recent_s=self.cfg.recent_s)
        if found is not None:
            self.window = self.window & found[0]
            return found[1]
        t = self.t
        for words, sighting in SIGHTING_VERBS:  # "when did you start seeing the couch"
            if self.at(i, *words):
                self.time_of = sighting
                self.set("sort", f"{sighting}_seen")
                return len(words)
        if self.word(i) in ("last", "first") and self.word(i + 1) in SEEN_WORDS:
            self.time_of = t[i]
            self.set("sort", "last_seen" if t[i] == "last" else "first_seen")
            return 2
        if self.word(i) in ("last", "first"):  # "when did a person last pass here", "first see"
            self.set("sort", "last_seen" if t[i] == "last" else "first_seen")
            self.time_of = self.time_of or t[i]
            return 1
        return 0

    def changes(self, i: int) -> int:
        for words, kind in CHANGE_WORDS:
            if self.at(i, *words):
                self.change = self.change or kind
                return len(words)
        return 0

    def passes(self, i: int) -> int:
        """"pass|enter|leave X|here|view", and without a place "come in", "leave". The mover
        is named before the verb ("when did the person pass the table"); without one it is
        no passing ("where did I leave my phone"), and "left" after "is" means remaining."""
        if self.word(i) == "left" and self.word(i - 1) in ("is", "are", "was", "were", "anything"):
            return 0
        for words, sighting in PASS_VERBS:
            if not self.at(i, *words) or not self.classes:
                continue
            k = i + len(words)
            k += 1 if self.word(k) in ("by", "past", "near", "through", "into", "at") else 0
            target = self.target_at(k)
            if target is None:
                continue
            self.implies_time = True
            if target[0] == "view":  # entering or leaving the view: the first or last sighting
                self.time_of = self.time_of or sighting
            else:
                self.passed = True
                self.time_of = self.time_of or sighting
                self.set("near", Near(target[0], self.cfg.pass_radius_m))
            return k - i + target[1]
        if self.at(i, "pass", "by") or self.at(i, "passed", "by"):  # by here
            self.passed = self.implies_time = True
            self.set("near", Near("me", self.cfg.pass_radius_m))
            return 2
        if self.word(i - 1) in ("the", "a", "an", "nearest", "closest", "my", "main"):
            return 0  # "the nearest exit": a noun, not a verb
        for words, sighting in ARRIVE_LEAVE_VERBS:
            if self.at(i, *words):  # "when did X leave": a time; "who came in": a change
                self.time_of = self.time_of or sighting
                self.arrival = "added" if sighting == "first" else "removed"
                return len(words)
        return 0

    def space(self, i: int) -> int:
        t = self.t
        j = i + 1 if self.at(i, "in") else i
        j = j + 1 if self.at(j, "the") or self.at(j, "my") else j
        if self.word(j) in FOV_WORDS | {"front", "visible"} and (j > i or t[j] in ("visible", "front")):
            if self.answer != "duration":  # "how long was X in view": time in view, not a filter
                self.set("in_fov", True)
            return j - i + 1
        n = _number(self.word(i))
        if n is not None and self.word(i + 1) in ("closest", "nearest"):
            self.set("sort", "distance")
            self.set("limit", max(1, int(n)))
            return 2
        if self.word(i) in ("closest", "nearest"):
            self.set("sort", "distance")
            self.fields.setdefault("limit", 1)
            # "the chair closest to the door", "the cup nearest the sink": ranked from the door
            to = 1 if self.word(i + 1) in ("to", "from") else 0
            target = self.target_at(i + 1 + to) if to or self.classes else None
            if target is not None and target[0] not in ("me", "view"):
                self.set("rank_from", target[0])
                return 1 + to + target[1]
            return 1
        if self.at(i, "within") and (n := _number(self.word(i + 1))) is not None and t[i + 2:i + 3] and (
            t[i + 2] in LENGTH_UNITS
        ):
            k = i + 3 + (1 if self.word(i + 3) in ("of", "from") else 0)
            target = self.target_at(k)
            self.set("near", Near(target[0] if target else "me", n * LENGTH_UNITS[t[i + 2]]))
            return k - i + (target[1] if target else 0)
        for words, how in NEAR_WORDS:
            if self.at(i, *words):
                target = self.target_at(i + len(words))
                if target is None or target[0] == "view" or (how != "near" and target[0] == "me"):
                    continue
                if how == "with" and not self.classes:
                    continue
                if words == ("from",) and target[0] == "me":  # "visible from here": the viewpoint
                    return 1 + target[1]
                radius_m = {"near": self.cfg.near_radius_m, "inside": 0.0}.get(how, self.cfg.support_gap_m)
                self.set("near", Near(target[0], radius_m))
                return len(words) + target[1]
        return self.support(i) or self.nearby(i)

    def support(self, i: int) -> int:
        if not (self.at(i, "on") or self.at(i, "on", "top", "of")):
            return 0
        j = i + (3 if self.at(i, "on", "top", "of") else 1)
        j += 1 if self.word(j) in ("the", "a", "an") else 0
        closest = self.word(j) in ("closest", "nearest")
        found = self.class_at(j + closest)
        if found is None:
            return 0
        if found[0] in VERTICAL_CLASSES:  # "pictures on the wall": touching it, not standing on it
            self.set("near", Near(found[0], self.cfg.support_gap_m))
        else:
            self.set("on", On(found[0], closest))
        return j + closest + found[1] - i

    def nearby(self, i: int) -> int:
        """"here", "nearby", "around", "close by": near the reference pose."""
        for words in (("here",), ("nearby",), ("close", "by"), ("around",), ("near", "by"), ("near",)):
            if self.at(i, *words):
                self.fields.setdefault("near", Near("me", self.cfg.near_radius_m))
                return len(words)
        return 0

    def state(self, i: int) -> int:
        if self.at(i, "not", "moving"):
            self.set("state", "static")
            return 2
        if self.at(i, "in", "motion"):
            self.set("state", "dynamic")
            return 2
        if self.t[i] in MOVING_WORDS | STATIC_WORDS:
            self.set("state", "dynamic" if self.t[i] in MOVING_WORDS else "static")
            return 1
        return 0

    def confidence(self, i: int) -> int:
        """"confidence above 0.5", "more than 50% confidence", "at least 80 % sure"."""
        k = i + (1 if self.word(i) in CONFIDENCE_WORDS else 0)
        while self.word(k) in AT_LEAST_WORDS:
            k += 1
        n = _number(self.word(k))
        if n is None:
            return 0
        k += 1
        if self.word(i) not in CONFIDENCE_WORDS:  # the number first: the confidence word must follow
            if self.word(k) not in CONFIDENCE_WORDS:
                return 0
            k += 1
        self.set("min_confidence", n)
        return k - i

    def order(self, i: int) -> int:
        """"sorted by distance", "by time", "most recent first": the order of the answer."""
        k = i + (1 if self.word(i) in ("sorted", "ordered", "sort", "order", "ranked") else 0)
        if self.word(k) == "by" and self.word(k + 1) in ORDER_WORDS:
            self.set("sort", ORDER_WORDS[self.word(k + 1)])
            return k + 2 - i
        if self.at(i, "most", "recent", "first") or self.at(i, "latest", "first"):
            self.set("sort", "last_seen")
            return 3 if self.word(i) == "most" else 2
        if self.at(i, "most", "recently") or self.at(i, "most", "recent"):
            self.set("sort", "last_seen")
            return 2
        return 0

    def noun(self, i: int) -> int:
        n = _number(self.t[i])
        if n is not None and self.class_at(i + 1) and n >= 1 and n == int(n):
            self.set("limit", int(n))
            return 1
        found = self.class_at(i)
        if found is None:
            if self.t[i] == "who":
                self.classes.append("person")
                return 1
            return 0
        self.classes.append(found[0])
        self.plural = self.plural or found[2]
        return found[1]

    def place(self, i: int) -> int:
        """A room or area name. The name of the whole place the KB holds ("in the house" when
        its one environment is "house") asks about all of it; any other is refused with a
        note that hiper keeps no named places (never read as a class spelled alike)."""
        for n in (2, 1):
            phrase = " ".join(self.t[i : i + n])
            if len(self.t[i : i + n]) < n:
                continue
            if phrase in self.whole_place:
                return n
            if phrase in PLACE_WORDS:
                self.places.append(phrase)
                return n
        return 0

    # -- the parse -------------------------------------------------------------------------

    def read(self) -> None:
        rules: list[Callable[[int], int]] = [
            self.questions, self.times, self.changes, self.passes, self.space, self.state,
            self.confidence, self.order, self.noun, self.place,
        ]
        i = 0
        while i < len(self.t):
            used = next((n for rule in rules if (n := rule(i)) > 0), 0)
            if used == 0:
                if self.t[i] not in FILLER:
                    self.unknown.append(self.t[i])
                used = 1
            i += used

    def run(self, *, suggest: bool = True) -> ParsedQuery:
        if not self.t:
            raise QueryError(
                f'empty query; ask e.g. "cups in FOV" or "how many chairs"; understood: {UNDERSTOOD}'
            )
        self.read()
        if self.unknown or self.places:
            words = [*self.unknown, *self.places]
            if not suggest:
                raise QueryError(f"cannot read {words}")
            raise QueryError(refusal(self.text, self.t, self.unknown, self.places, self.example(),
                                     lambda q: _parses(q, self.now_s, self.cfg), UNDERSTOOD))
        return self.build()

    def example(self) -> str:
        """A question that parses, built from what was understood (the fallback suggestion)."""
        name = next((c for c in self.classes if c != ANY_FOREGROUND), "chair")
        return {
            "count": f"how many {plural(name)}",
            "location": f"where is the {name}",
            "time": f"when was the {name} last seen",
            "duration": f"how long was the {name} in view",
            "yes_no": f"is there a {name}",
            "goal": f"go to the {name}",
        }.get(self.answer or "", "what moved recently" if self.change else f"{plural(name)} in view")

    def build(self) -> ParsedQuery:
        f = dict(self.fields)
        layer = None
        classes = tuple(dict.fromkeys(c for c in self.classes if c != ANY_FOREGROUND))
        if ANY_FOREGROUND in self.classes and not classes:
            layer = "foreground"
        yes_no = self.ask_yes_no and not self.request
        answer = self.answer or ("yes_no" if yes_no else "time" if self.implies_time else "list")
        time_of = self.time_of or "last"
        change = self.change or (self.arrival if answer in ("list", "yes_no", "count") else None)
        if answer == "time" and change in ("added", "removed"):
            time_of, change = ("first" if change == "added" else "last"), None
        # "when was someone near the couch": the time of the sighting near it, as for "pass"
        passed = self.passed or (answer == "time" and isinstance(f.get("near"), Near))
        window = self.window
        if change is not None and window.is_open:  # "anything new": new within the recent window
            window = TimeWindow(self.now_s - self.cfg.recent_s, None)
        if window.since_s is not None and window.until_s is not None and window.since_s > window.until_s:
            raise QueryError(f'the times in "{self.text}" leave no time between them (the window would '
                             'start after it ends); ask e.g. "people between 9:00 and 11:00"')
        if answer in ("location", "time", "duration", "goal") and not self.plural:
            f.setdefault("limit", 1)
        if answer == "goal":
            f.setdefault("sort", "distance")
        if answer in ("time", "duration") and not passed:
            f.setdefault("sort", "first_seen" if time_of == "first" else "last_seen")
        if answer == "location" and "sort" not in f:
            f["sort"] = "last_seen"
        spec = QuerySpec(classes=classes, layer=layer, passed_here=passed, since_s=window.since_s,
                         until_s=window.until_s, change=change, **f)
        assert answer in ANSWER_KINDS
        return ParsedQuery(self.text, answer, spec, time_of, window.since_event, window.until_event)


def _parses(text: str, now_s: float, cfg: QueryConfig) -> bool:
    """Whether ``text`` parses and asks about something (a class, a place, a change)."""
    try:
        spec = _Parser(text, now_s, cfg).run(suggest=False).spec
    except QueryError:
        return False
    return bool(spec.classes or spec.layer or spec.change or spec.near or spec.on or spec.in_fov)


def parse(
    text: str, *, now_s: float = 0.0, config: QueryConfig | None = None, whole_place: Sequence[str] = ()
) -> ParsedQuery:
    """Parse a plain-words query; ``now_s`` anchors relative times ("last 10 minutes");
    ``whole_place``: names of the whole place asked about ("house"), read as no filter."""
    names = frozenset(" ".join(tokens(name)) for name in whole_place)
    return _Parser(text, now_s, config or QueryConfig(), names).run()


def with_limit(parsed: ParsedQuery, limit: int | None) -> ParsedQuery:
    """The parsed query with another result limit (the CLI's --limit)."""
    return replace(parsed, spec=replace(parsed.spec, limit=limit)) if limit is not None else parsed


def parse_time(text: str, now_s: float) -> float | None:
    """A time of day ('10:00', '3pm', on the UTC day of ``now_s``) or an ISO date-time, as a
    stamp (s); None when it is neither."""
    return clock_stamp(text.strip().lower(), now_s)
