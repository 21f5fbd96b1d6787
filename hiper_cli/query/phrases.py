"""The words and phrases of the plain-words grammar (``grammar.py``), as data: filler words,
question phrases and the answer each asks for, change words, passing verbs, words of
nearness, order and confidence, chat shorthand; ``UNDERSTOOD``, what the grammar reads in one
line; ``tokens``, which normalises a query's words before the grammar reads them; and
``keywords``, every word the grammar reads (what a refusal's suggestions are drawn from)."""

from __future__ import annotations

import re

from hiper_cli.query.timewords import TIME_UNITS_S

__all__ = [
    "ARRIVE_LEAVE_VERBS",
    "AT_LEAST_WORDS",
    "AUX_WORDS",
    "CHANGE_WORDS",
    "CONFIDENCE_WORDS",
    "FILLER",
    "FOV_WORDS",
    "LENGTH_UNITS",
    "ME_WORDS",
    "MOVING_WORDS",
    "NEAR_WORDS",
    "NUMBER_WORDS",
    "ORDER_WORDS",
    "PASS_VERBS",
    "QUESTION_PHRASES",
    "REQUEST_WORDS",
    "SEEN_WORDS",
    "SHORTHAND",
    "SIGHTING_VERBS",
    "STATIC_WORDS",
    "UNDERSTOOD",
    "VERTICAL_CLASSES",
    "keywords",
    "tokens",
]

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
LENGTH_UNITS = {
    "m": 1.0, "meter": 1.0, "meters": 1.0, "metre": 1.0, "metres": 1.0, "cm": 0.01, "ft": 0.3048,
    "feet": 0.3048, "foot": 0.3048,
}
NUMBER_WORDS = {"one": 1.0, "two": 2.0, "three": 3.0, "four": 4.0, "five": 5.0, "six": 6.0, "ten": 10.0}
MOVING_WORDS = {"moving", "walking", "dynamic", "running", "driving", "mobile"}
STATIC_WORDS = {"static", "stationary", "parked", "standing", "unmoved"}
# Chat shorthand and contractions written without the apostrophe.
SHORTHAND = {
    "ppl": "people", "r": "are", "u": "you", "ur": "your", "plz": "please", "pls": "please", "thx": "",
    "wheres": "where is", "whats": "what is", "hows": "how is", "whos": "who is", "thats": "that is",
    "isnt": "is not", "arent": "are not", "dont": "do not", "didnt": "did not", "doesnt": "does not",
    "cant": "cannot", "wasnt": "was not", "werent": "were not", "havent": "have not", "hasnt": "has not",
    "#": "number", "w/": "with", "nr": "number", "no.": "number",
}
# Words putting an instance near a target: "near" (within ``near_radius_m``), "inside" (its box
# touches or is inside the target's), "with" (touching: ``support_gap_m``; "the table with the
# laptop", "people with a backpack"; only after a class).
NEAR_WORDS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("near",), "near"), (("close", "to"), "near"), (("next", "to"), "near"), (("beside",), "near"),
    (("around",), "near"), (("by",), "near"), (("from",), "near"), (("in",), "inside"),
    (("inside",), "inside"), (("into",), "inside"), (("with",), "with"),
)
CONFIDENCE_WORDS = frozenset(["confidence", "confident", "sure", "certainty", "score"])
AT_LEAST_WORDS = frozenset(
    ["above", "over", "at", "least", ">", ">=", "of", "more", "than", "greater", "higher"]
)
ORDER_WORDS = {"distance": "distance", "proximity": "distance", "time": "last_seen", "recency": "last_seen",
               "confidence": "confidence", "date": "last_seen"}
VERTICAL_CLASSES = frozenset(["wall", "door", "picture"])
REQUEST_WORDS = frozenset(["show", "list", "give", "tell", "display", "print", "report"])
ME_WORDS = {"me", "here", "robot", "you", "us"}
FOV_WORDS = {"fov", "view", "sight", "camera"}
SIGHTING_VERBS = tuple(
    ((verb, seeing), "first" if verb.startswith("start") else "last")
    for verb in ("start", "started", "stop", "stopped") for seeing in ("seeing", "observing", "detecting")
)
SEEN_WORDS = ("seen", "spotted", "detected", "observed", "see", "saw", "spot")
AUX_WORDS = ("is", "are", "was", "were", "did", "do", "does", "has", "have", "any", "can", "could")
# Question phrases -> the answer they ask for. Read where they stand; "did/is/any" at the start
# ask yes or no only when no other question word says otherwise ("do you know where the cup is").
QUESTION_PHRASES: tuple[tuple[tuple[str, ...], str], ...] = (
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
CHANGE_WORDS: tuple[tuple[tuple[str, ...], str], ...] = (
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
PASS_VERBS: tuple[tuple[tuple[str, ...], str], ...] = (
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
ARRIVE_LEAVE_VERBS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("come", "in"), "first"), (("came", "in"), "first"), (("show", "up"), "first"),
    (("showed", "up"), "first"), (("arrive",), "first"), (("arrived",), "first"),
    (("enter",), "first"), (("entered",), "first"), (("appear",), "first"), (("appeared",), "first"),
    (("leave",), "last"), (("left",), "last"), (("exit",), "last"), (("exited",), "last"),
    (("go",), "last"), (("went",), "last"), (("disappear",), "last"), (("disappeared",), "last"),
)


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
    return [part for w in words for part in SHORTHAND.get(w, w).split()]


UNDERSTOOD = (
    "classes (cup, chair, person, table, bottle, ... singular or plural; synonyms such as mug, sofa, "
    "fridge, desk, people, someone; 'objects'/'anything' for all); space: in FOV, closest/nearest, "
    "within R m of X|me, near X, on the (closest) X, here; time: now, recently, in the last N "
    "seconds|minutes|hours, N minutes ago, since|before|after HH:MM or an event ('after the person "
    "left'), between A and B, today, yesterday, last seen, first seen; change: new, gone, moved; "
    "passing: pass|enter|leave X|here; state: moving, static; questions: how many/count/number of, "
    "where, when/last time, how long, is there/any/did, go to"
)


def keywords() -> set[str]:
    """Every word the grammar reads besides class words (for suggestions)."""
    words = set(FILLER) | set(LENGTH_UNITS) | MOVING_WORDS | STATIC_WORDS | ME_WORDS | FOV_WORDS
    words |= set(tokens(UNDERSTOOD))
    for table in (QUESTION_PHRASES, CHANGE_WORDS, PASS_VERBS, ARRIVE_LEAVE_VERBS):
        for phrase, _kind in table:
            words.update(phrase)
    return words | set(TIME_UNITS_S) | {"closest", "nearest", "within", "beside", "nearby", "confidence"}
