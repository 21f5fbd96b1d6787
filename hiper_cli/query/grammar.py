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
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

from hiper_cli.errors import QueryError
from hiper_cli.query.results import ANSWER_KINDS
from hiper_cli.query.spec import Near, On, QueryConfig, QuerySpec
from hiper_cli.query.suggest import refusal
from hiper_cli.query.timewords import TIME_UNITS_S, TimeAnchor, TimeWindow, clock_stamp, read_time_phrase
from hiper_cli.query.vocabulary import ANY_FOREGROUND, PLACE_WORDS, plural, resolve_class, singular

__all__ = ["FILLER", "UNDERSTOOD", "ParsedQuery", "keywords", "parse", "parse_time", "tokens", "with_limit"]

UNDERSTOOD = (
    "classes (cup, chair, person, table, bottle, ... singular or plural; synonyms such as mug, sofa, "
    "fridge, desk, people, someone; 'objects'/'anything' for all); space: in FOV, closest/nearest, "
    "within R m of X|me, near X, on the (closest) X, here; time: now, recently, in the last N "
    "seconds|minutes|hours, N minutes ago, since|before|after HH:MM or an event ('after the person "
    "left'), between A and B, today, yesterday, last seen, first seen; change: new, gone, moved; "
    "passing: pass|enter|leave X|here; state: moving, static; questions: how many/count/number of, "
    "where, when/last time, how long, is there/any/did, go to"
)
FILLER = frozenset(
    [
        "the", "a", "an", "of", "is", "are", "was", "were", "be", "been", "being", "did", "do", "does",
        "there", "that", "which", "what", "who", "me", "all", "any", "some", "please", "currently", "in",
        "at", "with", "and", "by", "you", "i", "we", "my", "your", "our", "can", "could", "would", "will",
        "know", "want", "need", "like", "to", "hey", "ok", "okay", "robot", "so", "just", "still", "ever",
        "else", "it", "its", "they", "them", "these", "those", "this", "right", "exactly", "also", "has",
        "have", "had", "got", "get", "again", "see", "seen", "saw", "spot", "spotted", "notice", "noticed",
        "observed", "detected", "look", "looking", "for", "from", "one", "ones", "about", "let", "display",
        "print", "report", "check", "remember", "recall", "located", "situated", "positioned", "sit", "sits",
        "sitting", "lying", "lies", "placed", "stored", "kept", "resting", "stay", "stayed", "remain",
        "remained", "put", "left", "or", "seeing",
    ]
)
_LENGTH_UNITS = {
    "m": 1.0, "meter": 1.0, "meters": 1.0, "metre": 1.0, "metres": 1.0, "cm": 0.01, "ft": 0.3048,
    "feet": 0.3048, "foot": 0.3048,
}
_NUMBERS = {"one": 1.0, "two": 2.0, "three": 3.0, "four": 4.0, "five": 5.0, "six": 6.0, "ten": 10.0}
_MOVING = {"moving", "walking", "dynamic", "running", "driving", "mobile"}
_STATIC = {"static", "stationary", "parked", "standing", "unmoved"}
# Chat shorthand and contractions written without the apostrophe.
_SHORTHAND = {
    "ppl": "people", "r": "are", "u": "you", "ur": "your", "plz": "please", "pls": "please", "thx": "",
    "wheres": "where is", "whats": "what is", "hows": "how is", "whos": "who is", "thats": "that is",
    "isnt": "is not", "arent": "are not", "dont": "do not", "didnt": "did not", "doesnt": "does not",
    "cant": "cannot", "wasnt": "was not", "werent": "were not", "havent": "have not", "hasnt": "has not",
    "#": "number", "w/": "with", "nr": "number", "no.": "number",
}
# Words putting an instance near a target: "near" (within ``near_radius_m``), "inside" (its box
# touches or is inside the target's), "with" (touching: ``support_gap_m``; "the table with the
# laptop", "people with a backpack"; only after a class).
_NEAR_WORDS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("near",), "near"), (("close", "to"), "near"), (("next", "to"), "near"), (("beside",), "near"),
    (("around",), "near"), (("by",), "near"), (("from",), "near"), (("in",), "inside"),
    (("inside",), "inside"), (("into",), "inside"), (("with",), "with"),
)
_CONFIDENCE = frozenset(["confidence", "confident", "sure", "certainty", "score"])
_AT_LEAST = frozenset(["above", "over", "at", "least", ">", ">=", "of", "more", "than", "greater", "higher"])
_ORDERS = {"distance": "distance", "proximity": "distance", "time": "last_seen", "recency": "last_seen",
           "confidence": "confidence", "date": "last_seen"}
_VERTICAL = frozenset(["wall", "door", "picture"])
_REQUESTS = frozenset(["show", "list", "give", "tell", "display", "print", "report"])
_ME = {"me", "here", "robot", "you", "us"}
_FOV = {"fov", "view", "sight", "camera"}
_SIGHTINGS = tuple(
    ((verb, seeing), "first" if verb.startswith("start") else "last")
    for verb in ("start", "started", "stop", "stopped") for seeing in ("seeing", "observing", "detecting")
)
_SEEN = ("seen", "spotted", "detected", "observed", "see", "saw", "spot")
_AUX = ("is", "are", "was", "were", "did", "do", "does", "has", "have", "any", "can", "could")
# Question phrases -> the answer they ask for. Read where they stand; "did/is/any" at the start
# ask yes or no only when no other question word says otherwise ("do you know where the cup is").
_QUESTIONS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("how", "many"), "count"),
    (("how", "much"), "count"),
    (("count",), "count"),
    (("number", "of"), "count"),
    (("total", "number", "of"), "count"),
    (("how", "long", "ago"), "time"),
    (("for", "how", "long"), "duration"),
    (("how", "long"), "duration"),
    (("where",), "location"),
    (("location", "of"), "location"),
    (("position", "of"), "location"),
    (("locate",), "location"),
    (("location",), "location"),
    (("position",), "location"),
    (("find",), "location"),
    (("how", "far"), "location"),
    (("at", "what", "time"), "time"),
    (("at", "which", "time"), "time"),
    (("which", "time"), "time"),
    (("what", "time"), "time"),
    (("when",), "time"),
    (("is", "there"), "yes_no"),
    (("are", "there"), "yes_no"),
    (("was", "there"), "yes_no"),
    (("were", "there"), "yes_no"),
    (("go", "to"), "goal"),
    (("navigate", "to"), "goal"),
    (("take", "me", "to"), "goal"),
    (("bring", "me", "to"), "goal"),
    (("drive", "to"), "goal"),
    (("head", "to"), "goal"),
    (("move", "to"), "goal"),
    (("guide", "me", "to"), "goal"),
    (("go", "near"), "goal"),
    (("go", "back", "to"), "goal"),
    (("return", "to"), "goal"),
    (("come", "back", "to"), "goal"),
    (("go", "towards"), "goal"),
    (("go", "next", "to"), "goal"),
    (("get", "me"), "goal"),
    (("fetch",), "goal"),
    (("send",), "goal"),
)
# Change words -> the change they ask about (``QuerySpec.change``).
_CHANGES: tuple[tuple[tuple[str, ...], str], ...] = (
    (("new",), "added"),
    (("newly",), "added"),
    (("added",), "added"),
    (("appeared",), "added"),
    (("appear",), "added"),
    (("showed", "up"), "added"),
    (("show", "up"), "added"),
    (("turn", "up"), "added"),
    (("turned", "up"), "added"),
    (("gone",), "removed"),
    (("missing",), "removed"),
    (("removed",), "removed"),
    (("disappeared",), "removed"),
    (("disappear",), "removed"),
    (("vanished",), "removed"),
    (("taken", "away"), "removed"),
    (("no", "longer", "there"), "removed"),
    (("changed",), "any"),
    (("change",), "any"),
    (("changes",), "any"),
    (("different",), "any"),
    (("moved",), "moved"),
    (("move",), "moved"),
    (("shifted",), "moved"),
    (("movement",), "moved"),
    (("movements",), "moved"),
    (("relocated",), "moved"),
)
# Passing a place: the verb says which sighting near it ("first" for enter, "last" otherwise).
_PASS_VERBS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("walked", "past"), "last"), (("walk", "past"), "last"), (("went", "past"), "last"),
    (("go", "past"), "last"), (("walked", "by"), "last"), (("walk", "by"), "last"),
    (("went", "by"), "last"), (("go", "by"), "last"), (("came", "by"), "last"), (("come", "by"), "last"),
    (("pass", "by"), "last"), (("passed", "by"), "last"), (("passing", "by"), "last"),
    (("pass",), "last"), (("passed",), "last"), (("passing",), "last"), (("cross",), "last"),
    (("crossed",), "last"), (("been",), "last"),
    (("come", "into"), "first"), (("came", "into"), "first"), (("go", "into"), "first"),
    (("went", "into"), "first"), (("enter",), "first"), (("entered",), "first"),
    (("arrive", "at"), "first"), (("arrived", "at"), "first"), (("reach",), "first"),
    (("reached",), "first"), (("get", "to"), "first"),
    (("leave",), "last"), (("left",), "last"), (("exit",), "last"), (("exited",), "last"),
)
# The same verbs without a place: a first or last sighting ("when did the person leave").
_ARRIVE_LEAVE: tuple[tuple[tuple[str, ...], str], ...] = (
    (("come", "in"), "first"), (("came", "in"), "first"), (("show", "up"), "first"),
    (("showed", "up"), "first"), (("arrive",), "first"), (("arrived",), "first"),
    (("enter",), "first"), (("entered",), "first"), (("appear",), "first"), (("appeared",), "first"),
    (("leave",), "last"), (("left",), "last"), (("exit",), "last"), (("exited",), "last"),
    (("go",), "last"), (("went",), "last"), (("disappear",), "last"), (("disappeared",), "last"),
)


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


def tokens(text: str) -> list[str]:
    """The words of a query, normalised: lower case, contractions opened ("where's" -> "where
    is", "isn't" -> "is not"), "field of view" -> "fov", numbers split from units ("5min")."""
    text = text.lower().replace("’", "'").replace("field of view", "fov").replace("in front of", "front")
    text = re.sub(r"\bo'?clock\b", "oclock", text)
    text = re.sub(r"n't\b", " not", text).replace("can not", "cannot")
    text = re.sub(r"'s\b", " is", text)
    text = re.sub(r"'re\b", " are", text)
    text = re.sub(r"'ve\b", " have", text)
    text = re.sub(r"'ll\b", " will", text)
    text = re.sub(r"'d\b", " did", text)
    text = re.sub(r"(?<=[a-z])[-/](?=[a-z])", " ", text)
    text = re.sub(r"(\d)(m|cm|s|sec|secs|min|mins|h|hr|hrs|ft)\b", r"\1 \2", text)
    text = re.sub(r"#", " # ", text)
    words = re.split(r"[\s,;!?\"'()\[\]{}<>*]+", text)
    words = [w.rstrip(".") if re.fullmatch(r"[\d.:]+", w) else w.rstrip(".:") for w in words if w.strip(".:")]
    return [part for w in words for part in _SHORTHAND.get(w, w).split()]


def _number(token: str) -> float | None:
    try:
        value = float(token.rstrip("%"))
    except ValueError:
        return _NUMBERS.get(token)
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
        if self.word(j) in _ME:
            return "me", j - i + 1
        if self.word(j) in _FOV:
            return "view", j - i + 1
        found = self.class_at(j)
        return (found[0], j - i + found[1]) if found else None

    # -- rules: each returns the number of tokens it read (0: not this rule) ----------------

    def questions(self, i: int) -> int:
        for words, kind in _QUESTIONS:
            if self.at(i, *words):
                self.answer = self.answer or kind
                return len(words)
        if self.at(i, "last", "time") or self.at(i, "first", "time"):
            self.implies_time = True
            self.time_of = self.time_of or self.word(i)
            return 2
        if i == 0 and self.word(0) in _AUX:
            self.ask_yes_no = True
            return 1
        if self.word(i) in _REQUESTS and not self.at(i, "show", "up"):  # "could you list ...": not yes/no
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
        for words, sighting in _SIGHTINGS:  # "when did you start seeing the couch"
            if self.at(i, *words):
                self.time_of = sighting
                self.set("sort", f"{sighting}_seen")
                return len(words)
        if self.word(i) in ("last", "first") and self.word(i + 1) in _SEEN:
            self.time_of = t[i]
            self.set("sort", "last_seen" if t[i] == "last" else "first_seen")
            return 2
        if self.word(i) in ("last", "first"):  # "when did a person last pass here", "first see"
            self.set("sort", "last_seen" if t[i] == "last" else "first_seen")
            self.time_of = self.time_of or t[i]
            return 1
        return 0

    def changes(self, i: int) -> int:
        for words, kind in _CHANGES:
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
        for words, sighting in _PASS_VERBS:
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
        for words, sighting in _ARRIVE_LEAVE:
            if self.at(i, *words):  # "when did X leave": a time; "who came in": a change
                self.time_of = self.time_of or sighting
                self.arrival = "added" if sighting == "first" else "removed"
                return len(words)
        return 0

    def space(self, i: int) -> int:
        t = self.t
        j = i + 1 if self.at(i, "in") else i
        j = j + 1 if self.at(j, "the") or self.at(j, "my") else j
        if self.word(j) in _FOV | {"front", "visible"} and (j > i or t[j] in ("visible", "front")):
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
            t[i + 2] in _LENGTH_UNITS
        ):
            k = i + 3 + (1 if self.word(i + 3) in ("of", "from") else 0)
            target = self.target_at(k)
            self.set("near", Near(target[0] if target else "me", n * _LENGTH_UNITS[t[i + 2]]))
            return k - i + (target[1] if target else 0)
        for words, how in _NEAR_WORDS:
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
        if found[0] in _VERTICAL:  # "pictures on the wall": touching it, not standing on it
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
        if self.t[i] in _MOVING | _STATIC:
            self.set("state", "dynamic" if self.t[i] in _MOVING else "static")
            return 1
        return 0

    def confidence(self, i: int) -> int:
        """"confidence above 0.5", "more than 50% confidence", "at least 80 % sure"."""
        k = i + (1 if self.word(i) in _CONFIDENCE else 0)
        while self.word(k) in _AT_LEAST:
            k += 1
        n = _number(self.word(k))
        if n is None:
            return 0
        k += 1
        if self.word(i) not in _CONFIDENCE:  # the number first: the confidence word must follow
            if self.word(k) not in _CONFIDENCE:
                return 0
            k += 1
        self.set("min_confidence", n)
        return k - i

    def order(self, i: int) -> int:
        """"sorted by distance", "by time", "most recent first": the order of the answer."""
        k = i + (1 if self.word(i) in ("sorted", "ordered", "sort", "order", "ranked") else 0)
        if self.word(k) == "by" and self.word(k + 1) in _ORDERS:
            self.set("sort", _ORDERS[self.word(k + 1)])
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


def keywords() -> set[str]:
    """Every word the grammar reads besides class words (for suggestions)."""
    words = set(FILLER) | set(_LENGTH_UNITS) | _MOVING | _STATIC | _ME | _FOV | set(tokens(UNDERSTOOD))
    for table in (_QUESTIONS, _CHANGES, _PASS_VERBS, _ARRIVE_LEAVE):
        for phrase, _kind in table:
            words.update(phrase)
    return words | set(TIME_UNITS_S) | {"closest", "nearest", "within", "beside", "nearby", "confidence"}


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
